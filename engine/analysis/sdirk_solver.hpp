// Fixed-step L-stable SDIRK2 (two implicit stages, stiffly accurate, gamma = 1 - 1/sqrt 2) for
// stiff scenes at a fixed step, e.g. replay of test-bench records. Its sensitivities are the
// exact derivatives of the discrete solution: each stage's sensitivity solves the stage
// equation's linearisation at the converged stage value.
#pragma once

#include "engine/analysis/run_result.hpp"

namespace dydp::engine {

RunResult run_sdirk(const Diagram& d, const RunOptions& options);

}  // namespace dydp::engine
