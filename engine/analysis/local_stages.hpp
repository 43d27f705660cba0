// Rosenbrock-W's stages with the rows of the blocks that give a local Jacobian (the CDC
// dampers' chambers) solved exactly: Newton on those blocks' own states, their inputs held at
// the stage's base point, with the rest of the stage linear in the kept matrix W. That is ROS2
// with W's local blocks the secant of their law over the stage's own increment instead of its
// tangent: still of order 2 (ROS2 is for any W), and a secant cannot overshoot where a law's
// slope jumps within the step (a check valve opening). docs/engine.md, "rosw's local stages".
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "engine/analysis/newton_lu.hpp"
#include "engine/analysis/run_result.hpp"
#include "engine/evaluation/evaluator.hpp"

namespace dydp::engine {

/// A stage's value was not finite, a block refused its state, or a local stage's iteration did
/// not converge: the step is taken again (in halves).
struct StageFailure {
  double t;
  std::string block, why;
};

class LocalStages {
 public:
  using Matrix = Eigen::MatrixXd;
  using Vector = Eigen::VectorXd;

  /// gamma: the scheme's; scale: the states' nominal magnitudes (the iteration's test).
  LocalStages(Evaluator& ev, RunStats& stats, double gamma, const std::vector<double>& scale, int num_sensitivities)
      : ev_(ev), stats_(stats), gamma_(gamma), scale_(Eigen::Map<const Vector>(scale.data(), scale.size())),
        ns_(num_sensitivities) {}

  /// Finds the states of the blocks that give a local Jacobian at (t, x) (v; the others u).
  /// False when no block does: the stages are then the linearly implicit ones.
  bool find(double t, const Vector& x);

  /// Partitions M = I - gamma h W as [A B; C D] over (u, v): A factored, and A^-1 B and
  /// C A^-1 B kept for the Schur complement each iteration factors (nv x nv).
  void factor(const Matrix& w, double h);

  /// Stage k of ROS2 at the base point xb (the evaluator's last value pass, and for the tangent
  /// its last tangent pass, must be at xb) with fb = f(tb, xb):
  ///   k_u = fb_u + c_u + gamma h (W_uu k_u + W_uv k_v)
  ///   k_v = f_v(tb, u_b, v_b + gamma h k_v) + c_v + gamma h W_vu k_u.
  void solve(double tb, const Vector& xb, const Eigen::Ref<const Vector>& fb, const Vector& c, double h, Vector& k);
  /// Its derivative for the base point's state seeds dxb, with dfb = f's tangent there and dc
  /// c's: M* dk = [dfb_u + dc_u; df_v(stage) + dc_v], M* the Newton matrix at the stage's
  /// solution (solve() leaves it factored when there are sensitivities).
  void solve_tangent(double tb, const Vector& xb, const Matrix& dxb, const Matrix& dfb, const Matrix& dc, double h,
                     const Vector& k, Matrix& dk);

 private:
  void solve_partitioned(const Vector& r_u, const Vector& r_v);
  void factor_schur(double tb, const Vector& xs, double h);

  Evaluator& ev_;
  RunStats& stats_;
  double gamma_;
  Vector scale_;
  int ns_;
  int nx_ = 0;
  std::vector<int> u_, v_;          ///< the other states; the local blocks' states
  NewtonLU lu_a_;                   ///< A = I - gamma h W_uu
  Matrix a_, b_, c_, ainv_b_, p_;   ///< A, B = -gamma h W_uv, C = -gamma h W_vu, A^-1 B, C A^-1 B
  Matrix jloc_, schur_matrix_, dloc_;
  Eigen::PartialPivLU<Matrix> schur_;
  bool schur_valid_ = false;        ///< schur_ holds a factorisation for the current W and h
  Vector ru_, rv_, yu_, xu_, xv_, xi_, fv_, ku_, kv_;
};

}  // namespace dydp::engine
