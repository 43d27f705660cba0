// The Newton iteration's linear solver for CVODES: the dense matrix SUNDIALS forms (I - gamma J)
// factored by NewtonLU (engine/analysis/newton_lu.hpp: the rows x_i + c x_j = b_i substituted out, the
// rest by Eigen's partial-pivoting LU) instead of SUNDIALS' own column-by-column GETRF/GETRS,
// which on the sedan's 52 states took about a seventh of the main job. A SUNDIALS linear solver
// of the direct type on a dense SUNMatrix, so CVODES uses it like SUNLinSol_Dense; a zero pivot
// is a recoverable failure naming its column, as SUNLinSol_Dense reports it.
#pragma once

#include <functional>

#include <sundials/sundials_context.h>
#include <sundials/sundials_matrix.h>
#include <sundials/sundials_linearsolver.h>

namespace dydp::engine {

// A solver for square dense matrices (sized at its first set-up); free it with SUNLinSolFree.
SUNLinearSolver make_dense_lu_solver(SUNContext context);

// Called with the Newton matrix (I - gamma J as CVODES formed it) before each factorisation, to
// refresh parts of it in place; an empty function refreshes nothing.
using MatrixRefresh = std::function<void(SUNMatrix)>;
void set_matrix_refresh(SUNLinearSolver solver, MatrixRefresh refresh);

}  // namespace dydp::engine
