// tyre.mf: exact tangents; pure-slip curves against the Magic Formula written out; cornering
// stiffness B C D mu Fz; combined-slip reduction; aligning torque sign; the relaxation lag's
// time constant sigma / V against a simulated step in slip.
#include <gtest/gtest.h>

#include <cmath>

#include "tests/blocks/scene_helpers.hpp"
#include "tests/blocks/tangent_check.hpp"

namespace dydp::test {
namespace {

std::array<double, 5> forces(const engine::Block& b, const std::vector<double>& p, double fz, double kappa, double alpha) {
  const double x[2] = {kappa, alpha};
  const double u0 = fz, u1 = 20, u2 = 0, u3 = 0;
  const double* u[4] = {&u0, &u1, &u2, &u3};
  std::array<double, 5> y{};
  double* out[5] = {&y[0], &y[1], &y[2], &y[3], &y[4]};
  engine::Eval e;
  e.x = x;
  e.u = u;
  e.p = p.data();
  b.outputs(e, out);
  return y;
}

double magic(double x, double b, double c, double e) {
  return std::sin(c * std::atan(b * x - e * (b * x - std::atan(b * x))));
}

TEST(TyreMf, TangentsMatchFiniteDifferences) {
  BlockCase c;
  c.type = "tyre.mf";
  c.states = {{0.0, 0.3}, {0.0, 0.3}};
  c.inputs = {{{4000, 2000}}, {{15, 10}}, {{0, 3}}, {{50, 30}}};
  c.samples = 10;
  check_tangents(c);
}

TEST(TyreMf, PureAndCombinedSlip) {
  BlockCase c;
  c.type = "tyre.mf";
  std::vector<double> p;
  auto b = make_block(c, &p);
  // Nominal load: mu = 1; pure slip gives the formula exactly.
  for (double s : {-0.3, -0.05, 0.02, 0.1, 0.4}) {
    EXPECT_NEAR(forces(*b, p, 4000, s, 0)[0], 4000 * magic(s, 10, 1.65, 0.97), 1e-9);
    EXPECT_NEAR(forces(*b, p, 4000, 0, s)[1], 4000 * magic(s, 10, 1.9, 0.97), 1e-9);
  }
  // Cornering stiffness B C D at small slip; load dependence of friction (pD2 = -0.1).
  const double h = 1e-6;
  EXPECT_NEAR(forces(*b, p, 4000, 0, h)[1] / h, 10 * 1.9 * 4000, 1e-3 * 10 * 1.9 * 4000);
  // At twice the nominal load: friction 0.9 (pD2), and the cornering stiffness of the MF 5.2
  // law By Cy mu0 Fz0 sin(2 atan(Fz / (pKy2 Fz0))) / sin(2 atan(1 / pKy2)), pKy2 = 2, which is
  // 76 kN/rad * 1 / 0.8 = 95 kN/rad (not twice 76): load transfer costs an axle grip.
  const double k8000 = 10 * 1.9 * 4000 * std::sin(2 * std::atan(1.0)) / std::sin(2 * std::atan(0.5));
  EXPECT_NEAR(k8000, 95000.0, 1e-6);
  EXPECT_NEAR(forces(*b, p, 8000, 0, h)[1] / h, k8000, 1e-3 * k8000);
  const double b8000 = k8000 / (1.9 * 0.9 * 8000);
  EXPECT_NEAR(forces(*b, p, 8000, 0, 0.3)[1], 8000 * 0.9 * magic(0.3, b8000, 1.9, 0.97), 1e-9);
  // Peak friction force still mu Fz at any load (the stiffness law changes only the shape).
  EXPECT_NEAR(forces(*b, p, 8000, 0, 1.2)[1], 8000 * 0.9 * magic(1.2, b8000, 1.9, 0.97), 1e-9);
  // Combined slip reduces both forces; aligning torque opposes Fy's moment sense (self-aligning).
  const auto pure = forces(*b, p, 4000, 0, 0.05), combined = forces(*b, p, 4000, 0.1, 0.05);
  EXPECT_LT(std::fabs(combined[1]), std::fabs(pure[1]));
  EXPECT_LT(std::fabs(combined[0]), std::fabs(forces(*b, p, 4000, 0.1, 0)[0]));
  EXPECT_GT(pure[1], 0.0);
  EXPECT_LT(pure[2], 0.0);
  EXPECT_NEAR(pure[2], -0.03 / std::sqrt(1 + 0.4 * 0.4) * pure[1], 1e-9);
}

TEST(TyreMf, RelaxationLagHasTimeConstantSigmaOverSpeed) {
  const std::string scene = R"(scene: relaxation
time: {start: 0.0, stop: 0.1, output_step: 0.0005}
solver: {method: bdf, rtol: 1.0e-10, atol: 1.0e-12}
blocks:
  fz: {type: source.constant, value: 4000.0}
  vx: {type: source.constant, value: 20.0}
  vy: {type: source.constant, value: -1.0}
  omega: {type: source.constant, value: 64.516129032258064}
  tyre: {type: tyre.mf}
connections:
  - fz.y -> tyre.fz
  - vx.y -> tyre.vx
  - vy.y -> tyre.vy
  - omega.y -> tyre.omega
outputs: [tyre.slip_angle]
)";
  const auto r = run_scene(write_scene("relaxation.yaml", scene), {}, false);
  const auto alpha = signal(r, "tyre.slip_angle");
  const double speed = std::sqrt(400.0 + 0.25), target = std::atan(1.0 / speed), tau = 0.45 / speed;
  for (size_t k = 0; k < r.t.size(); k += 20)
    EXPECT_NEAR(alpha[k], target * (1 - std::exp(-r.t[k] / tau)), 1e-7) << r.t[k];
}

}  // namespace
}  // namespace dydp::test
