// The block registry: every block type's metadata (group, one-line summary, parameters with
// units and bounds, settings) and its factory. Filled by static registration in blocks/;
// read by the scene loader, `dydp blocks` and the GUI.
#pragma once

#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "engine/framework/block.hpp"
#include "engine/framework/block_check.hpp"
#include "engine/framework/block_settings.hpp"

namespace dydp::engine {

/// A numeric block parameter: may be given as a number or as `$scene_parameter`.
struct ParamSpec {
  std::string name;
  std::string unit;
  double default_value = 0.0;
  bool required = false;
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  std::string description;
  /// False for parameters the block's laws are not differentiable in (switching times):
  /// a sensitivity direction on such a parameter is refused at load time.
  bool differentiable = true;
};

struct BlockType {
  std::string name;     ///< as written in scenes, e.g. "source.sine"
  std::string group;    ///< palette group: sources, math, mechanics, objectives, ...
  std::string summary;  ///< one line
  std::vector<ParamSpec> parameters;
  std::vector<SettingSpec> settings;
  std::function<std::unique_ptr<Block>(const BlockSettings&)> make;
  /// Relations its values must satisfy, checked at load time and whenever a scene parameter
  /// driving one of them changes (engine/scene/consistency_checks.hpp).
  std::vector<BlockCheck> checks = {};
};

class Registry {
 public:
  /// The one registry of the program, filled before main() by BlockRegistration objects.
  static Registry& global();

  void add(BlockType type);
  const BlockType* find(const std::string& name) const;
  std::vector<const BlockType*> all() const;

 private:
  std::map<std::string, BlockType> types_;
};

/// Declared at namespace scope in a block's .cpp: registers the type during static init.
struct BlockRegistration {
  explicit BlockRegistration(BlockType type) { Registry::global().add(std::move(type)); }
};

}  // namespace dydp::engine
