#include "engine/analysis/sdirk_solver.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "engine/analysis/newton_lu.hpp"
#include "engine/analysis/step_driver.hpp"
#include "engine/evaluation/jacobian_colouring.hpp"
#include "engine/framework/errors.hpp"

namespace dydp::engine {
namespace {

constexpr double kGamma = kGamma2;
/// Newton corrections that shrink by less than this factor from one iteration to the next call
/// for a refresh of the iteration matrix (on the sedan replay 0.1 cost least; 0.25, 0.05 and
/// 0.02 cost 16 %, 7 % and 34 % more).
const double kSlowRate = 0.1;
const int kMaxIterations = 30;
/// A step whose stage iteration fails is taken as two of half the size, down to 1/2^this of
/// the scene's step; then the run stops naming the step that would do.
const int kMaxHalvings = 6;

/// A stage's Newton iteration failed (diverged, did not converge, or an iterate was outside a
/// block's domain): the step is retried in halves.
struct StageFailure {
  double t;
  std::string why;
};

/// The stages of one step share this: the diagram, the evaluator and the iteration matrix.
class Stages {
 public:
  Stages(const Diagram& d, Evaluator& ev, int ns, RunStats& stats)
      : ev_(ev), nx_(d.num_states), nq_(d.num_quadratures), ns_(ns), stats_(stats),
        jac_(nx_, nx_), identity_(Matrix::Identity(nx_, nx_)), colouring_(d) {
    stats_.jacobian_colours = colouring_.colours();
  }

  /// J = df/dx at (t, y): one tangent pass per colour of its columns (JacobianColouring).
  void jacobian(double t, const Vector& y) {
    colouring_.evaluate(ev_, t, y.data(), {jac_.data(), nx_}, {});
    ++stats_.jac_evals;
  }
  /// Refreshes only the diagonal blocks of J that blocks provide cheaply (Block::local_jacobian).
  bool local_jacobian(double t, const Vector& y) {
    if (!has_local_) return false;
    has_local_ = ev_.local_jacobians(t, y.data(), jac_.data(), nx_);
    if (has_local_) ++stats_.local_jac_evals;
    return has_local_;
  }
  void factor(double hg) {
    newton_matrix_ = identity_ - hg * jac_;
    lu_.factor(newton_matrix_.data(), nx_);  // a zero pivot shows as a non-finite iterate
    factored_hg_ = hg;
  }

  Vector f(double t, const Vector& y) {
    Vector out(std::max(nx_, 1));
    out.setZero();
    evaluate(t, [&] { ev_.derivatives(t, y.data(), out.data()); });
    ++stats_.rhs_evals;
    if (!ev_.all_finite(out.data())) {
      const std::string bad = ev_.find_nonfinite(out.data());
      throw SolverError(t, bad.substr(0, bad.find(':')), bad.substr(bad.find(':') + 2));
    }
    return out.head(nx_);
  }
  Vector g(double t, const Vector& y) {
    Vector out(std::max(nq_, 1));
    out.setZero();
    if (nq_ > 0) evaluate(t, [&] { ev_.quadratures(t, y.data(), out.data()); });
    return out.head(nq_);
  }

  /// Solves Y - hg f(t, Y) = rhs from the predictor `guess` by a modified Newton iteration: the
  /// iteration matrix I - hg J is kept across stages and steps, and J is evaluated afresh at the
  /// current iterate only when the corrections stop shrinking fast (a stale J shows as a slow
  /// contraction). Converged to rounding level, so the result is the discrete map's whichever J
  /// the iteration used, and the sensitivities below are those of the map.
  Vector solve_stage(double t, double hg, const Vector& rhs, Vector y) {
    if (hg != factored_hg_) factor(hg);
    double previous = 0.0;  // size of the last correction since J was last evaluated
    bool local_last = false;  // the last refresh was of the local blocks only
    for (int it = 0; it < kMaxIterations; ++it) {
      Vector fy;
      try {
        fy = f(t, y);
      } catch (const SolverError& e) {
        throw StageFailure{t, e.what()};  // an iterate off the solution: not the solution's failure
      }
      Vector delta = y - hg * fy - rhs;  // the residual, solved in place
      lu_.solve(delta.data(), delta.data());
      y -= delta;
      ++stats_.nonlinear_iterations;
      const double size = delta.cwiseAbs().maxCoeff();
      if (!std::isfinite(size)) throw StageFailure{t, "Newton iteration diverged (non-finite iterate)"};
      // Converged when the remaining error, estimated from the contraction rate theta as
      // theta / (1 - theta) times this correction (or the correction itself before a rate is
      // known), is at rounding level.
      const double theta = previous > 0.0 ? size / previous : 1.0;
      const double remaining = theta < 1.0 && previous > 0.0 ? size * theta / (1.0 - theta) : size;
      if (remaining <= 1e-13 * (1.0 + y.cwiseAbs().maxCoeff())) return y;
      if (previous > 0.0 && theta > kSlowRate) {
        // First the cheap diagonal blocks (the nonlinearity is mostly there), then all of J.
        local_last = !local_last && local_jacobian(t, y);
        if (!local_last) jacobian(t, y);
        factor(hg);
        previous = 0.0;
      } else {
        previous = size;
      }
    }
    throw StageFailure{t, "Newton iteration did not converge in " + std::to_string(kMaxIterations) + " iterations"};
  }

