// Running a block type's consistency checks (engine/framework/block_check.hpp) over one node of a
// diagram: a broken error rule is an InputError at the line of the field it names; a broken
// warning rule becomes a "file:line: field: message" warning of the run.
#pragma once

#include <string>
#include <vector>

#include "engine/framework/diagram.hpp"

namespace dydp::engine {

/// Checks node n with parameter values p (ParamSpec order; n.p, or the values a new scene
/// parameter value would give). Throws InputError for the first broken error rule; appends
/// broken warning rules to `warnings` when given.
void check_block(const std::string& file, const Node& n, const std::vector<double>& p,
                 const TimeSpec& time, std::vector<std::string>* warnings);

/// The rules of a block type for `dydp blocks`, one per line: "rule" or "rule (warning)".
std::vector<std::string> check_rules(const BlockType& type);

}  // namespace dydp::engine
