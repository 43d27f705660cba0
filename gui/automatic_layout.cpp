#include "gui/automatic_layout.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

#include "gui/diagram_items.hpp"
#include "gui/layered_layout.hpp"
#include "gui/ports_in_use.hpp"
#include "gui/subsystem_ports.hpp"

namespace dydp::gui {
namespace {

constexpr double kBelowPlaced = 120;  // [px] between blocks placed by hand and those laid out

void lay_out(std::vector<DocBlock>& blocks, const std::vector<DocConnection>& connections,
             const std::vector<std::string>& outputs, const std::function<BlockPorts(const DocBlock&)>& ports_of_block,
             LayoutScope scope) {
  std::vector<LayoutBlock> todo;
  double placed_bottom = -INFINITY, placed_left = INFINITY;
  for (const DocBlock& b : blocks) {
    const BlockPorts ports = ports_in_use(ports_of_block(b), b.name, connections, outputs);
    const QSizeF size = block_size(b, ports);
    if (scope == LayoutScope::unplaced_blocks && b.placed) {
      placed_bottom = std::max(placed_bottom, b.y + size.height());
      placed_left = std::min(placed_left, b.x);
      continue;
    }
    LayoutBlock l;
    l.name = b.name;
    l.width = size.width();
    l.height = size.height();
    l.objective = ports.is_objective;
    for (size_t k = 0; k < ports.inputs.size(); ++k) l.input_y[ports.inputs[k].name] = port_offset(k);
    for (size_t k = 0; k < ports.outputs.size(); ++k) l.output_y[ports.outputs[k].name] = port_offset(k);
    todo.push_back(std::move(l));
  }
  if (todo.empty()) return;
  const std::map<std::string, LayoutPosition> at = layered_layout(todo, connections);
  const double dx = std::isfinite(placed_left) ? placed_left - 40 : 0;
  const double dy = std::isfinite(placed_bottom) ? placed_bottom + kBelowPlaced - 40 : 0;
  for (DocBlock& b : blocks) {
    const auto it = at.find(b.name);
    if (it == at.end()) continue;
    b.x = std::round(it->second.x + dx);
    b.y = std::round(it->second.y + dy);
    b.placed = true;
  }
}

}  // namespace

void lay_out_scene(SceneDocument& doc, LayoutScope scope) {
  const SceneDocument& read = doc;
  lay_out(doc.blocks, doc.connections, doc.outputs, [&read](const DocBlock& b) { return block_ports(read, b); }, scope);
}

void lay_out_definition(const SceneDocument& doc, DocSubsystem& def, LayoutScope scope) {
  // Inside, `$name` values are the definition's defaults until an instance gives its own.
  const DocSubsystem copy = def;
  const DocBlock no_instance;
  lay_out(def.blocks, def.connections, {},
          [&](const DocBlock& b) { return block_ports(doc, bound_block(copy, no_instance, b)); }, scope);
}

}  // namespace dydp::gui