  /// Stage sensitivity: (I - hg J(Y)) dY = rhs + hg f_p(Y), with J refreshed at Y. Returns dY
  /// and fills dk = f_x dY + f_p and dq = g_x dY + g_p.
  Matrix stage_sensitivity(double t, double hg, const Vector& y, const Matrix& rhs, Matrix& dk,
                           Matrix& dq) {
    jacobian(t, y);
    factor(hg);
    Matrix fp(nx_, ns_), qp(std::max(nq_, 1), ns_);
    fp.setZero();
    qp.setZero();
    evaluate(t, [&] {
      ev_.tangents(t, y.data(), ns_, {}, true, {fp.data(), nx_}, {nq_ ? qp.data() : nullptr, nq_});
    });
    Matrix dy = rhs + hg * fp;
    for (Eigen::Index c = 0; c < dy.cols(); ++c) lu_.solve(dy.col(c).data(), dy.col(c).data());
    dk.resize(nx_, ns_);
    dq.resize(std::max(nq_, 1), ns_);
    dq.setZero();
    evaluate(t, [&] {
      ev_.tangents(t, y.data(), ns_, {dy.data(), nx_}, true, {dk.data(), nx_}, {nq_ ? dq.data() : nullptr, nq_});
    });
    ++stats_.sens_rhs_evals;
    return dy;
  }

 private:
  template <class F>
  void evaluate(double t, F&& call) {
    try {
      call();
    } catch (const OutOfDomain& e) {
      throw domain_failure(t, e);
    }
  }

  Evaluator& ev_;
  int nx_, nq_, ns_;
  RunStats& stats_;
  Matrix jac_, identity_;
  JacobianColouring colouring_;
  Matrix newton_matrix_;
  NewtonLU lu_;
  double factored_hg_ = -1.0;
  bool has_local_ = true;  ///< some block provides a local Jacobian (until found otherwise)
};

/// SDIRK2's step over the stages above; a step whose stage iteration fails is taken in halves.
class SdirkStepper final : public FixedStepper {
 public:
  SdirkStepper(const Diagram& d, Evaluator& ev, int ns, RunStats& stats)
      : FixedStepper(scene_fixed_step(d)), nx_(d.num_states), nq_(d.num_quadratures), ns_(ns), stats_(stats),
        stages_(d, ev, ns, stats) {}

  void begin(MarchState& s) override {
    if (!started_ && nx_ > 0) stages_.jacobian(s.t, s.x);
    started_ = true;
    slope_.setZero(nx_);  // the right-hand side may jump here
  }

 protected:
  void step(MarchState& s, double h) override { advance_step(s, s.t, h, 0); }

 private:
  /// One step of the scheme over [tn, tn + h]; when a stage's iteration fails, two steps of h / 2
  /// instead (the sensitivities are then those of the two half steps, the map actually taken).
  void advance_step(MarchState& s, double tn, double h, int halvings) {
    const double hg = kGamma * h, t1 = tn + hg, t2 = tn + h;
    Vector& x = s.x;
    try {
      // Y1 = x + h g f(Y1);  Y2 = x + h (1 - g) f(Y1) + h g f(Y2);  x+ = Y2.
      // Predictors: stage 1 extrapolates with the last step's final stage slope, stage 2 with
      // stage 1's slope (both are the slopes the stage equations gave, no extra evaluation).
      // Nothing is updated before both stages have converged, so a failed step leaves the state
      // as it was for its halves.
      const Vector y1 = nx_ ? stages_.solve_stage(t1, hg, x, x + hg * slope_) : x;
      const Vector k1 = stages_.f(t1, y1);
      const Vector q1 = stages_.g(t1, y1);
      Matrix dk1, dq1;
      const Matrix dy1 = ns_ ? stages_.stage_sensitivity(t1, hg, y1, s.S, dk1, dq1) : Matrix();
      const Vector rhs2 = x + h * (1 - kGamma) * k1;
      const Vector y2 = nx_ ? stages_.solve_stage(t2, hg, rhs2, rhs2 + hg * k1) : x;
      if (nx_) slope_ = (y2 - rhs2) / hg;
      const Vector q2 = stages_.g(t2, y2);
      if (ns_ > 0) {
        Matrix dk2, dq2;
        const Matrix dy2 = stages_.stage_sensitivity(t2, hg, y2, s.S + h * (1 - kGamma) * dk1, dk2, dq2);
        s.S = dy2;
        if (nq_ > 0) s.Sq.topRows(nq_) += h * ((1 - kGamma) * dq1.topRows(nq_) + kGamma * dq2.topRows(nq_));
      }
      if (nq_ > 0) s.q.head(nq_) += h * ((1 - kGamma) * q1 + kGamma * q2);
      x = y2;
      ++stats_.steps;
    } catch (const StageFailure& failure) {
      if (halvings == kMaxHalvings)
        throw SolverError(failure.t, "",
                          failure.why + " at a step of " + format_number(h) + " s (the scene's step " +
                              format_number(h_max_) + " s halved " + std::to_string(kMaxHalvings) +
                              " times): the solution changes faster than a fixed step can follow here; use "
                              "method bdf, or a step of at most " + format_number(h) + " s");
      ++stats_.substeps;
      slope_.setZero();  // the predictor only; the stages converge to rounding level from any start
      advance_step(s, tn, h / 2, halvings + 1);
      advance_step(s, tn + h / 2, h / 2, halvings + 1);
    }
  }

  int nx_, nq_, ns_;
  RunStats& stats_;
  Stages stages_;
  Vector slope_;  ///< f at the end of the last step, for the stage-1 predictor
  bool started_ = false;
};

}  // namespace

RunResult run_sdirk(const Diagram& d, const RunOptions& options) {
  return march(d, options, "sdirk2", [&](Evaluator& ev, int ns, RunStats& st) {
    return std::make_unique<SdirkStepper>(d, ev, ns, st);
  });
}

}  // namespace dydp::engine
