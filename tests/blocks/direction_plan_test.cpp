// DirectionPlan: which directions of a tangent call share a pass, and the multibody block's
// tangents when directions share one (several states reaching the car through one load entry,
// as a damper's states do in a Jacobian pass) against the same directions one call each.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "blocks/direction_plan.hpp"
#include "generated_models/registry.hpp"
#include "tests/blocks/tangent_check.hpp"

namespace dydp::test {
namespace {

using blocks::DirectionPlan;
using Matrix = Eigen::MatrixXd;

TEST(DirectionPlan, DirectionsOnOneEntryShareAPassAndTheOthersKeepTheirs) {
  // A (2 x 6) and B (3 x 6), B shared below row 2. Direction 0 is zero; 1, 2 and 5 are
  // multiples of B's row 1; 3 has two nonzero seeds; 4 is alone on B's row 2.
  Matrix a = Matrix::Zero(2, 6), b = Matrix::Zero(3, 6);
  b(1, 1) = 2.0, b(1, 2) = -3.0, b(1, 5) = 0.5;
  a(0, 3) = 1.0, b(2, 3) = 1.0;
  b(2, 4) = 5.0;
  DirectionPlan plan;
  plan.build({&a, &b}, 6, 1, 3);
  EXPECT_FALSE(plan.whole());
  ASSERT_EQ(plan.passes(), 3);  // row 1's unit seed, direction 3, direction 4
  Matrix ga, gb;
  plan.gather(a, ga);
  plan.gather(b, gb);
  EXPECT_EQ(gb.col(0), Eigen::Vector3d(0.0, 1.0, 0.0));
  EXPECT_EQ(ga.col(0), Eigen::Vector2d::Zero());
  EXPECT_EQ(ga.col(1), a.col(3));
  EXPECT_EQ(gb.col(1), b.col(3));
  EXPECT_EQ(gb.col(2), b.col(4));

  // A linear function of the seeds, f = P a + Q b: through the plan it equals f applied to
  // every direction.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Matrix p(4, 2), q(4, 3);
  for (int i = 0; i < p.size(); ++i) p.data()[i] = unit(rng);
  for (int i = 0; i < q.size(); ++i) q.data()[i] = unit(rng);
  const Matrix direct = p * a + q * b;
  Matrix planned;
  plan.scatter(Matrix(p * ga + q * gb), 4, planned);
  ASSERT_EQ(planned.cols(), 6);
  EXPECT_TRUE(planned.col(0).isZero(0.0));
  for (int d = 1; d < 6; ++d)
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(planned(i, d), direct(i, d), 1e-15) << "direction " << d;
  // copied directions are bit for bit the pass's
  EXPECT_EQ(planned.col(3), Matrix(p * ga + q * gb).col(1));
}

TEST(DirectionPlan, WithoutSharingOrZeroDirectionsTheSeedsServeAsTheyAre) {
  Matrix a = Matrix::Identity(3, 3);
  DirectionPlan plan;
  plan.build({&a}, 3, 0, 3);  // one direction per row: nothing to share
  EXPECT_TRUE(plan.whole());
  EXPECT_EQ(plan.passes(), 3);
  a(1, 1) = 0.0;
  plan.build({&a}, 3, 0, 3);
  EXPECT_FALSE(plan.whole());
  EXPECT_EQ(plan.passes(), 2);
}

// The sedan as a block: the tangents of directions that share load entries (three on one entry,
// one alone on another, beside a direction on the states and a zero one), computed in one call,
// equal those of each direction computed alone.
TEST(DirectionPlan, TheCarsTangentsInSharedDirectionsEqualThoseComputedOneByOne) {
  const mbs::GeneratedModel& g = *generated::find_model("sedan");
  BlockCase c;
  c.type = "multibody.sedan";
  std::vector<double> p;
  const auto block = make_block(c, &p);
  const engine::Block& b = *block;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  detail::Point pt;
  pt.t = 0.0;
  pt.p = p;
  for (int i = 0; i < g.independent_count; ++i) pt.x.push_back(g.initial_q[g.independent[i]] + 0.02 * unit(rng));
  for (int i = 0; i < g.independent_count; ++i) pt.x.push_back(0.5 * unit(rng));
  for (const auto& port : b.inputs()) {
    pt.u.emplace_back();
    for (int i = 0; i < port.width; ++i) pt.u.back().push_back(500.0 * unit(rng));
  }
  for (int i = 0; i < g.driven_count; ++i) pt.u[g.loads + 3 * i][0] = g.initial_q[g.driven[i]];
  ASSERT_GE(g.loads, 2);
  const int nx = b.num_states(), np = static_cast<int>(p.size()), nd = 6;
  detail::SeedSet seeds;
  seeds.sx.assign(static_cast<size_t>(nx) * nd, 0.0);
  seeds.sp.assign(static_cast<size_t>(std::max(np, 1)) * nd, 0.0);
  for (const auto& v : pt.u) seeds.su.emplace_back(v.size() * nd, 0.0);
  for (int i = 0; i < nx; ++i) seeds.sx[i] = unit(rng);  // direction 0: the states
  const int k0 = 0, k1 = g.loads - 1;                     // the first and last load ports
  const int w0 = static_cast<int>(pt.u[k0].size()), w1 = static_cast<int>(pt.u[k1].size());
  // directions 1, 2 and 4 on the first load's first entry, 3 alone on the last load's; 5 zero
  seeds.su[k0][1 * w0] = 1.7;
  seeds.su[k0][2 * w0] = -0.4;
  seeds.su[k1][3 * w1] = 2.2;
  seeds.su[k0][4 * w0] = 0.9;
  const detail::Values together = detail::tangents(b, pt, nd, seeds);

  for (int d = 0; d < nd; ++d) {
    detail::SeedSet one;
    one.sx.assign(seeds.sx.begin() + d * nx, seeds.sx.begin() + (d + 1) * nx);
    one.sp.assign(std::max(np, 1), 0.0);
    for (size_t k = 0; k < pt.u.size(); ++k) {
      const size_t w = pt.u[k].size();
      one.su.emplace_back(seeds.su[k].begin() + d * w, seeds.su[k].begin() + (d + 1) * w);
    }
    const detail::Values alone = detail::tangents(b, pt, 1, one);
    const size_t ny = alone.y.size();
    double scale = 0.0;
    for (double v : alone.y) scale = std::max(scale, std::abs(v));
    for (double v : alone.xdot) scale = std::max(scale, std::abs(v));
    if (d < 5) {
      EXPECT_GT(scale, 0.0) << "direction " << d;
    }
    for (size_t i = 0; i < ny; ++i)
      EXPECT_NEAR(together.y[d * ny + i], alone.y[i], 1e-12 * scale) << "output " << i << ", direction " << d;
    for (int i = 0; i < nx; ++i)
      EXPECT_NEAR(together.xdot[d * nx + i], alone.xdot[i], 1e-12 * scale) << "state " << i << ", direction " << d;
  }
}

}  // namespace
}  // namespace dydp::test
