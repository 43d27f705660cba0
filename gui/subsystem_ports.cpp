#include "gui/subsystem_ports.hpp"

#include <optional>

#include "engine/framework/registry.hpp"

namespace dydp::gui {
namespace {

constexpr int kMaxDepth = 16;

const engine::PortDecl* find_port(const std::vector<engine::PortDecl>& ports, const std::string& name) {
  for (const auto& p : ports)
    if (p.name == name) return &p;
  return nullptr;
}

BlockPorts ports_at(const SceneDocument& doc, const DocBlock& block, int depth);

BlockPorts instance_ports_at(const SceneDocument& doc, const DocBlock& instance, int depth) {
  BlockPorts out;
  const DocSubsystem* def = doc.subsystem_of(instance);
  if (!def) {
    out.error = "unknown subsystem '" + instance.type.substr(std::string(kSubsystemTypePrefix).size()) + "'";
    return out;
  }
  if (!def->error.empty()) {
    out.error = def->error;
    return out;
  }
  if (depth > kMaxDepth) {
    out.error = "subsystem '" + def->name + "' contains itself";
    return out;
  }
  // A port takes the declaration of the internal port it stands for, under its own name.
  const auto internal = [&](const std::string& ref, bool input) -> std::optional<engine::PortDecl> {
    PortRef r;
    if (!PortRef::parse(ref, r)) return std::nullopt;
    const DocBlock* b = def->find_block(r.block);
    if (!b) return std::nullopt;
    const BlockPorts inner = ports_at(doc, bound_block(*def, instance, *b), depth + 1);
    const engine::PortDecl* d = find_port(input ? inner.inputs : inner.outputs, r.port);
    if (!d) return std::nullopt;
    return *d;
  };
  for (const auto& [port, targets] : def->inputs) {
    const auto d = targets.empty() ? std::nullopt : internal(targets.front(), true);
    if (!d) {
      out.error = "input port '" + port + "' stands for no internal input";
      continue;
    }
    engine::PortDecl p = *d;
    p.name = port;
    out.inputs.push_back(p);
  }
  for (const auto& [port, source] : def->outputs) {
    const auto d = internal(source, false);
    if (!d) {
      out.error = "output port '" + port + "' stands for no internal output";
      continue;
    }
    engine::PortDecl p = *d;
    p.name = port;
    out.outputs.push_back(p);
  }
  return out;
}

BlockPorts ports_at(const SceneDocument& doc, const DocBlock& block, int depth) {
  if (doc.subsystem_of(block)) return instance_ports_at(doc, block, depth);
  const engine::BlockType* type = engine::Registry::global().find(block.type);
  if (!type) {
    BlockPorts none;
    none.error = "unknown block type '" + block.type + "'";
    return none;
  }
  return ports_of(*type, block);
}

}  // namespace

DocBlock bound_block(const DocSubsystem& def, const DocBlock& instance, const DocBlock& block) {
  const auto binding = [&](const std::string& name) -> const SceneValue* {
    if (const SceneValue* v = instance.find(name)) return v;
    for (const auto& [p, v] : def.parameters)
      if (p == name) return &v;
    return nullptr;
  };
  DocBlock out = block;
  for (auto& [key, value] : out.values) {
    SceneValue bound;
    bound.is_list = value.is_list;
    for (const std::string& item : value.items) {
      const SceneValue* b = item.size() > 1 && item[0] == '$' ? binding(item.substr(1)) : nullptr;
      if (!b) {
        bound.items.push_back(item);
        continue;
      }
      bound.items.insert(bound.items.end(), b->items.begin(), b->items.end());
      bound.is_list = bound.is_list || b->is_list;
    }
    value = bound;
  }
  return out;
}

BlockPorts block_ports(const SceneDocument& doc, const DocBlock& block) { return ports_at(doc, block, 0); }

BlockPorts instance_ports(const SceneDocument& doc, const DocBlock& instance) {
  return instance_ports_at(doc, instance, 0);
}

}  // namespace dydp::gui
