// Fixed-step linearly implicit Rosenbrock-W scheme ROS2 (two stages, order 2 whatever matrix W
// stands for the Jacobian, L-stable when W = J) for replay and real-time runs: W is an exact
// Jacobian from a tangent pass, factored once and kept over many steps, so a step costs two
// right-hand sides and two back-substitutions, no Newton iteration. Its sensitivities are the
// exact derivatives of the discrete map with W held constant.
#pragma once

#include <vector>

#include "engine/analysis/run_result.hpp"

namespace dydp::engine {

RunResult run_rosenbrock(const Diagram& d, const RunOptions& options);

/// The same scheme with W given (column-major, num_states x num_states) and never refreshed:
/// the map whose derivative the sensitivities are, for tests against differences of runs.
RunResult run_rosenbrock_fixed_w(const Diagram& d, const RunOptions& options, const std::vector<double>& w);

}  // namespace dydp::engine
