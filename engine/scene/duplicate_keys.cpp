#include "engine/scene/duplicate_keys.hpp"

#include <map>
#include <set>
#include <utility>

#include "engine/framework/errors.hpp"

namespace dydp::engine {
namespace {

int line_of(const YAML::Node& n) { return n.Mark().is_null() ? 0 : n.Mark().line + 1; }

std::string join(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

/// Where each mapping or list starts: an alias (`*name`) is the node of its anchor again, so a
/// node seen once is not walked twice (nested aliases would otherwise cost exponential time).
using Visited = std::set<std::pair<int, int>>;

/// `path`: the field of `node` ("" at the top; under `blocks`, the block's name).
void walk(const YAML::Node& node, const std::string& path, bool is_block_list,
          const std::string& file, Visited& visited) {
  if (!node.IsSequence() && !node.IsMap()) return;
  if (!node.Mark().is_null() && !visited.emplace(node.Mark().line, node.Mark().column).second) return;
  if (node.IsSequence()) {
    for (const YAML::Node& item : node) walk(item, path, false, file, visited);
    return;
  }
  std::map<std::string, int> first_line;
  for (auto kv : node) {
    // A key that is itself a mapping or a list is refused later as an unknown key.
    const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : std::string();
    const int line = line_of(kv.first);
    const auto [seen, inserted] = first_line.emplace(key, line);
    if (!inserted && kv.first.IsScalar()) {
      const std::string field = is_block_list ? key : join(path, key);
      const std::string what = is_block_list ? "block defined twice" : "key given twice";
      throw InputError(file, line, field,
                       what + " (first at line " + std::to_string(seen->second) + ")");
    }
    // The scene's top level and each inline subsystem definition (`subsystems.NAME`) hold a
    // `blocks:` mapping whose keys are block names.
    const bool top = !is_block_list && (path.empty() || (path.rfind("subsystems.", 0) == 0 &&
                                                         path.find('.', 11) == std::string::npos));
    const bool blocks = top && key == "blocks";
    walk(kv.second, is_block_list || blocks ? key : join(path, key), blocks, file, visited);
  }
}

}  // namespace

void refuse_duplicate_keys(const YAML::Node& root, const std::string& file) {
  Visited visited;
  walk(root, "", false, file, visited);
}

}  // namespace dydp::engine
