// The diagram's adjoint pass against its tangent pass: for random weights lambda on the state
// derivatives and wq on the quadratures, and random state directions v, <lambda, f_x v> +
// <wq, q_x v> equals <f_x^T lambda + q_x^T wq, v>, and for every sensitivity direction (all the
// scene's parameters and declared directions) <lambda, f_p> + <wq, q_p> equals the adjoint's
// parameter product, on the sedan on its 4-poster (subsystems flattened, dampers, tyres, the
// generated multibody model) and on the quarter car. Also the initial state's adjoint.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "engine/analysis/tolerances.hpp"
#include "engine/evaluation/evaluator.hpp"
#include "engine/framework/diagram.hpp"

namespace dydp::engine {
namespace {

/// |a - b| against the size of the terms that summed to them.
void expect_dot_equal(double reverse, double forward, double magnitude, const std::string& what) {
  EXPECT_NEAR(reverse, forward, 1e-12 * magnitude + 1e-300)
      << what << ": adjoint " << reverse << ", tangent " << forward << " (terms of size " << magnitude << ")";
}

void check_scene(const std::string& scene, double t, int adjoint_directions) {
  Diagram d = load_scene(std::string(DYDP_SOURCE_DIR) + "/scenarios/" + scene);
  std::vector<int> all(d.parameters.size());
  std::iota(all.begin(), all.end(), 0);
  d.set_sensitivities(all);
  const int nx = d.num_states, nq = d.num_quadratures, ns = static_cast<int>(all.size()), nm = adjoint_directions;
  ASSERT_GT(nx, 0);
  ASSERT_GT(nq, 0);
  Evaluator ev(d, true);
  std::vector<double> x(nx);
  ev.set_segment_start(t);
  ev.initial_state(d.time.start, x.data());
  // a state near the initial one, each moved by a tenth of its nominal magnitude
  const std::vector<double> nominal = state_nominals(d);
  std::mt19937_64 rng(2026);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int i = 0; i < nx; ++i) x[i] += 0.1 * nominal[i] * unit(rng);

  // forward: f_x v, q_x v for nm random v; f_p, q_p along every direction
  std::vector<double> v(static_cast<size_t>(nx) * nm), fxv(v.size()), qxv(static_cast<size_t>(nq) * nm);
  for (int m = 0; m < nm; ++m)
    for (int i = 0; i < nx; ++i) v[m * nx + i] = nominal[i] * unit(rng);
  ev.tangents(t, x.data(), nm, {v.data(), nx}, false, {fxv.data(), nx}, {qxv.data(), nq});
  std::vector<double> fp(static_cast<size_t>(nx) * ns), qp(static_cast<size_t>(nq) * ns);
  ev.tangents(t, x.data(), ns, {}, true, {fp.data(), nx}, {qp.data(), nq});

  // reverse
  std::vector<double> lambda(static_cast<size_t>(nx) * nm), wq(static_cast<size_t>(nq) * nm);
  for (int m = 0; m < nm; ++m) {
    for (int i = 0; i < nx; ++i) lambda[m * nx + i] = unit(rng) / nominal[i];
    for (int j = 0; j < nq; ++j) wq[m * nq + j] = unit(rng);
  }
  std::vector<double> ax(static_cast<size_t>(nx) * nm, 0.0), ap(static_cast<size_t>(ns) * nm, 0.0);
  ev.adjoint(t, x.data(), nm, {lambda.data(), nx}, {wq.data(), nq}, {ax.data(), nx}, {ap.data(), ns});

  // every weight direction against every tangent direction
  for (int m = 0; m < nm; ++m) {
    for (int k = 0; k < nm; ++k) {
      double forward = 0, reverse = 0, magnitude = 0;
      for (int i = 0; i < nx; ++i) {
        forward += lambda[m * nx + i] * fxv[k * nx + i];
        magnitude += std::fabs(lambda[m * nx + i] * fxv[k * nx + i]);
        reverse += ax[m * nx + i] * v[k * nx + i];
        magnitude += std::fabs(ax[m * nx + i] * v[k * nx + i]);
      }
      for (int j = 0; j < nq; ++j) {
        forward += wq[m * nq + j] * qxv[k * nq + j];
        magnitude += std::fabs(wq[m * nq + j] * qxv[k * nq + j]);
      }
      expect_dot_equal(reverse, forward, magnitude, scene + ": states, weights " + std::to_string(m) + ", direction " + std::to_string(k));
    }
    for (int dir = 0; dir < ns; ++dir) {
      double forward = 0, magnitude = 0;
      for (int i = 0; i < nx; ++i) {
        forward += lambda[m * nx + i] * fp[dir * nx + i];
        magnitude += std::fabs(lambda[m * nx + i] * fp[dir * nx + i]);
      }
      for (int j = 0; j < nq; ++j) {
        forward += wq[m * nq + j] * qp[dir * nq + j];
        magnitude += std::fabs(wq[m * nq + j] * qp[dir * nq + j]);
      }
      expect_dot_equal(ap[m * ns + dir], forward, magnitude + std::fabs(ap[m * ns + dir]),
                       scene + ": parameter " + d.parameters[dir].name + ", weights " + std::to_string(m));
    }
  }
  // the adjoint saw the parameters at all: some direction moves the derivatives
  double moved = 0;
  for (double a : ap) moved += std::fabs(a);
  EXPECT_GT(moved, 0.0) << scene;

  // the initial state: <w, dx0/dp> against its adjoint
  std::vector<double> dx0(static_cast<size_t>(nx) * ns), x0(nx), ap0(static_cast<size_t>(ns) * nm, 0.0);
  ev.initial_state(d.time.start, x0.data());
  ev.initial_state_tangent(d.time.start, x0.data(), {dx0.data(), nx});
  ev.initial_state_adjoint(d.time.start, x0.data(), nm, {lambda.data(), nx}, {ap0.data(), ns});
  for (int m = 0; m < nm; ++m)
    for (int dir = 0; dir < ns; ++dir) {
      double forward = 0, magnitude = 0;
      for (int i = 0; i < nx; ++i) {
        forward += lambda[m * nx + i] * dx0[dir * nx + i];
        magnitude += std::fabs(lambda[m * nx + i] * dx0[dir * nx + i]);
      }
      expect_dot_equal(ap0[m * ns + dir], forward, magnitude + std::fabs(ap0[m * ns + dir]),
                       scene + ": initial state by " + d.parameters[dir].name);
    }
}

TEST(AdjointPass, IsTheTransposeOfTheTangentPassOnTheSedanFourposter) { check_scene("fourposter_comfort.yaml", 2.5, 2); }

TEST(AdjointPass, IsTheTransposeOfTheTangentPassOnTheQuarterCar) { check_scene("quarter_car_cdc.yaml", 0.7, 1); }

}  // namespace
}  // namespace dydp::engine
