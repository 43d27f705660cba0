#include "engine/rosenbrock_solver.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <string>

#include "engine/cpu_clock.hpp"
#include "engine/errors.hpp"
#include "engine/jacobian_colouring.hpp"
#include "engine/newton_lu.hpp"
#include "engine/recorder.hpp"
#include "engine/timeline.hpp"
#include "engine/tolerances.hpp"

namespace dydp::engine {
namespace {

using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic>;
using Vector = Eigen::VectorXd;

// ROS2 of J. G. Verwer, E. J. Spee, J. G. Blom, W. Hundsdorfer, "A second-order Rosenbrock
// method applied to photochemical dispersion problems", SIAM J. Sci. Comput. 20(4), 1456-1480
// (1999), section 2:
//   (I - gamma h W) k1 = f(tn, yn)
//   (I - gamma h W) k2 = f(tn + h, yn + h k1) - 2 k1
//   y(n+1) = yn + 3/2 h k1 + 1/2 h k2.
// Order 2 for any W and any gamma: expanding, k1 = f + gamma h W f + O(h^2) and
// k2 = -f + h (J f + f_t) - 3 gamma h W f + O(h^2), so the W terms of 3/2 k1 + 1/2 k2 cancel and
// y(n+1) = yn + h f + h^2/2 (J f + f_t) + O(h^3). With W = J its stability function is
// R(z) = (1 + (1 - 2 gamma) z + (gamma^2 - 2 gamma + 1/2) z^2) / (1 - gamma z)^2, L-stable for
// gamma = 1 +- 1/sqrt 2. The paper takes the + root (for positivity); here the - root, which is
// A-stable as well (gamma >= 1/4) and whose error constant on y' = lambda y is 34 times smaller
// (1/6 - 3 gamma^2 + 2 gamma^3: -0.040 against 1.37), the same gamma as SDIRK2's.
const double kGamma = 1.0 - 1.0 / std::sqrt(2.0);
/// W is evaluated afresh after this many steps; in between, the diagonal blocks that blocks
/// provide cheaply (Block::local_jacobian: the damper's pressures) are refreshed at every step.
/// Without that, ROS2 is unstable on the damper's orifice laws at any step tried on the sedan
/// (a linearised step overshoots where the flow goes as the square root of the pressure drop and
/// the slope there moves within the step); docs/performance.md, 2026-12-02.
const int kRefreshSteps = 50;
/// With local stages W carries the rest of the diagram (the car, its couplings to the local
/// blocks) and none of the stiff laws: kept 4 times longer. On the sedan's shaker file it costs
/// 4 % of the run at every 50 steps, and at every 200 the errors do not move (docs/performance.md).
const int kRefreshStepsLocal = 200;
/// A step whose embedded error estimate grows by more than this factor over the last step's
/// (and exceeds kDivergenceFloor) while W is older than the step is taken again with W evaluated
/// at its start: a stale W on a stiff component shows as such a jump before it blows up.
const double kDivergenceGrowth = 10.0;
const double kDivergenceFloor = 1e-3;
/// A step whose stage fails (non-finite value, state refused by a block) with a fresh W is taken
/// as two of half the size, down to 1/2^this of the scene's step; then the run stops.
const int kMaxHalvings = 6;
/// The local stages' Newton iteration: converged when its last correction moves no local state
/// by more than this fraction of its nominal magnitude (or of its value, where larger); a stage
/// that has not converged in kLocalIterations is taken in halves like a failed one.
const double kLocalTolerance = 1e-6;
/// The iteration keeps the matrix of the last stage (its local blocks at that stage's solution)
/// while each correction is at most this fraction of the one before; a slower one, as where a
/// valve opens within the step, has the local blocks evaluated at the current iterate.
const double kRefactorRate = 0.1;
const int kLocalIterations = 10;

/// A stage's value was not finite, or a block refused its state: the step is retried.
struct StageFailure {
  double t;
  std::string block, why;
};

/// The scheme's state (x, q and their sensitivities S, Sq), W and its factorisation, and the
/// start-of-step evaluations f(tn, xn), g(tn, xn) and their tangents, which the last step's
/// end (or the record at an output time) already made.
class Ros2Stepper {
 public:
  Ros2Stepper(const Diagram& d, Evaluator& ev, int ns, RunStats& stats, const std::vector<double>* fixed_w)
      : ev_(ev), nx_(d.num_states), nq_(d.num_quadratures), ns_(ns), stats_(stats), fixed_(fixed_w != nullptr),
        w_(nx_, nx_), identity_(Matrix::Identity(nx_, nx_)), colouring_(d) {
    stats_.jacobian_colours = colouring_.colours();
    const std::vector<double> nominal = state_nominals(d);
    scale_ = Eigen::Map<const Vector>(nominal.data(), nx_);
    if (fixed_) w_ = Eigen::Map<const Matrix>(fixed_w->data(), nx_, nx_);
    const int nx1 = std::max(nx_, 1), nq1 = std::max(nq_, 1);
    for (Vector* v : {&f_start_, &f_end_, &f_stage_, &k1_, &k2_, &y_stage_, &x_end_}) v->setZero(nx1);
    for (Vector* v : {&g_start_, &g_end_, &g_stage_, &q_end_}) v->setZero(nq1);
    for (Matrix* m : {&df_start_, &df_end_, &df_stage_, &dk1_, &dk2_, &dy_stage_, &s_end_}) m->setZero(nx_, ns_);
    for (Matrix* m : {&dg_start_, &dg_end_, &dg_stage_, &sq_end_}) m->setZero(nq1, ns_);
  }

