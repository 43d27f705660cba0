// A block's `nominal:` map in a scene: the nominal magnitudes of some of its states, by state
// name, replacing those its type declares (see engine/analysis/tolerances.hpp for what they scale).
#pragma once

#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "engine/framework/block.hpp"

namespace dydp::engine {

/// The block's nominal magnitudes with the map's entries in place of the declared ones.
/// Throws InputError (file, line, `block.nominal.state`) on a state the block does not have,
/// a malformed number, or a value that is not positive and finite.
std::vector<double> read_nominal_overrides(const std::string& file, const std::string& block_name,
                                           const YAML::Node& map, const Block& block);

}  // namespace dydp::engine
