// The meaning of a loaded scene as text, for comparing two files that should say the same:
// blocks (type, parameter values and $refs, settings, nominal magnitudes), connections, outputs,
// objectives, sensitivities, scene parameters, time and solver. Layout and formatting do not enter.
#pragma once

#include <cstdio>
#include <map>
#include <sstream>
#include <string>

#include "engine/framework/diagram.hpp"

namespace dydp::gui::testing {

inline std::string exact(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

inline std::string diagram_meaning(const engine::Diagram& d) {
  std::ostringstream s;
  s << "scene " << d.scene_name << "\n";
  s << "time " << exact(d.time.start) << " " << exact(d.time.stop) << " " << exact(d.time.output_step) << "\n";
  s << "solver " << d.solver.method << " " << exact(d.solver.rtol) << " " << exact(d.solver.atol) << " "
    << exact(d.solver.step) << " " << d.solver.max_steps << " " << d.solver.sens_error_test << " "
    << exact(d.solver.min_step) << " " << d.solver.nominal_scaling << "\n";
  s << "solver newton_coefficient " << exact(d.solver.newton_coefficient) << " max_order " << d.solver.max_order
    << " refresh_local_jacobians " << d.solver.refresh_local_jacobians << "\n";
  s << "initial " << (d.initial.equilibrium ? "equilibrium" : "declared");
  for (const auto& [offset, value] : d.initial.held) s << " hold " << offset << "=" << exact(value);
  s << "\n";
  for (const auto& p : d.parameters)
    s << "parameter " << p.name << " = " << exact(p.value) << " [" << p.unit << "] in [" << exact(p.lower)
      << ", " << exact(p.upper) << "]\n";
  for (int i : d.sensitivities) s << "direction " << d.parameters[i].name << "\n";
  // Which port each signal offset is, to name the source of every input.
  std::map<int, std::string> port_at;
  for (const auto& n : d.nodes)
    for (size_t k = 0; k < n.output_offset.size(); ++k)
      port_at[n.output_offset[k]] = n.name + "." + n.block->outputs()[k].name;
  for (const auto& n : d.nodes) {
    s << "block " << n.name << ": " << n.type->name << "\n";
    for (size_t j = 0; j < n.p.size(); ++j) {
      s << "  " << n.type->parameters[j].name << " = " << exact(n.p[j]);
      if (n.p_scene[j] >= 0) s << " ($" << d.parameters[n.p_scene[j]].name << ")";
      s << "\n";
    }
    for (size_t k = 0; k < n.input_source.size(); ++k)
      s << "  " << port_at[n.input_source[k]] << " -> " << n.name << "." << n.block->inputs()[k].name << "\n";
    // settings as written (objective windows, road class and seed, steering mode, input files,
    // demux indices, ...) and the states' nominal magnitudes
    for (const auto& spec : n.type->settings) {
      s << "  setting " << spec.name << " =";
      for (const auto& item : n.settings->texts(spec.name)) s << " " << item;
      s << "\n";
    }
    s << "  nominal";
    for (double v : n.state_nominal) s << " " << exact(v);
    s << "\n";
    s << "  states " << n.block->num_states() << ", quadratures " << n.block->num_quadratures() << "\n";
  }
  for (const auto& p : d.pruned) s << "pruned " << p << "\n";
  for (const auto& l : d.logged) s << "logged " << l.name << "\n";
  for (int i : d.objectives) s << "objective " << d.nodes[i].name << "\n";
  return s.str();
}

}  // namespace dydp::gui::testing