  double t = 0.0;
  Vector x, q;
  Matrix S, Sq;  ///< dx/dp (nx x ns), dq/dp (max(nq, 1) x ns)

  /// Evaluates the first stage's right-hand side (and tangent) at (t, x): at the start and
  /// after a breakpoint, where the right-hand side may jump. W is evaluated there too.
  void begin() {
    try {
      evaluate(t, x, S, f_start_, g_start_, df_start_, dg_start_);
    } catch (const StageFailure& e) {
      throw SolverError(e.t, e.block, e.why);
    }
    if (!fixed_) refresh(t, x);
    if (!fixed_ && !local_checked_) find_local_states();
  }

  /// Leaves the evaluator's signals and tangents at (t, x) for the recorder.
  void prepare_record() {
    if (ns_ > 0 && !evaluator_at_start_) ev_.tangents(t, x.data(), ns_, {S.data(), nx_}, true, {}, {});
    else ev_.outputs(t, x.data());
    evaluator_at_start_ = true;
  }

  /// Advances by one step of size h, or by its halves when a stage fails.
  void advance(double h, int halvings, double scene_step) {
    for (;;) {
      try {
        const double estimate = attempt(h);
        if (!fixed_ && age_ > 0 && estimate > kDivergenceFloor && estimate > kDivergenceGrowth * last_estimate_) {
          refresh(t, x);  // and take the step again with W at its start
          continue;
        }
        accept(h, estimate);
        return;
      } catch (const StageFailure& failure) {
        if (!fixed_ && age_ > 0 && refreshed(t, x)) continue;  // a stale W first
        if (halvings == kMaxHalvings)
          throw SolverError(failure.t, failure.block,
                            failure.why + " at a step of " + format_number(h) + " s (the scene's step " +
                                format_number(scene_step) + " s halved " + std::to_string(kMaxHalvings) +
                                " times): a linearly implicit step cannot follow the solution here (and, without "
                                "error control, the steps before may already have strayed); use method sdirk2 or "
                                "bdf, or a smaller step for the whole run");
        ++stats_.substeps;
        advance(h / 2, halvings + 1, scene_step);
        advance(h / 2, halvings + 1, scene_step);
        return;
      }
    }
  }

