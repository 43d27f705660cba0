#include "engine/linear/equilibrium.hpp"

#include <cmath>
#include <sstream>

#include "engine/analysis/tolerances.hpp"
#include "engine/evaluation/evaluator.hpp"
#include "engine/framework/errors.hpp"
#include "engine/linear/linearization.hpp"

namespace dydp::engine {
namespace {

/// Scaled residual r_i = xdot_i / nominal_i, or nothing when a block refuses the point.
bool scaled_residual(Evaluator& e, double t, const std::vector<double>& x, const Eigen::VectorXd& nominal,
                     Eigen::VectorXd& r) {
  std::vector<double> xdot(x.size());
  try {
    e.derivatives(t, x.data(), xdot.data());
  } catch (const OutOfDomain&) {
    return false;
  }
  r = Eigen::Map<const Eigen::VectorXd>(xdot.data(), static_cast<Eigen::Index>(xdot.size())).cwiseQuotient(nominal);
  return r.allFinite();
}

}  // namespace

Equilibrium find_equilibrium(Diagram& d, const EquilibriumOptions& options) {
  const int n = d.num_states;
  Equilibrium eq;
  eq.t = options.time;
  for (int i = 0; i < n; ++i) eq.states.push_back(state_label(d, i));
  std::vector<double> nominals = state_nominals(d);
  const Eigen::VectorXd nominal = Eigen::Map<Eigen::VectorXd>(nominals.data(), n);
  Evaluator e(d, false);
  e.set_segment_start(options.time);
  std::vector<double> x(n);
  e.initial_state(d.time.start, x.data());
  eq.initial = x;
  Eigen::VectorXd r;
  if (!scaled_residual(e, eq.t, x, nominal, r))
    throw SolverError(eq.t, "", "the initial state is outside a block's domain or gives non-finite derivatives");
  // Newton in nominal units z = x / nominal: S^-1 A S dz = -r, minimum-norm, with backtracking
  // on |r| so that a far start does not jump out of the blocks' domains.
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> solver;
  double step = INFINITY;
  for (eq.iterations = 0; eq.iterations < options.max_iterations && step > options.tolerance; ++eq.iterations) {
    const Eigen::MatrixXd A = state_jacobian(e, n, eq.t, x);
    const Eigen::MatrixXd As = nominal.cwiseInverse().asDiagonal() * A * nominal.asDiagonal();
    solver.setThreshold(1e-12);
    solver.compute(As);
    const Eigen::VectorXd dz = -solver.solve(r);
    double alpha = 1.0;
    std::vector<double> trial(n);
    Eigen::VectorXd r_trial;
    for (;;) {
      for (int i = 0; i < n; ++i) trial[i] = x[i] + alpha * dz[i] * nominal[i];
      if (scaled_residual(e, eq.t, trial, nominal, r_trial) && r_trial.norm() <= (1 - 1e-4 * alpha) * r.norm()) break;
      if (r.norm() == 0.0) break;
      alpha *= 0.5;
      if (alpha < 1.0 / 4096) {
        // Newton made no progress: accept the full step's failure as the end.
        alpha = 0.0;
        break;
      }
    }
    if (alpha == 0.0) break;
    step = alpha * dz.lpNorm<Eigen::Infinity>();
    x = trial;
    r = r_trial;
  }
  eq.x = x;
  eq.residual = n ? r.lpNorm<Eigen::Infinity>() : 0.0;
  // Converged: the step fell below the tolerance with a residual of rounding size (the
  // residual is in 1/s: relative to the largest rate the Jacobian gives at x*).
  const Eigen::MatrixXd A = state_jacobian(e, n, eq.t, x);
  const Eigen::MatrixXd As = nominal.cwiseInverse().asDiagonal() * A * nominal.asDiagonal();
  solver.compute(As);
  eq.rank_deficiency = n - static_cast<int>(solver.rank());
  const double rate = n ? As.cwiseAbs().maxCoeff() : 0.0;
  if (step > options.tolerance && !(eq.residual <= 1e-10 * rate)) {
    int worst = 0;
    if (n) r.cwiseAbs().maxCoeff(&worst);
    std::ostringstream why;
    why << "no equilibrium in reach: after " << eq.iterations << " Newton iterations the state derivatives are still "
        << eq.residual << " nominal units per second (largest: " << (n ? eq.states[worst] : "") << ")";
    throw SolverError(eq.t, n ? eq.states[worst].substr(0, eq.states[worst].rfind('.')) : "", why.str());
  }
  // dx*/dp: A dx = -f_p, in nominal units, minimum-norm like the steps.
  eq.parameters = differentiable_parameters(d);
  const int np = static_cast<int>(eq.parameters.size());
  eq.dx_dp = Eigen::MatrixXd::Zero(n, np);
  if (np > 0 && n > 0) {
    const std::vector<int> saved = d.sensitivities;
    d.set_sensitivities(eq.parameters);
    Evaluator ep(d, true);
    ep.set_segment_start(eq.t);
    Eigen::MatrixXd fp(n, np);
    ep.tangents(eq.t, x.data(), np, {}, true, {fp.data(), n}, {});
    d.set_sensitivities(saved);
    eq.dx_dp = nominal.asDiagonal() * solver.solve(-(nominal.cwiseInverse().asDiagonal() * fp));
  }
  return eq;
}

}  // namespace dydp::engine
