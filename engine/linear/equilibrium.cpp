#include "engine/linear/equilibrium.hpp"

#include <cmath>
#include <sstream>

#include "engine/analysis/tolerances.hpp"
#include "engine/evaluation/evaluator.hpp"
#include "engine/framework/errors.hpp"
#include "engine/linear/linearization.hpp"

namespace dydp::engine {
namespace {

/// Scaled residual r_i = xdot_i / nominal_i, or false when a block refuses the point (`why`
/// then says which and why) or a derivative is not finite.
bool scaled_residual(Evaluator& e, double t, const std::vector<double>& x, const Eigen::VectorXd& nominal,
                     Eigen::VectorXd& r, std::string* why = nullptr) {
  std::vector<double> xdot(x.size());
  try {
    e.derivatives(t, x.data(), xdot.data());
  } catch (const OutOfDomain& refused) {
    if (why) *why = refused.reason;
    return false;
  }
  r = Eigen::Map<const Eigen::VectorXd>(xdot.data(), static_cast<Eigen::Index>(xdot.size())).cwiseQuotient(nominal);
  if (!r.allFinite() && why) *why = e.find_nonfinite(xdot.data());
  return r.allFinite();
}

/// The Jacobian in nominal units, S^-1 A S, the held signals' tangents at zero.
Eigen::MatrixXd scaled_jacobian(Evaluator& e, double t, const std::vector<double>& x, const Eigen::VectorXd& nominal,
                                const std::vector<int>& held) {
  const Eigen::MatrixXd A = state_jacobian(e, static_cast<int>(x.size()), t, x, held);
  return nominal.cwiseInverse().asDiagonal() * A * nominal.asDiagonal();
}

/// The left null space of As (columns: c^T As = 0): the conserved quantities' gradients there
/// (oil in a damper, a free body's momentum), from the singular values below 1e-10 of the largest.
Eigen::MatrixXd left_null_space(const Eigen::MatrixXd& As) {
  const Eigen::BDCSVD<Eigen::MatrixXd> svd(As, Eigen::ComputeFullU);
  const Eigen::VectorXd& s = svd.singularValues();
  const double limit = 1e-10 * (s.size() ? s[0] : 0.0);
  Eigen::Index rank = 0;
  while (rank < s.size() && s[rank] > limit) ++rank;
  return svd.matrixU().rightCols(As.rows() - rank);
}

struct Newton {
  std::vector<double> x;
  Eigen::VectorXd r;
  int iterations = 0;
  double step = INFINITY;
};

/// Damped Newton on r(z) = 0 in nominal units z = x / nominal, each step the least-squares
/// solution of [As; G^T] dz = [-r; -G^T (z - z0)]: with G empty the minimum-norm Newton step,
/// with G the conserved quantities' gradients, steps that keep G^T z at its start value.
Newton solve(Evaluator& e, double t, std::vector<double> x, const Eigen::VectorXd& nominal, const Eigen::MatrixXd& G,
             const EquilibriumOptions& options, const std::vector<int>& held) {
  const int n = static_cast<int>(x.size());
  const Eigen::VectorXd z0 = Eigen::Map<const Eigen::VectorXd>(x.data(), n).cwiseQuotient(nominal);
  Newton out;
  std::string why;
  if (!scaled_residual(e, t, x, nominal, out.r, &why))
    throw SolverError(t, "", "the state Newton starts from is refused: " + why);
  const auto merit = [&](const std::vector<double>& at, const Eigen::VectorXd& r) {
    const Eigen::VectorXd z = Eigen::Map<const Eigen::VectorXd>(at.data(), n).cwiseQuotient(nominal);
    return std::hypot(r.norm(), G.cols() ? (G.transpose() * (z - z0)).norm() : 0.0);
  };
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> ls;
  for (; out.iterations < options.max_iterations && out.step > options.tolerance; ++out.iterations) {
    const Eigen::MatrixXd As = scaled_jacobian(e, t, x, nominal, held);
    Eigen::MatrixXd M(n + G.cols(), n);
    M << As, G.transpose();
    const Eigen::VectorXd z = Eigen::Map<const Eigen::VectorXd>(x.data(), n).cwiseQuotient(nominal);
    Eigen::VectorXd rhs(n + G.cols());
    rhs << -out.r, -(G.transpose() * (z - z0));
    ls.setThreshold(1e-12);
    ls.compute(M);
    const Eigen::VectorXd dz = ls.solve(rhs);
    const double before = merit(x, out.r);
    double alpha = 1.0;
    std::vector<double> trial(n);
    Eigen::VectorXd r_trial;
    while (alpha > 0.0) {
      for (int i = 0; i < n; ++i) trial[i] = x[i] + alpha * dz[i] * nominal[i];
      if (scaled_residual(e, t, trial, nominal, r_trial) && merit(trial, r_trial) <= (1 - 1e-4 * alpha) * before) break;
      alpha = alpha > 1.0 / 4096 ? alpha / 2 : 0.0;  // no progress: the end of the iteration
    }
    if (alpha == 0.0) break;
    out.step = alpha * dz.lpNorm<Eigen::Infinity>();
    x = trial;
    out.r = r_trial;
  }
  out.x = std::move(x);
  return out;
}

/// The diagram's own motion toward its equilibrium with the inputs held: linearly implicit
/// Euler steps of `h` (L-stable: the stiff hydraulics are damped at any step), which keep the
/// conserved quantities to second order in each step, so that many small steps bring the state
/// near x* with them nearly as a run keeps them: their error is first order in h, which the
/// caller's Richardson extrapolation removes.
std::vector<double> settle(Evaluator& e, double t, std::vector<double> x, const Eigen::VectorXd& nominal, double h,
                           int steps, const std::vector<int>& held) {
  const int n = static_cast<int>(x.size());
  Eigen::VectorXd r;
  for (int k = 0; k < steps; ++k) {
    if (!scaled_residual(e, t, x, nominal, r)) break;
    const Eigen::MatrixXd As = scaled_jacobian(e, t, x, nominal, held);
    const Eigen::VectorXd dz = (Eigen::MatrixXd::Identity(n, n) - h * As).partialPivLu().solve(h * r);
    if (!dz.allFinite()) break;
    for (int i = 0; i < n; ++i) x[i] += dz[i] * nominal[i];
  }
  return x;
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
  e.hold_signals(options.held);
  eq.held = options.held;
  std::vector<int> held;
  for (const auto& h : options.held) held.push_back(h.first);
  std::vector<double> x0(n);
  e.initial_state(d.time.start, x0.data());
  eq.initial = x0;
  // Converged: the step fell below the tolerance, or the residual is of rounding size against
  // the largest rate the (scaled) Jacobian gives there (both in 1/s).
  const auto require_converged = [&](const Newton& at, const Eigen::MatrixXd& jacobian) {
    const double residual = n ? at.r.lpNorm<Eigen::Infinity>() : 0.0;
    const double rate = n ? jacobian.cwiseAbs().maxCoeff() : 0.0;
    if (at.step <= options.tolerance || residual <= 1e-10 * rate) return;
    int worst = 0;
    if (n) at.r.cwiseAbs().maxCoeff(&worst);
    std::ostringstream why;
    why << "no equilibrium in reach: after " << at.iterations << " Newton iterations the state derivatives are still "
        << residual << " nominal units per second (largest: " << (n ? eq.states[worst] : "") << ")";
    std::string block;
    for (const Node& node : d.nodes)
      if (worst >= node.state_offset && worst < node.state_offset + node.block->num_states()) block = node.name;
    throw SolverError(eq.t, block, why.str());
  };
  // A first solution finds the conserved quantities (the left null space of the Jacobian at an
  // equilibrium: oil in a damper, a free body's momentum). If there are any, the state first
  // moves toward x* as the diagram would (settle), which keeps them as a run does; Newton from
  // there holds them at that state's values to second order in the (now small) distance.
  Newton sol = solve(e, eq.t, x0, nominal, Eigen::MatrixXd(n, 0), options, held);
  Eigen::MatrixXd As = scaled_jacobian(e, eq.t, sol.x, nominal, held);
  require_converged(sol, As);
  Eigen::MatrixXd G = left_null_space(As);
  // The parameters' evaluator (f_p, the initial state's tangent) and dz0/dp.
  eq.parameters = differentiable_parameters(d);
  const int np = static_cast<int>(eq.parameters.size());
  // The diagram's directions are the parameters' while ep lives; given back on every exit.
  struct RestoreSensitivities {
    Diagram& d;
    std::vector<int> saved;
    ~RestoreSensitivities() { d.set_sensitivities(saved); }
  } restore{d, d.sensitivities};
  d.set_sensitivities(eq.parameters);
  Evaluator ep(d, true);
  ep.set_segment_start(eq.t);
  ep.hold_signals(options.held);
  ep.set_signal_seeds(held, std::vector<double>(held.size() * np, 0.0));
  Eigen::MatrixXd dx0(n, np);
  ep.initial_state_tangent(d.time.start, x0.data(), {dx0.data(), n});
  // The tangent of the conserved quantities' values that Newton holds: the initial state's.
  const Eigen::MatrixXd D_start = nominal.cwiseInverse().asDiagonal() * dx0;
  if (G.cols() > 0) {
    // Two step sizes over the same time, extrapolated (Richardson): the conserved quantities'
    // first-order error in h cancels. Measured on the sedan against the state a 60 s run
    // settles to (2026-12-07): 5e-8 of travel at h = 10 ms alone, 1.3e-8 at 2 ms alone (0.6 s),
    // 8e-9 extrapolated from 10 and 5 ms (0.26 s).
    const double T = options.settle_time;
    const int N = options.settle_steps;
    const std::vector<double> coarse = settle(e, eq.t, x0, nominal, T / N, N, held);
    const std::vector<double> fine = settle(e, eq.t, x0, nominal, T / (2 * N), 2 * N, held);
    std::vector<double> start(n);
    for (int i = 0; i < n; ++i) start[i] = 2 * fine[i] - coarse[i];
    Eigen::VectorXd r;
    if (!scaled_residual(e, eq.t, start, nominal, r)) start = fine;  // extrapolated out of a domain
    for (int round = 0; round < 2; ++round) {
      sol = solve(e, eq.t, start, nominal, G, options, held);
      G = left_null_space(scaled_jacobian(e, eq.t, sol.x, nominal, held));
    }
    // The constraints' gradients are those of the previous round, so the least-squares steps
    // leave a residual of their mismatch (1e-6 /s on the sedan): minimum-norm Newton steps from
    // there remove it, moving the conserved quantities by the square of those steps.
    const int iterations = sol.iterations;
    sol = solve(e, eq.t, sol.x, nominal, Eigen::MatrixXd(n, 0), options, held);
    sol.iterations += iterations;
    As = scaled_jacobian(e, eq.t, sol.x, nominal, held);
    require_converged(sol, As);
  }
  eq.x = sol.x;
  eq.iterations = sol.iterations;
  eq.residual = n ? sol.r.lpNorm<Eigen::Infinity>() : 0.0;
  eq.rank_deficiency = static_cast<int>(G.cols());
  // dx*/dp: As dz = -f_p with the conserved quantities' linearisation at x* held at the
  // initial state's, G^T dz = G^T dz0/dp. Exact where p does not change how a conserved quantity
  // reads the states; where it does (a mount point changes a damper's stroke, hence the oil its
  // pressures hold; the gas volume and pre-charge its gas law) the term G_p^T (x* - x0) is
  // missing: on the sedan the front pressures' d/d(strut mount) is 3 % off, the eigenvalue
  // derivatives up to 2.7e-4 of |lambda| / |p| (docs/studies.md). A tangent of the
  // settling motion would carry the term; its backward Euler form diverged at 5 ms steps.
  eq.dx_dp = Eigen::MatrixXd::Zero(n, np);
  if (np > 0 && n > 0) {
    Eigen::MatrixXd fp(n, np);
    ep.tangents(eq.t, eq.x.data(), np, {}, true, {fp.data(), n}, {});
    Eigen::MatrixXd M(n + G.cols(), n), rhs(n + G.cols(), np);
    M << As, G.transpose();
    rhs << -(nominal.cwiseInverse().asDiagonal() * fp), G.transpose() * D_start;
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> ls;
    ls.setThreshold(1e-12);
    ls.compute(M);
    eq.dx_dp = nominal.asDiagonal() * ls.solve(rhs);
  }
  return eq;
}

}  // namespace dydp::engine
