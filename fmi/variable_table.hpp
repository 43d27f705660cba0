// The FMU's variables (FMI 3.0, 2.4.7 "Model Variables") as the diagram gives them: time, the
// tunable scene parameters, the inputs (signals whose wires the importer drives), the
// continuous states (the blocks' states, then the objectives' quadratures) and their
// derivatives, the outputs (signals and objectives) and one event indicator per breakpoint.
// The exporter writes modelDescription.xml from it; the FMU builds the same table at
// instantiation from the same scene, so value references agree (the instantiation token).
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "engine/framework/diagram.hpp"
#include "fmi/exposure.hpp"

namespace dydp::fmi {

enum class Role {
  time, parameter, input, state, derivative, output_signal, output_objective, event_indicator,
  output_sensitivity  ///< d(output)/d(direction), Co-Simulation only
};

struct Variable {
  std::string name;
  uint32_t value_reference = 0;
  Role role = Role::time;
  /// parameter: scene parameter index; input: index into the inputs; state, derivative: index
  /// into the FMU's state vector; output_signal: signal offset; output_objective: node index;
  /// event_indicator: index of its breakpoint; output_sensitivity: value reference of its output.
  int index = 0;
  /// output_sensitivity: its direction, an index into VariableTable::sensitivities (and into
  /// the diagram's sensitivities, which begin with them).
  int direction = -1;
  std::string unit;
  std::string description;
  bool has_start = false;
  double start = 0.0;
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  /// Outputs and derivatives: the value references of the inputs and states it depends on
  /// (ModelStructure `dependencies`), sorted.
  std::vector<uint32_t> dependencies;
};

struct VariableTable {
  std::vector<Variable> variables;   ///< value reference = position
  std::vector<int> input_offsets;    ///< signal offset of each input
  std::vector<int> parameters;       ///< exposed scene parameters
  /// The exposed parameters the blocks can differentiate: the parameter knowns of the
  /// directional derivatives, and the diagram's sensitivity directions in the FMU.
  std::vector<int> differentiable;
  /// The description's `sensitivities:` (scene parameter indices): the first directions of the
  /// diagram's sensitivities, the differentiable knowns not among them after.
  std::vector<int> sensitivities;
  int num_block_states = 0;          ///< the diagram's states
  int num_quadratures = 0;           ///< then the objectives' integrals
  std::vector<double> nominals;      ///< per FMU state
  std::vector<double> breakpoints;   ///< the event indicators' times, over the scene's time span
  uint32_t first_state = 0;          ///< value reference of state 0 (the states are consecutive)
  uint32_t first_derivative = 0;     ///< of der(state 0)
  std::string token;                 ///< instantiationToken

  int num_states() const { return num_block_states + num_quadratures; }
  /// The variable of `vr`, or null.
  const Variable* find(uint32_t vr) const { return vr < variables.size() ? &variables[vr] : nullptr; }
};

/// Builds the table for diagram `d` (loaded from e.scene_file) exposing what `e` names; input
/// start values are their signals' values at time.start. Throws engine::InputError naming the
/// description file, line and field for a name the diagram does not have.
VariableTable build_variables(engine::Diagram& d, const Exposure& e);

}  // namespace dydp::fmi
