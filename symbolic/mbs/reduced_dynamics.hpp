// The explicit direct dynamics of a generated model by coordinate partitioning:
// u independent, v dependent, d driven. Newton-Raphson on h(u, v) = 0 for v, v_dot = -Jv^-1 Ju u_dot,
// qdd = B udd + beta with B = [I; -Jv^-1 Ju], the reduced system B^T M B udd = -B^T (c + M beta)
// solved by Cholesky, and the multipliers from the v rows. M [B beta] from M's composite-inertia
// entries over B's structure (a loop's rows of B are nonzero in its own independent columns
// only), or from the inertial pass seeded on [B beta]. Its tangent reuses the factors:
// dv = -Jv^-1 (Ju du + dh/dp dp), and the same Cholesky factor for dudd.
#pragma once

#include <Eigen/Dense>
#include <utility>
#include <vector>

#include "symbolic/mbs/block_lu.hpp"
#include "symbolic/mbs/generated_model.hpp"
#include "symbolic/mbs/reduced_cholesky.hpp"

namespace dydp::mbs {

class ReducedDynamics {
 public:
  using Vector = Eigen::VectorXd;
  using Matrix = Eigen::MatrixXd;
  // Row-major where the partitioning reads rows: B's and M [B beta]'s rows are gathered by
  // coordinate.
  using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

  explicit ReducedDynamics(const GeneratedModel& model);
  const GeneratedModel& model() const { return model_; }
  int nu() const { return static_cast<int>(u_.size()); }

  // The state of one evaluation, kept for its tangent.
  struct Result {
    Vector q, qd, qdd, lam;
    Vector udd;
    RowMatrix MB;                                 // M [B beta]: n x (nu + 1 if m > 0)
    RowMatrix J;                                  // m x n (as the generated function writes it)
    BlockLU Jv;                                   // dependent columns of J, loop by loop
    RowMatrix B;                                  // free coordinates x nu
    ReducedCholesky reduced;                      // B^T M_ff B
    Matrix seeds;                                 // [B beta] over q
    RowMatrix MBf;                                // M_ff B
    int newton_iterations = 0;
    bool dynamics_current = false;                // B (and the rest of the dynamic half) is at q
    // Scratch storage sized at the first call and reused, so that a solve and its tangents
    // allocate nothing once the sizes are known (the right-hand side's path).
    struct Work {
      std::vector<double> hj, res, out, lam_zero, mass, s_val;
      Vector beta, cf, Mbeta, fv, qddf;
      Matrix beta_v, reduced, MBv, mass_columns;
      Matrix dinp, dp, dqdd_seed, dout, dh, dv, dbeta_v, dudd;
      // directions that move the coordinates (dq != 0) and those that do not, and their seeds
      // gathered in that order when they are not already
      std::vector<int> moving, still;
      // residual_tangent_groups: each direction's block, the directions in block order, and
      // the number in each block
      std::vector<int> block, order, per_block;
      Matrix g_dq, g_dqd, g_dqdd, g_dinp, g_dp, g_dout;
      const void* shaped_by = nullptr;  // the partitioning that last shaped B and MB
    };
    mutable Work work;
  };

  // u, u_dot (nu), inputs, parameters (model sizes; p may be null for the model's values).
  // `guess` holds a full q whose dependent coordinates start the Newton iteration.
  // Throws std::runtime_error when Newton-Raphson does not converge.
  void solve(const double* u, const double* ud, const double* inputs, const double* p, const Vector& guess,
             Result& r) const;
  // solve() in its two halves. Kinematics: q, qd, J, Jv from u, u_dot, the driven joints' q and
  // qd, p (the inputs' loads and driven accelerations are not read). Dynamics: qdd, udd, lam,
  // B, MB, reduced at the kinematic state in r, reading the loads and driven accelerations.
  void solve_kinematics(const double* u, const double* ud, const double* inputs, const double* p,
                        const Vector& guess, Result& r) const;
  void solve_dynamics(const double* inputs, const double* p, Result& r) const;
  // A start for the Newton iteration at new independent coordinates u: r's q with its dependent
  // coordinates moved along B (dv = Bv du, the kinematics to first order), so the iteration
  // starts O(|du|^2) from the solution. Without r's dynamics at its q, r's q as it is.
  void predict(const Result& r, const double* u, Vector& guess) const;

