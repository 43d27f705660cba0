// The Newton iteration's linear solver for CVODES: the dense matrix SUNDIALS forms (I - gamma J)
// factored by Eigen's partial-pivoting LU (blocked and vectorised) instead of SUNDIALS' own
// column-by-column GETRF/GETRS, which on the sedan's 52 states took about a seventh of the
// main job; solved by plain column-oriented substitutions (Eigen's panelled triangular solves
// are slow at this size). A SUNDIALS linear solver of the direct type on a dense SUNMatrix, so
// CVODES uses it like SUNLinSol_Dense.
//
// Rows of the form x_i + c x_j = b_i (a unit diagonal and one other entry: in I - gamma J, a
// state whose derivative is another state, the car's positions) are substituted out before the
// factorisation, x_i = b_i - c x_j, so only the other rows are factored: 38 of the main job's 52
// states, a third of the factorisation's work and a quarter of each solve's.
#pragma once

#include <sundials/sundials_context.h>
#include <sundials/sundials_linearsolver.h>

namespace dydp::engine {

// A solver for n x n dense matrices; free it with SUNLinSolFree.
SUNLinearSolver make_dense_lu_solver(SUNContext context, int n);

}  // namespace dydp::engine
