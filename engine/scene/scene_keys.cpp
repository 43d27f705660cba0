// The list of the scene format's keys, from the tables the loader checks against.
#include "engine/scene/scene_keys.hpp"

namespace dydp::engine {

std::vector<std::string> scene_format_keys() {
  std::vector<std::string> keys(kSceneKeys.begin(), kSceneKeys.end());
  auto add = [&keys](const std::string& prefix, const auto& table) {
    for (const char* key : table) keys.push_back(prefix + key);
  };
  add("time.", kTimeKeys);
  add("solver.", kSolverKeys);
  add("initial.", kInitialKeys);
  add("parameters.*.", kSceneParameterKeys);
  add("directions.*.", kDirectionKeys);
  return keys;
}

}  // namespace dydp::engine
