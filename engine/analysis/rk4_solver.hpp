// Classical fixed-step Runge-Kutta 4 whose sensitivities are the exact derivatives of the
// discrete solution: the tangent pass is taken through every stage.
#pragma once

#include "engine/analysis/run_result.hpp"

namespace dydp::engine {

RunResult run_rk4(const Diagram& d, const RunOptions& options);

}  // namespace dydp::engine
