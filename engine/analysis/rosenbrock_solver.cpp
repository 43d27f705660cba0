#include "engine/analysis/rosenbrock_solver.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "engine/analysis/local_stages.hpp"
#include "engine/analysis/newton_lu.hpp"
#include "engine/analysis/step_driver.hpp"
#include "engine/analysis/timeline.hpp"
#include "engine/analysis/tolerances.hpp"
#include "engine/evaluation/jacobian_colouring.hpp"
#include "engine/framework/errors.hpp"

namespace dydp::engine {
namespace {

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
constexpr double kGamma = kGamma2;
/// W is evaluated afresh after this many steps (and at the start, after each breakpoint, and
/// when a step's error estimate jumps).
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

/// The scheme's state (x, q and their sensitivities S, Sq), W and its factorisation, and the
/// start-of-step evaluations f(tn, xn), g(tn, xn) and their tangents, which the last step's
/// end (or the record at an output time) already made.
class Ros2Stepper final : public Stepper {
 public:
  Ros2Stepper(const Diagram& d, Evaluator& ev, int ns, RunStats& stats, const std::vector<double>* fixed_w)
      : h_max_(scene_fixed_step(d)), ev_(ev), nx_(d.num_states), nq_(d.num_quadratures), ns_(ns), stats_(stats), fixed_(fixed_w != nullptr),
        w_(nx_, nx_), identity_(Matrix::Identity(nx_, nx_)), colouring_(d),
        local_(ev, stats, kGamma, state_nominals(d), ns) {
    stats_.jacobian_colours = colouring_.colours();
    const std::vector<double> nominal = state_nominals(d);
    scale_ = Eigen::Map<const Vector>(nominal.data(), nx_);
    adaptive_ = !fixed_ && d.solver.step <= 0;
    if (adaptive_) {
      rtol_ = d.solver.rtol;
      const AbsoluteTolerances atol = absolute_tolerances(d, d.solver.atol, ns_);
      atol_ = Eigen::Map<const Vector>(atol.states.data(), nx_);
      sens_in_test_ = d.solver.sens_error_test && ns_ > 0;
      if (sens_in_test_) atol_s_ = Eigen::Map<const Matrix>(atol.sensitivities.data(), nx_, ns_);
      h_pref_ = d.time.output_step / 10.0;
      h_floor_ = 1e-12 * std::max(1.0, std::fabs(d.time.stop - d.time.start));
      stats_.rtol = d.solver.rtol;
      stats_.atol = d.solver.atol;
    }
    if (fixed_) w_ = Eigen::Map<const Matrix>(fixed_w->data(), nx_, nx_);
    const int nx1 = std::max(nx_, 1), nq1 = std::max(nq_, 1);
    for (Vector* v : {&f_start_, &f_end_, &f_stage_, &k1_, &k2_, &y_stage_, &x_end_}) v->setZero(nx1);
    for (Vector* v : {&g_start_, &g_end_, &g_stage_, &q_end_}) v->setZero(nq1);
    for (Matrix* m : {&df_start_, &df_end_, &df_stage_, &dk1_, &dk2_, &dy_stage_, &s_end_}) m->setZero(nx_, ns_);
    for (Matrix* m : {&dg_start_, &dg_end_, &dg_stage_, &sq_end_}) m->setZero(nq1, ns_);
  }

  /// Evaluates the first stage's right-hand side (and tangent) at (t, x): at the start and
  /// after a breakpoint, where the right-hand side may jump. W is evaluated there too.
  void begin(MarchState& s) override {
    const Held held(*this, s);
    try {
      evaluate(t, x, S, f_start_, g_start_, df_start_, dg_start_);
    } catch (const StageFailure& e) {
      throw SolverError(e.t, e.block, e.why);
    }
    if (!fixed_) refresh(t, x);
    if (!fixed_ && !local_checked_) find_local_states();
  }

  void advance(MarchState& s, double target) override {
    const Held held(*this, s);
    if (adaptive_) return advance_controlled(target);
    const double t_start = s.t;
    const long n = fixed_steps(t_start, target, h_max_);
    const double h = (target - t_start) / n;
    for (long k = 0; k < n; ++k) {
      t = t_start + k * h;
      advance_step(h, 0, h_max_);
    }
  }

  double reported_step() const override { return adaptive_ ? 0.0 : h_max_; }

