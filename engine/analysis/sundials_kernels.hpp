// Compiled kernels for the serial N_Vector's and the dense SUNMatrix's busiest operations.
//
// Debian's SUNDIALS 6.4.1 (libsundials-dev) ships its vector and matrix modules without
// optimisation: every element of N_VLinearSum goes through the stack, about 20 instructions where
// an optimised loop needs two or three. On the main job those kernels were 15 % of all
// instructions (docs/performance.md, 2026-12-03). SUNDIALS dispatches every operation through
// the object's table of function pointers, so replacing the hot entries of the template vector
// (its clones copy the table) and of the Newton matrix (its clones get the same kernels) moves
// that work into code built with the project's flags.
//
// Each kernel does per element what the library's does, in the same order, including its special
// cases (N_VLinearSum's a == b and a == -b forms, N_VLinearCombination's two- and one-vector
// forms): the results are the same bit for bit (tests/engine/analysis/sundials_kernels_test.cpp).
#pragma once

#include <sundials/sundials_matrix.h>
#include <sundials/sundials_nvector.h>

namespace dydp::engine {

// Replaces the hot operations of a serial vector; vectors cloned from it afterwards inherit them.
void use_compiled_vector_kernels(N_Vector v);

// Replaces copy, zero and scale-add-identity of a dense matrix, and its clone so that the copies
// CVODES keeps (the saved Jacobian) get the same.
void use_compiled_matrix_kernels(SUNMatrix A);

}  // namespace dydp::engine
