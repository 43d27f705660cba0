#include "engine/dense_lu_solver.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <nvector/nvector_serial.h>
#include <sunmatrix/sunmatrix_dense.h>

namespace dydp::engine {
namespace {

struct Content {
  Eigen::PartialPivLU<Eigen::MatrixXd> lu;
  Eigen::MatrixXd work;
  Eigen::VectorXd rhs;  ///< the permuted right-hand side, substituted in place
  sunindextype last_flag = 0;
};

Content& content(SUNLinearSolver S) { return *static_cast<Content*>(S->content); }

SUNLinearSolver_Type type(SUNLinearSolver) { return SUNLINEARSOLVER_DIRECT; }
SUNLinearSolver_ID id(SUNLinearSolver) { return SUNLINEARSOLVER_CUSTOM; }
int initialize(SUNLinearSolver S) {
  content(S).last_flag = 0;
  return SUNLS_SUCCESS;
}

// A zero or non-finite pivot: a recoverable failure (CVODES retries with a smaller step), as
// SUNLinSol_Dense reports it, with the (1-based) column in the last flag.
int setup(SUNLinearSolver S, SUNMatrix A) {
  Content& c = content(S);
  const auto n = static_cast<Eigen::Index>(SM_ROWS_D(A));
  c.work = Eigen::Map<const Eigen::MatrixXd>(SM_DATA_D(A), n, n);
  c.lu.compute(c.work);
  const Eigen::MatrixXd& U = c.lu.matrixLU();
  for (Eigen::Index k = 0; k < n; ++k) {
    if (U(k, k) == 0.0 || !std::isfinite(U(k, k))) {
      c.last_flag = k + 1;
      return SUNLS_LUFACT_FAIL;
    }
  }
  c.last_flag = 0;
  return SUNLS_SUCCESS;
}

// x = U^-1 L^-1 P b by column-oriented substitutions: each step is one contiguous multiply-add
// over a column of the factors. Eigen's own solve splits the small triangles into panels and
// matrix-vector products, at about five instructions per multiply-add on 54 unknowns (a
// fifteenth of the main job).
int solve(SUNLinearSolver S, SUNMatrix A, N_Vector x, N_Vector b, realtype) {
  Content& c = content(S);
  const auto n = static_cast<Eigen::Index>(SM_ROWS_D(A));
  const double* __restrict lu = c.lu.matrixLU().data();
  const auto& to = c.lu.permutationP().indices();  // (P b)[to[i]] = b[i]
  double* __restrict z = c.rhs.data();
  const double* bv = NV_DATA_S(b);
  for (Eigen::Index i = 0; i < n; ++i) z[to[i]] = bv[i];
  for (Eigen::Index j = 0; j < n; ++j) {  // L (unit diagonal)
    const double zj = z[j];
    if (zj == 0.0) continue;
    const double* __restrict below = lu + j * n + j + 1;
    double* __restrict rest = z + j + 1;
    for (Eigen::Index i = 0; i < n - j - 1; ++i) rest[i] -= below[i] * zj;
  }
  for (Eigen::Index j = n - 1; j >= 0; --j) {  // U
    const double* __restrict column = lu + j * n;
    const double zj = z[j] /= column[j];
    if (zj == 0.0) continue;
    for (Eigen::Index i = 0; i < j; ++i) z[i] -= column[i] * zj;
  }
  std::copy_n(z, n, NV_DATA_S(x));
  c.last_flag = 0;
  return SUNLS_SUCCESS;
}

sunindextype last_flag(SUNLinearSolver S) { return content(S).last_flag; }

int space(SUNLinearSolver S, long int* real_words, long int* integer_words) {
  const Content& c = content(S);
  *real_words = static_cast<long int>(2 * c.work.size());
  *integer_words = static_cast<long int>(c.work.rows());
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
  c->lu = Eigen::PartialPivLU<Eigen::MatrixXd>(n);
  S->content = c;
  return S;
}

}  // namespace dydp::engine