 private:
  /// One step of ROS2 from (t, x) into x_end_ (q_end_, s_end_, sq_end_), with the next step's
  /// first-stage evaluations at its end. Returns the embedded error estimate's weighted rms.
  double attempt(double h) {
    if (h != factored_h_) factor(h);
    // Stage 1: k1 = M^-1 f(tn, xn);  dk1 = M^-1 (f_x S + f_p), W held constant.
    if (local_stages_) {
      // The local stages read the blocks' inputs (and their tangents) at the step's start.
      ev_.outputs(t, x.data());
      if (ns_ > 0 && !evaluator_at_start_) ev_.tangents(t, x.data(), ns_, {S.data(), nx_}, true, {}, {});
      evaluator_at_start_ = true;
      zero_.setZero(nx_);
      local_stage(t, x, f_start_.head(nx_), zero_, h, k1_);
      if (ns_ > 0) {
        dzero_.setZero(nx_, ns_);
        local_stage_tangent(t, x, S, df_start_, dzero_, h, k1_, dk1_);
      }
    } else {
      solve(f_start_.head(nx_), k1_.head(nx_));
      if (ns_ > 0) solve(df_start_, dk1_);
    }
    y_stage_.head(nx_) = x + h * k1_.head(nx_);
    if (ns_ > 0) dy_stage_ = S + h * dk1_;
    // Stage 2 at (tn + h, xn + h k1): k2 = M^-1 (f - 2 k1), and its tangent likewise.
    const double t_end = t + h;
    evaluator_at_start_ = false;
    evaluate(t_end, y_stage_.head(nx_), dy_stage_, f_stage_, g_stage_, df_stage_, dg_stage_);
    if (local_stages_) {
      cv_.noalias() = -2 * k1_;
      local_stage(t_end, y_stage_, f_stage_, cv_, h, k2_);
      if (ns_ > 0) {
        dcv_.noalias() = -2 * dk1_;
        local_stage_tangent(t_end, y_stage_, dy_stage_, df_stage_, dcv_, h, k2_, dk2_);
      }
    } else {
      f_stage_.head(nx_) -= 2 * k1_.head(nx_);
      solve(f_stage_.head(nx_), k2_.head(nx_));
    }
    x_end_.head(nx_) = x + h * (1.5 * k1_.head(nx_) + 0.5 * k2_.head(nx_));
    // The quadratures see W = 0 in their rows: the trapezoidal rule over the two stage points.
    q_end_.head(nq_) = q + 0.5 * h * (g_start_.head(nq_) + g_stage_.head(nq_));
    if (ns_ > 0) {
      if (!local_stages_) {
        df_stage_ -= 2 * dk1_;
        solve(df_stage_, dk2_);
      }
      s_end_ = S + h * (1.5 * dk1_ + 0.5 * dk2_);
      sq_end_.topRows(nq_) = Sq.topRows(nq_) + 0.5 * h * (dg_start_.topRows(nq_) + dg_stage_.topRows(nq_));
    }
    // The next step's first stage, at the new state: a value a block refuses fails this step.
    evaluate(t_end, x_end_.head(nx_), s_end_, f_end_, g_end_, df_end_, dg_end_);
    // Embedded first-order solution xn + h k1: x(n+1) minus it is h/2 (k1 + k2), weighted by
    // the states' nominal magnitudes (or their values, where larger).
    if (nx_ == 0) return 0.0;
    const Vector weight = scale_.cwiseMax(x_end_.head(nx_).cwiseAbs());
    const Vector error = (0.5 * h * (k1_.head(nx_) + k2_.head(nx_))).cwiseQuotient(weight);
    return std::sqrt(error.squaredNorm() / nx_);
  }

  void accept(double h, double estimate) {
    t += h;
    x.swap(x_end_);
    x_end_.resize(std::max(nx_, 1));
    x.conservativeResize(nx_);
    q = q_end_.head(nq_);
    std::swap(f_start_, f_end_);
    std::swap(g_start_, g_end_);
    if (ns_ > 0) {
      std::swap(S, s_end_);
      std::swap(df_start_, df_end_);
      std::swap(dg_start_, dg_end_);
      Sq.topRows(nq_) = sq_end_.topRows(nq_);
    }
    evaluator_at_start_ = true;
    last_estimate_ = estimate;
    ++stats_.steps;
    if (fixed_) return;
    if (++age_ >= (local_stages_ ? kRefreshStepsLocal : kRefreshSteps)) refresh(t, x);
    else if (!local_stages_) refresh_local(t, x);
  }

  /// Finds the states of the blocks that provide Block::local_jacobian (v; the others u). With
  /// any, the stages are solved with those blocks' rows exact (local_stage).
  void find_local_states() {
    local_checked_ = true;
    if (nx_ == 0) return;
    jloc_.setZero(nx_, nx_);
    try {
      if (!ev_.local_jacobians(t, x.data(), jloc_.data(), nx_)) return;
    } catch (const OutOfDomain& e) {
      throw domain_failure(t, e);
    }
    std::vector<char> local(nx_, 0);
    for (const auto& [first, count] : ev_.local_state_ranges())
      for (int i = first; i < first + count; ++i) local[i] = 1;
    for (int i = 0; i < nx_; ++i) (local[i] ? v_ : u_).push_back(i);
    local_stages_ = true;
    has_local_ = false;  // the per-step refresh of W's local blocks is not used
    factored_h_ = -1.0;
    const int nu = static_cast<int>(u_.size()), nv = static_cast<int>(v_.size());
    ru_.setZero(nu), yu_.setZero(nu), xu_.setZero(nu), rv_.setZero(nv), xv_.setZero(nv);
    xi_.setZero(nx_), fv_.setZero(nx_);
  }

