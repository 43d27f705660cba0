#include "engine/dense_lu_solver.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <nvector/nvector_serial.h>
#include <sunmatrix/sunmatrix_dense.h>

namespace dydp::engine {
namespace {

struct Content {
  Eigen::PartialPivLU<Eigen::MatrixXd> lu;
  Eigen::MatrixXd work;
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

int solve(SUNLinearSolver S, SUNMatrix A, N_Vector x, N_Vector b, realtype) {
  Content& c = content(S);
  const auto n = static_cast<Eigen::Index>(SM_ROWS_D(A));
  Eigen::Map<Eigen::VectorXd> xv(NV_DATA_S(x), n);
  const Eigen::Map<const Eigen::VectorXd> bv(NV_DATA_S(b), n);
  xv = c.lu.solve(bv);
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
  c->lu = Eigen::PartialPivLU<Eigen::MatrixXd>(n);
  S->content = c;
  return S;
}

}  // namespace dydp::engine
