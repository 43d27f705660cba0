#include "engine/dense_lu_solver.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <vector>
#include <nvector/nvector_serial.h>
#include <sunmatrix/sunmatrix_dense.h>

namespace dydp::engine {
namespace {

struct Content {
  // Kinematic rows: row i of the matrix is x_i + c_i x_{p_i} = b_i, the form the Newton matrix
  // I - gamma J takes for a state whose derivative is another state (a position whose derivative
  // is its velocity: the car's fourteen u). Such x_i are substituted out and only the other rows
  // and columns (`kept`) are factored, a 38 x 38 system for the main job's 52 states.
  std::vector<int> eliminated, partner, kept;  // eliminated[e] = i, partner[e] = p_i
  std::vector<double> coefficient;             // c_i
  Eigen::MatrixXd coupling;                    // A(kept, eliminated): how b_i enters the kept rows
  Eigen::PartialPivLU<Eigen::MatrixXd> lu;
  Eigen::MatrixXd work;
  Eigen::VectorXd rhs;  ///< the permuted right-hand side, substituted in place
  Eigen::VectorXd kept_rhs;  ///< b over the kept rows, the eliminated ones' b moved in
  std::vector<int> place;                      // row/column of the full matrix -> place in kept (-1: eliminated)
  sunindextype last_flag = 0;
};

Content& content(SUNLinearSolver S) { return *static_cast<Content*>(S->content); }

SUNLinearSolver_Type type(SUNLinearSolver) { return SUNLINEARSOLVER_DIRECT; }
SUNLinearSolver_ID id(SUNLinearSolver) { return SUNLINEARSOLVER_CUSTOM; }
int initialize(SUNLinearSolver S) {
  content(S).last_flag = 0;
  return SUNLS_SUCCESS;
}

// The kinematic rows of column-major a (n x n): a unit diagonal and one other nonzero, in a
// column that is not itself eliminated.
void find_kinematic_rows(const double* a, Eigen::Index n, Content& c) {
  c.eliminated.clear();
  c.partner.clear();
  c.coefficient.clear();
  std::vector<int> other(static_cast<std::size_t>(n), -1);  // -1 none yet, -2 more than one
  for (Eigen::Index j = 0; j < n; ++j) {
    const double* column = a + j * n;
    for (Eigen::Index i = 0; i < n; ++i) {
      if (i == j || column[i] == 0.0) continue;
      other[i] = other[i] == -1 ? static_cast<int>(j) : -2;
    }
  }
  std::vector<char> candidate(static_cast<std::size_t>(n), 0);
  for (Eigen::Index i = 0; i < n; ++i) candidate[i] = other[i] >= 0 && a[i * n + i] == 1.0;
  c.place.assign(static_cast<std::size_t>(n), -1);
  c.kept.clear();
  for (Eigen::Index i = 0; i < n; ++i) {
    if (candidate[i] && !candidate[other[i]]) {
      c.eliminated.push_back(static_cast<int>(i));
      c.partner.push_back(other[i]);
      c.coefficient.push_back(a[static_cast<Eigen::Index>(other[i]) * n + i]);
    } else {
      c.place[i] = static_cast<int>(c.kept.size());
      c.kept.push_back(static_cast<int>(i));
    }
  }
}

// A zero or non-finite pivot: a recoverable failure (CVODES retries with a smaller step), as
// SUNLinSol_Dense reports it, with the (1-based) column in the last flag.
int setup(SUNLinearSolver S, SUNMatrix A) {
  Content& c = content(S);
  const auto n = static_cast<Eigen::Index>(SM_ROWS_D(A));
  const double* a = SM_DATA_D(A);
  find_kinematic_rows(a, n, c);
  const auto m = static_cast<Eigen::Index>(c.kept.size());
  const auto ne = static_cast<Eigen::Index>(c.eliminated.size());
  // A(kept, kept) with x_i = b_i - c_i x_{p_i} substituted: column p_i gains -A(kept, i) c_i
  c.work.resize(m, m);
  for (Eigen::Index k = 0; k < m; ++k) {
    const double* column = a + static_cast<Eigen::Index>(c.kept[k]) * n;
    double* out = c.work.data() + k * m;
    for (Eigen::Index r = 0; r < m; ++r) out[r] = column[c.kept[r]];
  }
  c.coupling.resize(m, ne);
  for (Eigen::Index e = 0; e < ne; ++e) {
    const double* column = a + static_cast<Eigen::Index>(c.eliminated[e]) * n;
    double* coupling = c.coupling.data() + e * m;
    for (Eigen::Index r = 0; r < m; ++r) coupling[r] = column[c.kept[r]];
    double* target = c.work.data() + static_cast<Eigen::Index>(c.place[c.partner[e]]) * m;
    const double ce = c.coefficient[e];
    for (Eigen::Index r = 0; r < m; ++r) target[r] -= coupling[r] * ce;
  }
  c.lu.compute(c.work);
  const Eigen::MatrixXd& U = c.lu.matrixLU();
  for (Eigen::Index k = 0; k < m; ++k) {
    if (U(k, k) == 0.0 || !std::isfinite(U(k, k))) {
      c.last_flag = c.kept[k] + 1;
      return SUNLS_LUFACT_FAIL;
    }
  }
  c.last_flag = 0;
  return SUNLS_SUCCESS;
}

// x = U^-1 L^-1 P b by column-oriented substitutions: each step is one contiguous multiply-add
// over a column of the factors. Eigen's own solve splits the small triangles into panels and
// matrix-vector products, at about five instructions per multiply-add on 54 unknowns (a
// fifteenth of the main job). The kinematic rows before (their b_i moved to the kept rows) and
// after (x_i from its partner).
int solve(SUNLinearSolver S, SUNMatrix A, N_Vector x, N_Vector b, realtype) {
  Content& c = content(S);
  const auto m = static_cast<Eigen::Index>(c.kept.size());
  const auto ne = static_cast<Eigen::Index>(c.eliminated.size());
  const double* __restrict lu = c.lu.matrixLU().data();
  const auto& to = c.lu.permutationP().indices();  // (P b)[to[i]] = b[i]
  double* __restrict z = c.rhs.data();
  const double* bv = NV_DATA_S(b);
  double* __restrict y = c.kept_rhs.data();
  for (Eigen::Index r = 0; r < m; ++r) y[r] = bv[c.kept[r]];
  for (Eigen::Index e = 0; e < ne; ++e) {
    const double be = bv[c.eliminated[e]];
    if (be == 0.0) continue;
    const double* __restrict coupling = c.coupling.data() + e * m;
    for (Eigen::Index r = 0; r < m; ++r) y[r] -= coupling[r] * be;
  }
  for (Eigen::Index i = 0; i < m; ++i) z[to[i]] = y[i];
  for (Eigen::Index j = 0; j < m; ++j) {  // L (unit diagonal)
    const double zj = z[j];
    if (zj == 0.0) continue;
    const double* __restrict below = lu + j * m + j + 1;
    double* __restrict rest = z + j + 1;
    for (Eigen::Index i = 0; i < m - j - 1; ++i) rest[i] -= below[i] * zj;
  }
  for (Eigen::Index j = m - 1; j >= 0; --j) {  // U
    const double* __restrict column = lu + j * m;
    const double zj = z[j] /= column[j];
    if (zj == 0.0) continue;
    for (Eigen::Index i = 0; i < j; ++i) z[i] -= column[i] * zj;
  }
  double* xv = NV_DATA_S(x);
  // x may be b: the eliminated entries read their b before the kept ones are written
  for (Eigen::Index e = 0; e < ne; ++e) {
    const int i = c.eliminated[e];
    xv[i] = bv[i] - c.coefficient[e] * z[c.place[c.partner[e]]];
  }
  for (Eigen::Index r = 0; r < m; ++r) xv[c.kept[r]] = z[r];
  c.last_flag = 0;
  return SUNLS_SUCCESS;
}

sunindextype last_flag(SUNLinearSolver S) { return content(S).last_flag; }

int space(SUNLinearSolver S, long int* real_words, long int* integer_words) {
  const Content& c = content(S);
  // the factored matrix, its factors and the kinematic rows' coupling and coefficients
  *real_words = static_cast<long int>(2 * c.work.size() + c.coupling.size() + c.coefficient.size());
  *integer_words = static_cast<long int>(c.work.rows() + c.kept.size() + 2 * c.eliminated.size() + c.place.size());
  return SUNLS_SUCCESS;
}

int release(SUNLinearSolver S) {
  if (!S) return SUNLS_SUCCESS;
  delete static_cast<Content*>(S->content);
  S->content = nullptr;
  SUNLinSolFreeEmpty(S);
  return SUNLS_SUCCESS;
}

}  // namespace

SUNLinearSolver make_dense_lu_solver(SUNContext context, int n) {
  SUNLinearSolver S = SUNLinSolNewEmpty(context);
  if (!S) return nullptr;
  S->ops->gettype = type;
  S->ops->getid = id;
  S->ops->initialize = initialize;
  S->ops->setup = setup;
  S->ops->solve = solve;
  S->ops->lastflag = last_flag;
  S->ops->space = space;
  S->ops->free = release;
  auto* c = new Content;
  c->work.resize(n, n);
  c->rhs.resize(n);
  c->kept_rhs.resize(n);
  c->lu = Eigen::PartialPivLU<Eigen::MatrixXd>(n);
  S->content = c;
  return S;
}

}  // namespace dydp::engine