  /// M = I - gamma h W partitioned as [A B; C D] over (u, v): A = I - gamma h W_uu factored,
  /// B = -gamma h W_uv, C = -gamma h W_vu, and A^-1 B and C A^-1 B kept for the Schur
  /// complement D - C A^-1 B that each local iteration factors (nv x nv).
  void factor_partitioned(double h) {
    const int nu = static_cast<int>(u_.size()), nv = static_cast<int>(v_.size());
    const double gh = kGamma * h;
    a_.resize(nu, nu), b_.resize(nu, nv), c_.resize(nv, nu);
    for (int j = 0; j < nu; ++j)
      for (int i = 0; i < nu; ++i) a_(i, j) = (i == j ? 1.0 : 0.0) - gh * w_(u_[i], u_[j]);
    for (int j = 0; j < nv; ++j)
      for (int i = 0; i < nu; ++i) b_(i, j) = -gh * w_(u_[i], v_[j]);
    for (int j = 0; j < nu; ++j)
      for (int i = 0; i < nv; ++i) c_(i, j) = -gh * w_(v_[i], u_[j]);
    if (nu > 0) lu_a_.factor(a_.data(), nu);  // a zero pivot shows as a non-finite stage
    ainv_b_ = b_;
    for (int j = 0; j < nv && nu > 0; ++j) lu_a_.solve(ainv_b_.col(j).data(), ainv_b_.col(j).data());
    p_ = c_ * ainv_b_;
    schur_valid_ = false;
  }

  /// Solves M [x_u; x_v] = [r_u; r_v] with the Schur complement factored in schur_.
  void solve_partitioned(const Vector& r_u, const Vector& r_v) {
    yu_ = r_u;
    if (yu_.size() > 0) lu_a_.solve(yu_.data(), yu_.data());
    xv_ = schur_.solve(r_v - c_ * yu_);
    xu_ = yu_ - ainv_b_ * xv_;
  }

  /// Factors S = I - gamma h J_vv(xs) - C A^-1 B, J_vv the local blocks at the states xs.
  void factor_schur(double tb, const Vector& xs, double h) {
    const int nv = static_cast<int>(v_.size());
    ev_.local_jacobians_held(tb, xs.data(), jloc_.data(), nx_);
    ++stats_.local_jac_evals;
    schur_matrix_.resize(nv, nv);
    for (int j = 0; j < nv; ++j)
      for (int i = 0; i < nv; ++i)
        schur_matrix_(i, j) = (i == j ? 1.0 : 0.0) - kGamma * h * jloc_(v_[i], v_[j]) - p_(i, j);
    schur_.compute(schur_matrix_);
    schur_valid_ = true;
  }

