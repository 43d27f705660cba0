#include <cmath>
#include <iomanip>

#include "apps/dydp/commands.hpp"
#include "engine/framework/registry.hpp"
#include "engine/scene/consistency_checks.hpp"

namespace dydp::apps {

int blocks_command(std::ostream& out) {
  for (const engine::BlockType* t : engine::Registry::global().all()) {
    out << t->name << "  [" << t->group << "]  " << t->summary << "\n";
    for (const auto& p : t->parameters) {
      out << "    param   " << std::left << std::setw(12) << p.name << " default " << p.default_value;
      if (!p.unit.empty()) out << " " << p.unit;
      if (std::isfinite(p.lower) || std::isfinite(p.upper))
        out << "  in [" << p.lower << ", " << p.upper << "]";
      // A differentiable parameter can be a sensitivity direction by its path (block.name).
      out << "  " << p.description << (p.differentiable ? "  [direction]" : "  (not differentiable: no direction)") << "\n";
    }
    for (const auto& s : t->settings)
      out << "    setting " << std::left << std::setw(12) << s.name
          << (s.required ? " required" : " default '" + s.default_value + "'") << "  "
          << s.description << "\n";
    for (const std::string& rule : engine::check_rules(*t)) out << "    check   " << rule << "\n";
    // Ports of an instance with default settings (types that need settings say so).
    engine::BlockSettings defaults(t->name, "", 0);
    bool complete = true;
    for (const auto& s : t->settings) {
      if (s.required) complete = false;
      else defaults.set(s.name, {{s.default_value}, false, 0, {}});
    }
    if (!complete) {
      out << "    ports depend on the settings\n";
      continue;
    }
    const auto block = t->make(defaults);
    for (const auto& p : block->inputs())
      out << "    input   " << std::left << std::setw(12) << p.name << " width " << p.width
          << (p.unit.empty() ? "" : " [" + p.unit + "]") << "\n";
    for (const auto& p : block->outputs())
      out << "    output  " << std::left << std::setw(12) << p.name << " width " << p.width
          << (p.unit.empty() ? "" : " [" + p.unit + "]") << "\n";
    // The nominal magnitudes scale the absolute tolerance of each state (a scene's `nominal:`
    // map overrides them).
    for (int i = 0; i < block->num_states(); ++i)
      out << "    state   " << std::left << std::setw(12) << block->state_names()[i] << " nominal "
          << block->state_nominals()[i] << "\n";
  }
  return 0;
}

}  // namespace dydp::apps
