// The objectives' gradients by the adjoint method with CVODES: the diagram integrated forward
// with checkpoints (CVodeF), then the adjoint states lambda (one column per objective, together)
// backwards (CVodeB) with the parameter gradient as backward quadratures. See cvodes_adjoint.cpp.
#pragma once

#include <string>

#include "engine/analysis/run_result.hpp"

namespace dydp::engine {

/// The run of d with every requested objective's d(psi)/dp for the sensitivity directions by the
/// adjoint method (signals without sensitivities). Throws InputError naming the objective when
/// one has no adjoint (it reads output samples) and naming --solver bdf for a fixed-step method.
RunResult run_cvodes_adjoint(const Diagram& d, const RunOptions& options);

/// Throws InputError when d cannot be run by the adjoint method (its solver, its objectives).
void check_adjoint_possible(const Diagram& d);

}  // namespace dydp::engine