  /// A stage of ROS2 with the local blocks' rows exact: k solves
  ///   k_u = fb_u + c_u + gamma h (W_uu k_u + W_uv k_v)                (linear, W as kept)
  ///   k_v = f_v(t, u_b, v_b + gamma h k_v) + c_v + gamma h W_vu k_u    (the blocks' own law)
  /// where f_v is evaluated with the blocks' inputs held at the base point xb (the last value
  /// pass) and fb = f(tb, xb). That is ROS2 with W_vv the secant of f_v over the stage's own
  /// increment instead of its tangent: ROS2 is of order 2 for any W, and the secant cannot
  /// overshoot where a law's slope jumps within the step (a check valve opening). Newton's
  /// iteration from k = 0; its first iterate is the linearly implicit stage itself.
  void local_stage(double tb, const Vector& xb, const Eigen::Ref<const Vector>& fb, const Vector& cv, double h,
                   Vector& k) {
    const int nu = static_cast<int>(u_.size()), nv = static_cast<int>(v_.size());
    const double gh = kGamma * h;
    k.head(nx_).setZero();
    Vector& ku = ku_;
    Vector& kv = kv_;
    ku.setZero(nu);
    kv.setZero(nv);
    xi_ = xb;
    double last_size = 0.0, last_rate = 0.0;
    for (int it = 0; it < kLocalIterations; ++it) {
      try {
        if (it == 0) {
          for (int i = 0; i < nv; ++i) fv_(v_[i]) = fb(v_[i]);
          // The first iterate is the linearly implicit stage itself, with the matrix of the last
          // stage (the states have moved by a stage at most).
          if (!schur_valid_) factor_schur(tb, xi_, h);
        } else {
          for (int i = 0; i < nv; ++i) xi_(v_[i]) = xb(v_[i]) + gh * kv(i);
          ev_.local_derivatives(tb, xi_.data(), fv_.data());
          if (it >= 2 && last_rate > kRefactorRate) factor_schur(tb, xi_, h);
        }
      } catch (const OutOfDomain& e) {
        throw local_failure(tb, e);
      }
      for (int i = 0; i < nv; ++i) rv_(i) = kv(i) - fv_(v_[i]) - cv(v_[i]);
      rv_.noalias() += c_ * ku;
      if (it == 0) {
        for (int i = 0; i < nu; ++i) ru_(i) = -(fb(u_[i]) + cv(u_[i]));
        solve_partitioned(ru_, rv_);
      } else {
        // The u rows are linear and every iterate solves them exactly: their residual is zero.
        xv_ = schur_.solve(rv_);
        xu_.noalias() = -ainv_b_ * xv_;
      }
      ku -= xu_;
      kv -= xv_;
      ++stats_.nonlinear_iterations;
      double size = 0.0;
      for (int i = 0; i < nv; ++i)
        size = std::max(size, std::abs(gh * xv_(i)) / std::max(scale_(v_[i]), std::abs(xb(v_[i]))));
      if (!std::isfinite(size)) break;
      // Converged when the correction, or the one its contraction rate predicts next, is below
      // the tolerance (the usual test of implicit integrators, Hairer and Wanner IV.8).
      const double rate = it > 0 && last_size > 0 ? size / last_size : 1.0;
      if (it > 1 && rate >= 1.0) break;  // diverging
      if (it > 0 && (size <= kLocalTolerance || (rate < 1.0 && rate / (1.0 - rate) * size <= kLocalTolerance))) {
        for (int i = 0; i < nu; ++i) k(u_[i]) = ku(i);
        for (int i = 0; i < nv; ++i) k(v_[i]) = kv(i);
        if (ns_ > 0) {  // the sensitivities' matrix at the stage's solution
          for (int i = 0; i < nv; ++i) xi_(v_[i]) = xb(v_[i]) + gh * kv(i);
          try {
            factor_schur(tb, xi_, h);
          } catch (const OutOfDomain& e) {
            throw local_failure(tb, e);
          }
        }
        return;
      }
      last_size = size;
      last_rate = rate;
    }
    ++stats_.nonlinear_failures;
    throw StageFailure{tb, "", "the local stage's Newton iteration did not converge in " +
                                   std::to_string(kLocalIterations) + " iterations"};
  }

  /// The derivative of local_stage's solution: with M* = [A B; C I - gamma h J_vv(stage)],
  ///   M* dk = [dfb_u + dc_u; df_v(stage; dxb, the inputs' seeds, dp) + dc_v],
  /// where df_v is the local blocks' tangent at the stage's states for the base point's state
  /// seeds dxb and input seeds (the last tangent pass, which was at the base point).
  void local_stage_tangent(double tb, const Vector& xb, const Matrix& dxb, const Matrix& dfb, const Matrix& dcv,
                           double h, const Vector& k, Matrix& dk) {
    const int nu = static_cast<int>(u_.size()), nv = static_cast<int>(v_.size());
    xi_ = xb;
    for (int i = 0; i < nv; ++i) xi_(v_[i]) += kGamma * h * k(v_[i]);
    dloc_.setZero(nx_, ns_);
    try {
      ev_.local_derivatives_tangent(tb, xi_.data(), ns_, {dxb.data(), nx_}, true, {dloc_.data(), nx_});
    } catch (const OutOfDomain& e) {
      throw local_failure(tb, e);
    }
    for (int c = 0; c < ns_; ++c) {
      for (int i = 0; i < nu; ++i) ru_(i) = dfb(u_[i], c) + dcv(u_[i], c);
      for (int i = 0; i < nv; ++i) rv_(i) = dloc_(v_[i], c) + dcv(v_[i], c);
      solve_partitioned(ru_, rv_);
      for (int i = 0; i < nu; ++i) dk(u_[i], c) = xu_(i);
      for (int i = 0; i < nv; ++i) dk(v_[i], c) = xv_(i);
    }
  }

