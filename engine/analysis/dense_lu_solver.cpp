#include "engine/analysis/dense_lu_solver.hpp"

#include "engine/analysis/newton_lu.hpp"
#include <nvector/nvector_serial.h>
#include <sunmatrix/sunmatrix_dense.h>

namespace dydp::engine {
namespace {

struct Content {
  NewtonLU lu;
  sunindextype last_flag = 0;
  MatrixRefresh refresh;
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
  if (c.refresh) c.refresh(A);
  if (!c.lu.factor(SM_DATA_D(A), static_cast<int>(SM_ROWS_D(A)))) {
    c.last_flag = c.lu.failed_column() + 1;
    return SUNLS_LUFACT_FAIL;
  }
  c.last_flag = 0;
  return SUNLS_SUCCESS;
}

int solve(SUNLinearSolver S, SUNMatrix, N_Vector x, N_Vector b, realtype) {
  Content& c = content(S);
  c.lu.solve(NV_DATA_S(b), NV_DATA_S(x));
  c.last_flag = 0;
  return SUNLS_SUCCESS;
}

sunindextype last_flag(SUNLinearSolver S) { return content(S).last_flag; }

int space(SUNLinearSolver S, long int* real_words, long int* integer_words) {
  const Content& c = content(S);
  *real_words = c.lu.real_words();
  *integer_words = c.lu.integer_words();
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

SUNLinearSolver make_dense_lu_solver(SUNContext context) {
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
  auto* c = new Content;  // sized at the first set-up
  S->content = c;
  return S;
}

void set_matrix_refresh(SUNLinearSolver solver, MatrixRefresh refresh) { content(solver).refresh = std::move(refresh); }

}  // namespace dydp::engine
