#include "gui/ports_in_use.hpp"

#include <set>

namespace dydp::gui {

BlockPorts ports_in_use(const BlockPorts& all, const std::string& block, const std::vector<DocConnection>& connections,
                        const std::vector<std::string>& outputs) {
  BlockPorts ports = all;
  if (ports.inputs.size() + ports.outputs.size() <= kPortsShownAll) return ports;
  std::set<std::string> used_in, used_out;
  for (const DocConnection& c : connections) {
    if (c.to.block == block) used_in.insert(c.to.port);
    if (c.from.block == block) used_out.insert(c.from.port);
  }
  for (const std::string& o : outputs) {
    PortRef r;
    if (PortRef::parse(o, r) && r.block == block) used_out.insert(r.port);
  }
  std::erase_if(ports.inputs, [&](const engine::PortDecl& p) { return !used_in.count(p.name); });
  std::erase_if(ports.outputs, [&](const engine::PortDecl& p) { return !used_out.count(p.name); });
  return ports;
}

}  // namespace dydp::gui