  static StageFailure local_failure(double tb, const OutOfDomain& e) {
    const auto colon = e.reason.find(": ");
    if (colon == std::string::npos) return StageFailure{tb, "", "input out of a block's domain: " + e.reason};
    return StageFailure{tb, e.reason.substr(0, colon), "input out of the block's domain: " + e.reason.substr(colon + 2)};
  }

  /// The blocks' own diagonal blocks of W at (t, y), where blocks provide them (else nothing).
  void refresh_local(double t_at, const Vector& y) {
    if (!has_local_ || nx_ == 0) return;
    try {
      has_local_ = ev_.local_jacobians(t_at, y.data(), w_.data(), nx_);
    } catch (const OutOfDomain& e) {
      throw domain_failure(t_at, e);
    }
    if (!has_local_) return;
    ++stats_.local_jac_evals;
    factored_h_ = -1.0;
    evaluator_at_start_ = false;
  }

  /// refresh(t, y), false when a block refuses the point.
  bool refreshed(double t_at, const Vector& y) {
    try {
      refresh(t_at, y);
      return true;
    } catch (const SolverError&) {
      age_ = 0;  // W as it was: halve instead
      return false;
    }
  }

  /// W = df/dx at (t, y): one tangent pass per colour of its columns (JacobianColouring).
  void refresh(double t_at, const Vector& y) {
    if (nx_ == 0) return;
    try {
      colouring_.evaluate(ev_, t_at, y.data(), {w_.data(), nx_}, {});
    } catch (const OutOfDomain& e) {
      throw domain_failure(t_at, e);
    }
    ++stats_.jac_evals;
    factored_h_ = -1.0;
    age_ = 0;
    evaluator_at_start_ = false;
  }

  void factor(double h) {
    if (local_stages_) {
      factor_partitioned(h);
      factored_h_ = h;
      return;
    }
    if (nx_ > 0) {
      newton_matrix_ = identity_ - kGamma * h * w_;
      lu_.factor(newton_matrix_.data(), nx_);  // a zero pivot shows as a non-finite stage
    }
    factored_h_ = h;
  }

  /// out = (I - gamma h W)^-1 rhs, column by column (nothing to solve without states).
  template <class Rhs, class Out>
  void solve(const Rhs& rhs, Out&& out) const {
    if (nx_ == 0) return;
    columns_ = rhs;
    for (Eigen::Index c = 0; c < columns_.cols(); ++c) lu_.solve(columns_.col(c).data(), columns_.col(c).data());
    out = columns_;
  }

  /// f(t, y) and g(t, y) and, with sensitivities, their tangents for the state seeds dy.
  void evaluate(double t_at, const Eigen::Ref<const Vector>& y, const Matrix& dy, Vector& f, Vector& g, Matrix& df,
                Matrix& dg) {
    try {
      ev_.derivatives(t_at, y.data(), f.data());
      if (nq_ > 0) ev_.quadratures(t_at, y.data(), g.data());
      ++stats_.rhs_evals;
      if (!ev_.all_finite(f.data())) {
        const std::string bad = ev_.find_nonfinite(f.data());
        const auto colon = bad.find(':');
        throw StageFailure{t_at, bad.substr(0, colon), colon == std::string::npos ? bad : bad.substr(colon + 2)};
      }
      if (ns_ > 0) {
        ev_.tangents(t_at, y.data(), ns_, {dy.data(), nx_}, true, {df.data(), nx_}, {nq_ ? dg.data() : nullptr, nq_});
        ++stats_.sens_rhs_evals;
      }
    } catch (const OutOfDomain& e) {
      const auto colon = e.reason.find(": ");
      if (colon == std::string::npos) throw StageFailure{t_at, "", "input out of a block's domain: " + e.reason};
      throw StageFailure{t_at, e.reason.substr(0, colon),
                         "input out of the block's domain: " + e.reason.substr(colon + 2)};
    }
  }

