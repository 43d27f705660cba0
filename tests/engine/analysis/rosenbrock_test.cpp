// The Rosenbrock-W scheme (rosw) on the mass-spring-damper scene (scenarios/msd_sensitivity.yaml):
// - its sensitivities are the derivative of its discrete map with W held constant: central
//   differences of runs with one W for all of them agree with them (step study: the difference
//   error falls as delta^2 until rounding), for the signals on the grid and the objective;
// - runs that evaluate W themselves (W = J(p), so W moves with p) differ from that derivative by
//   the neglected dW/dp term, which is of the order of the discretisation error: it falls as h^2;
// - states, sensitivities and the objective converge at order 2 to the closed form;
// - its gamma, a literal, is 1 - 1/sqrt 2.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "engine/analysis/rosenbrock_solver.hpp"
#include "engine/analysis/run.hpp"
#include "engine/analysis/step_driver.hpp"
#include "engine/analysis/timeline.hpp"
#include "engine/evaluation/evaluator.hpp"
#include "engine/framework/diagram.hpp"
#include "tests/engine/msd_closed_form.hpp"
#include "tests/grid_error.hpp"

namespace dydp::engine {
namespace {

using test::grid_error;

const std::string kScene = std::string(DYDP_SOURCE_DIR) + "/scenarios/msd_sensitivity.yaml";
constexpr double kWindowFrom = 2.0, kWindowTo = 10.0;

// ROS2's and SDIRK2's gamma is a literal so that it is initialised before any other file's
// constants read it: it must be the double that 1 - 1/sqrt 2 rounds to.
TEST(Rosenbrock, GammaIsOneMinusOneOverRootTwo) {
  const double root_two = std::sqrt(2.0);
  EXPECT_EQ(kGamma2, 1.0 - 1.0 / root_two);
}

Diagram load(double step) {
  Diagram d = load_scene(kScene);
  d.solver.method = "rosw";
  d.solver.step = step;
  return d;
}

/// The scene's values, read from the diagram (mass, stiffness, damping, then the fixed ones).
test::MsdParams<double> params(const Diagram& d) {
  auto value = [&](const char* name) {
    for (const auto& p : d.parameters)
      if (p.name == name) return p.value;
    ADD_FAILURE() << "no parameter " << name;
    return 0.0;
  };
  return {value("mass"), value("stiffness"), value("damping"), 2.0, 2 * std::numbers::pi * 0.8, 0.05, 0.0};
}

/// J = df/dx at the initial state: the W given to every run of the discrete-map tests.
std::vector<double> initial_jacobian(const Diagram& d) {
  Evaluator ev(d, false);
  const int nx = d.num_states;
  std::vector<double> x(nx), identity(nx * nx, 0.0), jac(nx * nx);
  for (int i = 0; i < nx; ++i) identity[i * nx + i] = 1.0;
  ev.set_segment_start(d.time.start);
  ev.initial_state(d.time.start, x.data());
  ev.tangents(d.time.start, x.data(), nx, {identity.data(), nx}, false, {jac.data(), nx}, {});
  return jac;
}

std::vector<double> signal(const RunResult& r, int i) {
  std::vector<double> v;
  for (size_t k = 0; k < r.t.size(); ++k) v.push_back(r.value(static_cast<int>(k), i));
  return v;
}
std::vector<double> sensitivity(const RunResult& r, int d, int i) {
  std::vector<double> v;
  for (size_t k = 0; k < r.t.size(); ++k) v.push_back(r.tangent(static_cast<int>(k), d, i));
  return v;
}

/// Central difference of runs at p_j +- delta, each made by `run_at`, against the exact
/// sensitivities of `r`: signal body.x on the grid, and the objective.
struct DifferenceErrors {
  double signal, objective;
};
template <class RunAt>
DifferenceErrors difference_errors(const Diagram& base, const RunResult& r, int j, double delta, RunAt run_at) {
  const int param = base.sensitivities[j];
  const double p0 = base.parameters[param].value;
  Diagram plus = load(base.solver.step), minus = load(base.solver.step);
  plus.set_parameter(param, p0 + delta);
  minus.set_parameter(param, p0 - delta);
  const RunResult rp = run_at(plus), rm = run_at(minus);
  const int ix = r.signal_index("body.x");
  std::vector<double> fd;
  for (size_t k = 0; k < r.t.size(); ++k)
    fd.push_back((rp.value(static_cast<int>(k), ix) - rm.value(static_cast<int>(k), ix)) / (2 * delta));
  const double fd_psi = (rp.objectives[0].value - rm.objectives[0].value) / (2 * delta);
  return {grid_error(sensitivity(r, j, ix), fd),
          std::fabs(r.objectives[0].sensitivity[j] - fd_psi) / std::fabs(fd_psi)};
}

TEST(Rosenbrock, SensitivitiesAreTheDerivativeOfTheMapWithWConstant) {
  const Diagram d = load(0.01);
  const std::vector<double> w = initial_jacobian(d);
  const RunResult r = run_rosenbrock_fixed_w(d, {}, w);
  EXPECT_EQ(r.stats.jac_evals, 0);
  for (int j = 0; j < 3; ++j) {
    const double p0 = d.parameters[d.sensitivities[j]].value;
    auto run_at = [&](const Diagram& at) { return run_rosenbrock_fixed_w(at, {}, w); };
    // Step study: the central difference's own error falls as delta^2 (100x per decade) while
    // it is above rounding; the best of the ladder is the discrete map's derivative.
    const DifferenceErrors coarse = difference_errors(d, r, j, 1e-2 * p0, run_at);
    const DifferenceErrors finer = difference_errors(d, r, j, 1e-3 * p0, run_at);
    EXPECT_LT(finer.signal, coarse.signal / 50) << "direction " << j;
    EXPECT_LT(finer.objective, coarse.objective / 50) << "direction " << j;
    double best_signal = finer.signal, best_objective = finer.objective;
    for (double rel : {1e-4, 1e-5}) {
      const DifferenceErrors e = difference_errors(d, r, j, rel * p0, run_at);
      best_signal = std::min(best_signal, e.signal);
      best_objective = std::min(best_objective, e.objective);
    }
    EXPECT_LT(best_signal, 1e-8) << "direction " << j;
    EXPECT_LT(best_objective, 1e-8) << "direction " << j;
  }
}

TEST(Rosenbrock, OwnJacobiansMoveTheMapByTheDiscretisationErrorOnly) {
  // W = J(p) here: central differences of the runs see dW/dp, the recursion does not. That
  // term is O(h^3) per step (W enters a step at h^3), so the gap falls as h^2 with the step.
  double gap[2];
  for (int i = 0; i < 2; ++i) {
    const Diagram d = load(i == 0 ? 0.01 : 0.005);
    const RunResult r = run(d);
    const double p0 = d.parameters[d.sensitivities[1]].value;  // stiffness
    gap[i] = difference_errors(d, r, 1, 1e-4 * p0, [](const Diagram& at) { return run(at); }).signal;
  }
  EXPECT_GT(gap[0], 1e-7) << "W's dependence on p no longer shows: is W still J(p)?";
  EXPECT_GT(gap[0] / gap[1], 3.5);
  EXPECT_LT(gap[0] / gap[1], 4.5);
}

TEST(Rosenbrock, ConvergesAtOrderTwoToTheClosedForm) {
  // Position and its sensitivities to m, k, c on the grid, the rms objective and its
  // sensitivities: errors against the closed form at h, h/2, h/4 fall by 4 each time.
  const double steps[3] = {0.01, 0.005, 0.0025};
  double err[3][8];
  for (int s = 0; s < 3; ++s) {
    const Diagram d = load(steps[s]);
    const RunResult r = run(d);
    EXPECT_EQ(r.stats.method, "rosw");
    EXPECT_EQ(r.stats.substeps, 0);
    const auto p = params(d);
    const int ix = r.signal_index("body.x");
    std::vector<double> x_ref;
    for (double t : r.t) x_ref.push_back(test::msd_position(p, t));
    err[s][0] = grid_error(signal(r, ix), x_ref);
    for (int j = 0; j < 3; ++j) {
      std::vector<double> dx_ref;
      for (double t : r.t)
        dx_ref.push_back(test::complex_step(
            [t](const test::MsdParams<std::complex<double>>& pc) { return test::msd_position(pc, t); }, p, j));
      err[s][1 + j] = grid_error(sensitivity(r, j, ix), dx_ref);
    }
    auto rms = [](const test::MsdParams<std::complex<double>>& pc) {
      const auto integral = test::gauss_legendre<std::complex<double>>(
          [&](double t) { const auto x = test::msd_position(pc, t); return x * x; }, kWindowFrom, kWindowTo, 4000);
      return std::sqrt(integral / (kWindowTo - kWindowFrom));
    };
    const test::MsdParams<std::complex<double>> pc{p.m, p.k, p.c, p.amplitude, p.omega, p.x0, p.v0};
    const double psi = rms(pc).real();
    err[s][4] = std::fabs(r.objectives[0].value - psi) / psi;
    for (int j = 0; j < 3; ++j) {
      const double g = test::complex_step(rms, p, j);
      err[s][5 + j] = std::fabs(r.objectives[0].sensitivity[j] - g) / std::fabs(g);
    }
  }
  const char* what[8] = {"x", "dx/dm", "dx/dk", "dx/dc", "psi", "dpsi/dm", "dpsi/dk", "dpsi/dc"};
  for (int i = 0; i < 8; ++i) {
    for (int s = 0; s < 2; ++s) {
      const double ratio = err[s][i] / err[s + 1][i];
      EXPECT_GT(ratio, 3.5) << what[i] << " at h = " << steps[s];
      EXPECT_LT(ratio, 4.5) << what[i] << " at h = " << steps[s];
    }
    EXPECT_LT(err[0][i], 1e-2) << what[i];  // and not order 2 of something far off
  }
}

TEST(Rosenbrock, KeepsItsJacobianOverManySteps) {
  const Diagram d = load(0.001);
  const RunResult r = run(d);
  EXPECT_EQ(r.stats.steps, 10000);
  // Two right-hand sides a step (the second stage and the next step's first, at the new
  // state), one at the start and one after each breakpoint, where the right-hand side may jump.
  EXPECT_EQ(r.stats.rhs_evals, 2 * r.stats.steps + 1 + static_cast<long>(Timeline(d).breaks.size()));
  EXPECT_LT(r.stats.jac_evals, r.stats.steps / 20);
  EXPECT_GT(r.stats.jac_evals, 0);
  EXPECT_EQ(r.stats.nonlinear_iterations, 0);
}

}  // namespace
}  // namespace dydp::engine
