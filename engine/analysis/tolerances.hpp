// Absolute tolerances in physical units: the solver's atol scaled by each state's nominal
// magnitude (declared by its block, overridden by the scene's `nominal:` map), and for the
// sensitivities further by the parameter's value (CVODES' pbar), so that dx/dp * |p| is held
// like x. Quadratures likewise with their blocks' nominal magnitudes.
#pragma once

#include <string>
#include <vector>

#include "engine/framework/diagram.hpp"

namespace dydp::engine {

struct AbsoluteTolerances {
  std::vector<double> states;                    ///< [num_states]
  std::vector<double> quadratures;               ///< [num_quadratures]
  std::vector<double> sensitivities;             ///< [directions * num_states], direction-major
  std::vector<double> quadrature_sensitivities;  ///< [directions * num_quadratures]
};

/// Nominal magnitude of every state of the diagram, in state order.
std::vector<double> state_nominals(const Diagram& d);

/// `block.state` for state i of the diagram.
std::string state_label(const Diagram& d, int i);

/// The absolute tolerances for atol over `directions` sensitivity directions
/// (d.sensitivities[0 .. directions)); with d.solver.nominal_scaling off, every nominal is 1.
AbsoluteTolerances absolute_tolerances(const Diagram& d, double atol, int directions);

}  // namespace dydp::engine
