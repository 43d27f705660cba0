#include "engine/framework/registry.hpp"

#include <stdexcept>

namespace dydp::engine {

Registry& Registry::global() {
  static Registry registry;
  return registry;
}

void Registry::add(BlockType type) {
  const std::string name = type.name;
  if (!types_.emplace(name, std::move(type)).second)
    throw std::logic_error("block type registered twice: " + name);
}

const BlockType* Registry::find(const std::string& name) const {
  auto it = types_.find(name);
  return it == types_.end() ? nullptr : &it->second;
}

std::vector<const BlockType*> Registry::all() const {
  std::vector<const BlockType*> out;
  for (const auto& [name, type] : types_) out.push_back(&type);
  return out;
}

}  // namespace dydp::engine
