// Sensitivity directions named by block parameters instead of scene parameters: one block
// parameter (`corner_fl.damper.friction`), or one group driving the same parameter of several
// blocks as one direction (`{name: piston_valve, of: "corner_*.damper.piston_rebound_section"}`).
// Each becomes a scene parameter of the diagram, so sweeps, --set and screening see no difference.
// A scene's `directions:` list declares such directions (with their ranges) without computing
// them; its `sensitivities:` list (or `dydp sweep`, `dydp screen`) picks the ones to compute.
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "engine/framework/diagram.hpp"

namespace dydp::engine {

/// One entry of a scene's `sensitivities:` list as written.
struct DirectionEntry {
  std::string name;                  ///< the direction's name (a scene parameter's, or new)
  std::vector<std::string> members;  ///< block.parameter paths, `*` matching any characters
  std::vector<int> member_lines;     ///< where each member was written
  bool has_range = false;
  double lower = 0.0, upper = 0.0;   ///< `range: [lower, upper]` when has_range
  std::string unit;                  ///< `unit:` when written (checked against the blocks')
  int line = 0;
  bool scene_parameter = false;      ///< names a scene parameter or a declared direction (plain name)
};

/// Reads a `directions:` or `sensitivities:` list (`field`) of `file`: plain names of scene
/// parameters or of `declared` directions (sensitivities only), block parameter paths, or
/// mappings {name, of, range, unit}. Throws InputError where an entry is malformed.
std::vector<DirectionEntry> read_direction_entries(const YAML::Node& list, const std::string& file,
                                                   const std::string& field, const Diagram& d,
                                                   const std::vector<DirectionEntry>& declared = {});

/// Binds the entries that name block parameters to the flattened blocks: each becomes a scene
/// parameter (value: the members' common value; range: the entry's or the block's bounds) that
/// drives its members; with `compute`, every entry's scene parameter joins d.sensitivities in
/// list order (`sensitivities:`), without it they are declared only (`directions:`).
/// Throws InputError at the entry's line for an unknown, already driven, non-differentiable or
/// doubly named member, and for members of one group that disagree in value or unit.
void bind_directions(const std::vector<DirectionEntry>& entries, const std::string& file,
                     std::vector<Node>& nodes, Diagram& d, bool compute);

}  // namespace dydp::engine