  Evaluator& ev_;
  int nx_, nq_, ns_;
  RunStats& stats_;
  bool fixed_;
  Matrix w_, identity_;
  JacobianColouring colouring_;
  Matrix newton_matrix_;
  NewtonLU lu_;
  mutable Matrix columns_;         ///< solve()'s right-hand sides, solved in place
  double factored_h_ = -1.0;
  int age_ = 0;                    ///< steps taken since W was evaluated
  double last_estimate_ = 0.0;     ///< the last accepted step's error estimate
  bool evaluator_at_start_ = false;  ///< the evaluator's last passes were at (t, x) with seeds S
  bool has_local_ = true;            ///< some block provides a local Jacobian (until found otherwise)
  bool local_checked_ = false;
  bool schur_valid_ = false;       ///< find_local_states has run
  bool local_stages_ = false;        ///< stages with the local blocks' rows exact (local_stage)
  std::vector<int> u_, v_;           ///< the other states; the local blocks' states
  NewtonLU lu_a_;                    ///< A = I - gamma h W_uu
  Matrix a_, b_, c_, ainv_b_, p_, jloc_, schur_matrix_, dloc_, dzero_;
  Eigen::PartialPivLU<Matrix> schur_;
  Vector ru_, rv_, yu_, xu_, xv_, xi_, fv_, zero_, ku_, kv_, cv_;
  Matrix dcv_;
  Vector scale_;
  Vector f_start_, f_end_, f_stage_, k1_, k2_, y_stage_, x_end_, g_start_, g_end_, g_stage_, q_end_;
  Matrix df_start_, df_end_, df_stage_, dk1_, dk2_, dy_stage_, s_end_, dg_start_, dg_end_, dg_stage_, sq_end_;
};

RunResult run_ros2(const Diagram& d, const RunOptions& options, const std::vector<double>* fixed_w) {
  const int nx = d.num_states, nq = d.num_quadratures;
  const int ns = options.sensitivities ? static_cast<int>(d.sensitivities.size()) : 0;
  const double t0 = d.time.start;
  const double h_max = d.solver.step > 0 ? d.solver.step : d.time.output_step / 10.0;
  if (fixed_w && fixed_w->size() != static_cast<size_t>(nx) * nx)
    throw SolverError(t0, "", "the given W has " + std::to_string(fixed_w->size()) + " elements, not " +
                                  std::to_string(nx) + " x " + std::to_string(nx));

  Evaluator ev(d, ns > 0);
  RunResult result;
  Recorder recorder(d, ns, result, options);
  RunStats& st = result.stats;
  const CpuClock clock;
  Ros2Stepper stepper(d, ev, ns, st, fixed_w);

  stepper.t = t0;
  stepper.x.setZero(std::max(nx, 1));
  ev.set_segment_start(t0);
  ev.initial_state(t0, stepper.x.data());
  stepper.x.conservativeResize(nx);
  stepper.q.setZero(nq);
  stepper.S.setZero(nx, ns);
  stepper.Sq.setZero(std::max(nq, 1), ns);
  if (ns > 0) ev.initial_state_tangent(t0, stepper.x.data(), {stepper.S.data(), nx});
  stepper.begin();

  auto record = [&](double t) {
    stepper.prepare_record();
    recorder.record(t, stepper.x.data(), ev);
  };
  record(t0);

  const Timeline timeline(d);
  double t = t0;
  for (double target : timeline.events) {
    const long n = fixed_steps(t, target, h_max);
    const double h = (target - t) / n;
    for (long step = 0; step < n; ++step) {
      stepper.t = t + step * h;
      stepper.advance(h, 0, h_max);
    }
    t = stepper.t = target;
    if (timeline.is_output(target)) record(target);
    if (timeline.is_break(target)) {
      ev.set_segment_start(target);
      stepper.begin();  // the right-hand side may jump here
    }
  }
  Vector qf = Vector::Zero(std::max(nq, 1));
  qf.head(nq) = stepper.q;
  recorder.finish(qf.data(), {stepper.Sq.data(), static_cast<int>(stepper.Sq.rows())});
  result.final_state.assign(stepper.x.data(), stepper.x.data() + nx);

  st.step = h_max;
  finish_stats(st, "rosw", clock.seconds(), d.time);
  return result;
}

}  // namespace

RunResult run_rosenbrock(const Diagram& d, const RunOptions& options) { return run_ros2(d, options, nullptr); }

RunResult run_rosenbrock_fixed_w(const Diagram& d, const RunOptions& options, const std::vector<double>& w) {
  return run_ros2(d, options, &w);
}

}  // namespace dydp::engine