  /// Leaves the evaluator's signals and tangents at (t, x) for the recorder.
  void prepare_record(const MarchState& s, Evaluator&, int) override {
    const Held held(*this, const_cast<MarchState&>(s));
    if (ns_ > 0 && !evaluator_at_start_) ev_.tangents(t, x.data(), ns_, {S.data(), nx_}, true, {}, {});
    else ev_.outputs(t, x.data());
    evaluator_at_start_ = true;
  }

  /// Advances by one step of size h, or by its halves when a stage fails.
  void advance_step(double h, int halvings, double scene_step) {
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
        advance_step(h / 2, halvings + 1, scene_step);
        advance_step(h / 2, halvings + 1, scene_step);
        return;
      }
    }
  }

 private:
  /// The march's state, held as the members t, x, q, S, Sq while a call lasts (swapped in and
  /// out, no copy).
  struct Held {
    Held(Ros2Stepper& r, MarchState& s) : r_(r), s_(s) {
      r_.t = s_.t;
      swap();
    }
    ~Held() {
      s_.t = r_.t;
      swap();
    }
    void swap() {
      r_.x.swap(s_.x);
      r_.q.swap(s_.q);
      r_.S.swap(s_.S);
      r_.Sq.swap(s_.Sq);
    }
    Ros2Stepper& r_;
    MarchState& s_;
  };
  double t = 0.0;
  Vector x, q;   ///< q: max(nq, 1) rows
  Matrix S, Sq;  ///< dx/dp (nx x ns), dq/dp (max(nq, 1) x ns)

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
      local_.solve(t, x, f_start_.head(nx_), zero_, h, k1_);
      if (ns_ > 0) {
        local_.solve_tangent(t, x, S, df_start_, dzero_, h, k1_, dk1_);
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
      local_.solve(t_end, y_stage_, f_stage_, cv_, h, k2_);
      if (ns_ > 0) {
        dcv_.noalias() = -2 * dk1_;
        local_.solve_tangent(t_end, y_stage_, dy_stage_, df_stage_, dcv_, h, k2_, dk2_);
      }
    } else {
      f_stage_.head(nx_) -= 2 * k1_.head(nx_);
      solve(f_stage_.head(nx_), k2_.head(nx_));
    }
    x_end_.head(nx_) = x + h * (1.5 * k1_.head(nx_) + 0.5 * k2_.head(nx_));
    // The quadratures see W = 0 in their rows: the trapezoidal rule over the two stage points.
    q_end_.head(nq_) = q.head(nq_) + 0.5 * h * (g_start_.head(nq_) + g_stage_.head(nq_));
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
    if (adaptive_) {
      // The error test's norm: the same difference over atol_i + rtol |x_i| (at both ends).
      const Vector tolerance =
          atol_ + rtol_ * x.head(nx_).cwiseAbs().cwiseMax(x_end_.head(nx_).cwiseAbs());
      double sum = (0.5 * h * (k1_.head(nx_) + k2_.head(nx_))).cwiseQuotient(tolerance).squaredNorm();
      int count = nx_;
      if (sens_in_test_) {
        // The sensitivities' own embedded estimate h/2 (dk1 + dk2), within atol_i / |p_j| +
        // rtol |S_ij| (CVODES' weights for them).
        const Matrix tol_s = atol_s_ + rtol_ * S.cwiseAbs().cwiseMax(s_end_.cwiseAbs());
        sum += (0.5 * h * (dk1_ + dk2_)).cwiseQuotient(tol_s).squaredNorm();
        count += nx_ * ns_;
      }
      error_norm_ = std::sqrt(sum / count);
    }
    return std::sqrt(error.squaredNorm() / nx_);
  }

  void accept(double h, double estimate) {
    t += h;
    x.swap(x_end_);
    x_end_.resize(std::max(nx_, 1));
    x.conservativeResize(nx_);
    q.head(nq_) = q_end_.head(nq_);
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
  }

  /// Error-controlled steps from t to target: each step's embedded estimate (the difference
  /// of the order-2 solution and the order-1 solution xn + h k1) must be within atol_i + rtol
  /// |x_i| in the rms norm over the states, or the step is taken again smaller. The next step
  /// comes from Gustafsson's PI controller on that estimate (of order h^2: exponents 0.7 / 2
  /// and 0.4 / 2), and the steps to the next stop are made equal (n steps of (target - t) / n,
  /// at most the controller's), so that an output grid finer than the steps does not cut them
  /// and the Newton matrix is kept over the steps of equal size.
  void advance_controlled(double target) {
    while (t < target) {
      const double remaining = target - t;
      const double n = std::max(1.0, std::ceil(remaining / h_pref_ - 1e-9));
      const double h = n == 1.0 ? remaining : remaining / n;
      if (h < h_floor_)
        throw SolverError(t, "", "error-controlled step " + format_number(h) +
                                     " s too small: the solution changes faster than rosw can follow here; use "
                                     "method bdf");
      try {
        const double estimate = attempt(h);
        if (age_ > 0 && estimate > kDivergenceFloor && estimate > kDivergenceGrowth * last_estimate_) {
          refresh(t, x);  // a stale W on a stiff component: the step again with W at its start
          continue;
        }
        const double err = error_norm_;
        if (!(err <= 1.0)) {
          ++stats_.error_test_failures;
          h_pref_ = h * (std::isfinite(err) ? std::clamp(0.9 / std::sqrt(err), 0.2, 0.9) : 0.25);
          continue;
        }
        accept(h, estimate);
        const double e = std::max(err, 1e-8);
        const double grow = 0.9 * std::pow(e, -0.35) * std::pow(last_error_norm_, 0.2);
        h_pref_ = h * std::clamp(grow, 0.2, 2.0);
        last_error_norm_ = e;
      } catch (const StageFailure& failure) {
        if (age_ > 0 && refreshed(t, x)) continue;  // a stale W first
        ++stats_.nonlinear_failures;
        h_pref_ = h / 4;
      }
    }
  }

  /// Whether some block gives a local Jacobian: then its rows of each stage are solved exactly
  /// (LocalStages), and W's local blocks are not refreshed at every step.
  void find_local_states() {
    local_checked_ = true;
    try {
      local_stages_ = local_.find(t, x);
    } catch (const OutOfDomain& e) {
      throw domain_failure(t, e);
    }
    if (!local_stages_) return;
    factored_h_ = -1.0;
    zero_.setZero(nx_);
    dzero_.setZero(nx_, ns_);
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
      local_.factor(w_, h);
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
      throw domain_failure<StageFailure>(t_at, e);
    }
  }

  double h_max_;  ///< the scene's step
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
  bool local_checked_ = false;       ///< find_local_states has run
  bool local_stages_ = false;        ///< some block gives a local Jacobian: LocalStages solves
  LocalStages local_;
  Vector zero_, cv_;                 ///< the stages' c: 0 and -2 k1
  Matrix dzero_, dcv_;               ///< and their tangents
  Vector scale_;
  bool adaptive_ = false;         ///< error-controlled steps (no fixed step given)
  double rtol_ = 0.0;
  Vector atol_;                   ///< per state: atol times its nominal magnitude
  bool sens_in_test_ = false;     ///< the sensitivities in the error test (solver.sens_error_test)
  Matrix atol_s_;                 ///< their absolute tolerances (nx x ns)
  double h_pref_ = 0.0;           ///< the controller's next step
  double h_floor_ = 0.0;          ///< below this the run stops
  double error_norm_ = 0.0;       ///< the last attempt's error in the tolerances' norm
  double last_error_norm_ = 1.0;  ///< the last accepted step's (the PI controller's memory)
  Vector f_start_, f_end_, f_stage_, k1_, k2_, y_stage_, x_end_, g_start_, g_end_, g_stage_, q_end_;
  Matrix df_start_, df_end_, df_stage_, dk1_, dk2_, dy_stage_, s_end_, dg_start_, dg_end_, dg_stage_, sq_end_;
};

RunResult run_ros2(const Diagram& d, const RunOptions& options, const std::vector<double>* fixed_w) {
  const int nx = d.num_states;
  if (fixed_w && fixed_w->size() != static_cast<size_t>(nx) * nx)
    throw SolverError(d.time.start, "", "the given W has " + std::to_string(fixed_w->size()) + " elements, not " +
                                            std::to_string(nx) + " x " + std::to_string(nx));
  return march(d, options, "rosw", [&](Evaluator& ev, int ns, RunStats& st) {
    return std::make_unique<Ros2Stepper>(d, ev, ns, st, fixed_w);
  });
}

}  // namespace

RunResult run_rosenbrock(const Diagram& d, const RunOptions& options) { return run_ros2(d, options, nullptr); }

RunResult run_rosenbrock_fixed_w(const Diagram& d, const RunOptions& options, const std::vector<double>& w) {
  return run_ros2(d, options, &w);
}

}  // namespace dydp::engine
