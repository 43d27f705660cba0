// CVODES driver: BDF (Newton, exact dense Jacobian) or Adams (fixed point), with forward
// sensitivities and quadratures. See cvodes_solver.cpp.
#pragma once

#include "engine/analysis/run_result.hpp"

namespace dydp::engine {

RunResult run_cvodes(const Diagram& d, const RunOptions& options);

}  // namespace dydp::engine