  // Derivatives of q, qd, qdd (n x nd each, column per direction) for seeds on u, u_dot
  // (nu x nd), inputs (inputs x nd) and parameters (parameters x nd); null seeds are zero.
  void tangent(const Result& r, const double* inputs, const double* p, int nd, const double* du,
               const double* dud, const double* dinputs, const double* dp, Matrix& dq, Matrix& dqd,
               Matrix& dqdd) const;
  // The dynamic half of tangent(): dqdd from dq, dqd of tangent_kinematics (same seeds).
  void tangent_dynamics(const Result& r, const double* inputs, const double* p, int nd, const double* dinputs,
                        const double* dp, const Matrix& dq, const Matrix& dqd, Matrix& dqdd) const;
  // The kinematic half of tangent(): dq and dqd only, what positions and velocities need.
  void tangent_kinematics(const Result& r, const double* inputs, const double* p, int nd, const double* du,
                          const double* dud, const double* dinputs, const double* dp, Matrix& dq,
                          Matrix& dqd) const;

  const std::vector<int>& independent() const { return u_; }
  const std::vector<int>& dependent() const { return v_; }
  const std::vector<int>& free() const { return f_; }

 private:
  const double* params(const double* p) const { return p ? p : (model_.parameters ? model_.parameter_values : pad_.data()); }
  // solve_dynamics() in its steps, in this order, over r's scratch storage. B and beta (a0: the
  // constraint bias); M [B beta] into r.MB from M's entries or by the seeded inertial pass; M_ff B,
  // M beta, c over the free rows and the factor of B^T M_ff B (c: the residual's n entries); udd and
  // the free rows of qdd; the multipliers.
  void free_basis(const double* a0, Result& r) const;
  void gathered_mass_basis(const double* in, const double* p, Result& r) const;
  void seeded_mass_basis(const double* in, const double* p, Result& r) const;
  void factor_reduced(const double* c, bool identity, bool whole, Result& r) const;
  void free_accelerations(bool identity, Result& r) const;
  void multipliers(const double* c, Result& r) const;
  // The input and parameter seeds as padded matrices (null: zero), and dqdd seeded on the
  // driven joints' accelerations.
  void seed_arrays(int nd, const double* dinputs, const double* dp, Matrix& dinp, Matrix& dp_out,
                   Matrix& dqdd) const;
  // tangent_dynamics() after seed_arrays: r.work.dinp and dp hold the seeds, dqdd the driven
  // joints' seeded accelerations.
  void dynamics_from_seeds(const Result& r, const double* inputs, const double* p, int nd, const Matrix& dq,
                           const Matrix& dqd, Matrix& dqdd) const;
  // out (m) = J x over seeded_entries_ (x: n entries, zero in the dependent ones).
  void jacobian_times(const RowMatrix& J, const double* x, double* out) const;
  // The directions (columns) with a nonzero dq, or a nonzero dp when dp is given, and the others.
  static void split_directions(const Matrix& dq, const Matrix* dp, int nd, std::vector<int>& moving,
                               std::vector<int>& still);
  // out = the columns `cols` of a, in that order.
  static void gather_columns(const Matrix& a, const std::vector<int>& cols, Matrix& out);
  // Whether cols is 0, 1, ..., k - 1: those directions are the seeds' leading columns as they are.
  static bool leading(const std::vector<int>& cols);
  // The seeds of the directions `cols` (in that order) as consecutive columns for a generated
  // tangent, and where its derivatives go: the arrays themselves (dq, dqd, dqdd, work's dinp and
  // dp; dout) when cols lead, otherwise copies gathered into work's g_ arrays (g_dout sized
  // dout.rows() x cols), which put_directions then copies back to dout's columns `cols`.
  struct DirectionSeeds {
    const double *dq, *dqd, *dqdd, *dinp, *dp;
    Eigen::Index ld_inp, ld_p;
    double* dout;
  };
  static DirectionSeeds directions(const std::vector<int>& cols, const Matrix& dq, const Matrix& dqd,
                                   const Matrix& dqdd, Matrix& dout, Result::Work& w);
  static void put_directions(const std::vector<int>& cols, Result::Work& w, Matrix& dout);
  // The residual's tangent (dr, da) into r.work.dout for the seeds dq, dqd, dqdd and
  // r.work.dinp, dp: through the model's tangent in blocks when it has one (each direction in
  // the cheapest block its seeds fit), else the directions with dq = 0 through the model's
  // velocity tangent, which skips every derivative of the rotations and positions.
  void residual_tangent(const Result& r, const double* lam, const double* in, const double* p, int nd,
                        const Matrix& dq, const Matrix& dqd, const Matrix& dqdd) const;
  // The block of residual_tangent_groups for direction d (GeneratedGroupedTangent's numbering):
  // a coordinate group's when every seed it has on q, qd and qdd lies in that group and it has
  // none on the inputs and parameters; the full or the velocity block otherwise.
  int tangent_block(const Result::Work& w, int d, const Matrix& dq, const Matrix& dqd, const Matrix& dqdd) const;
  // Row a of the free coordinates: its place among u (>= 0), or -1 - its place among v.
  std::vector<int> free_place_;
  // The structure of B = [I; -Jv^-1 Ju] over the free coordinates: the u columns row a can be
  // nonzero in (its own for a u row; for a v row those entering its loop's constraints, a
  // corner's two or three of the car's fourteen). M [B beta], B^T M B and the products with B
  // run over these only.
  std::vector<std::vector<int>> b_cols_;
  // the u columns that reach each block of Jv (Ju's structurally nonzero columns on its rows),
  // and the free row of each dependent coordinate (by its place among v)
  std::vector<std::vector<int>> block_u_;
  std::vector<int> row_of_v_;
  // The same by rows for the tangent's loops: an independent row's coordinate q and its column
  // (B's entry 1); a dependent row's entries, coordinate q, column c and the entry's place b in
  // B's row-major storage (a * nu + c); and the dependent rows' free row a with their place
  // among v.
  struct IndependentRow {
    int q, place;
  };
  struct DependentEntry {
    int q, c, b;
  };
  std::vector<IndependentRow> independent_rows_;
  std::vector<DependentEntry> dependent_entries_;
  std::vector<std::pair<int, int>> dependent_rows_;
  // [B beta] by rows of q: row j's entries s_start_[j] .. s_start_[j + 1] - 1, at columns s_col_
  // (nu: beta); free row of coordinate j (-1: driven).
  std::vector<int> s_start_, s_col_, free_row_of_;
  // M [B beta] as gathered sums: entry mb_place_[o] (row-major, i * k + c) of the product is
  // the sum over p in mb_start_[o] .. mb_start_[o + 1] - 1 of mass[mb_mass_[p]] * s_val[mb_s_[p]],
  // the products of M's structurally nonzero entries (both triangles) and [B beta]'s, in the
  // order a scatter over M's entries would add them. Entries with no product stay zero.
  // An independent coordinate's row of [B beta] holds a single 1 (in its own column), so an
  // entry of the product has at most one such term, M's entry itself: mb_unit_[o] (or the
  // index of a zero after M's entries) starts the sum, and the gathered products are the others.
  std::vector<int> mb_place_, mb_start_, mb_mass_, mb_s_, mb_unit_;
  // J's structurally nonzero entries in the independent and driven columns, the only ones a
  // kinematic seed reaches before the dependent rows are solved for: dh = J dq there when the
  // parameters are not seeded, and d(J qd) = J dqd for a direction that moves no coordinate.
  struct JacobianEntry {
    int row, col;
  };
  std::vector<JacobianEntry> seeded_entries_;
  const GeneratedModel& model_;
  std::vector<int> u_, v_, f_, d_;
  std::vector<double> pad_;  // one zero for arrays of size zero
  BlockLU jv_blocks_;        // Jv's block structure, copied into each Result
};

}  // namespace dydp::mbs
