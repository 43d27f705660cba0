#include "engine/scene/nominal_overrides.hpp"

#include <algorithm>
#include <cmath>

#include "engine/framework/block_settings.hpp"
#include "engine/framework/errors.hpp"

namespace dydp::engine {

std::vector<double> read_nominal_overrides(const std::string& file, const std::string& block_name,
                                           const YAML::Node& map, const Block& block) {
  std::vector<double> nominal = block.state_nominals();
  const std::string field = block_name + ".nominal";
  const auto line_of = [](const YAML::Node& n) { return n.Mark().is_null() ? 0 : n.Mark().line + 1; };
  if (!map.IsMap())
    throw InputError(file, line_of(map), field, "expected a mapping of state name: nominal magnitude");
  const std::vector<std::string>& names = block.state_names();
  for (auto kv : map) {
    const std::string state = kv.first.Scalar();
    const auto it = std::find(names.begin(), names.end(), state);
    if (it == names.end()) {
      std::string known;
      for (const std::string& n : names) known += " " + n;
      throw InputError(file, line_of(kv.first), field + "." + state,
                       "no state of that name" + (names.empty() ? std::string(" (the block has no states)")
                                                                 : " (states:" + known + ")"));
    }
    double v = 0.0;
    if (!kv.second.IsScalar() || !parse_number(kv.second.Scalar(), v))
      throw InputError(file, line_of(kv.second), field + "." + state, "expected a number");
    if (!(v > 0) || !std::isfinite(v))
      throw InputError(file, line_of(kv.second), field + "." + state,
                       "value " + kv.second.Scalar() + " must be positive and finite");
    nominal[it - names.begin()] = v;
  }
  return nominal;
}

}  // namespace dydp::engine
