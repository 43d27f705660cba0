// Running a diagram: the one entry point that picks the integrator the scene's solver names
// (CVODES BDF or Adams, RK4, SDIRK2, Rosenbrock-W). The types it takes and gives are in
// run_result.hpp, which the integrators include instead of this file.
#pragma once

#include "engine/analysis/run_result.hpp"

namespace dydp::engine {

/// Runs the diagram with the method of its solver spec. Throws SolverError on failure.
RunResult run(const Diagram& d, const RunOptions& options = {});

}  // namespace dydp::engine
