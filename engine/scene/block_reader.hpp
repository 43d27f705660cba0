// Reads one block of a scene or of a subsystem into a Node: its type, its parameters (numbers,
// `$scene_parameter`, or inside a subsystem `$subsystem_parameter`) and settings, each value
// checked where it was written, so errors name that file and line.
#pragma once

#include <yaml-cpp/yaml.h>

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "engine/framework/diagram.hpp"

namespace dydp::engine {

struct SubsystemDefinition;
struct SubsystemLibrary;

/// The value one subsystem parameter takes in one instance, in the scene's terms: a plain value
/// as written, or a scene parameter (through any depth of nesting).
struct Binding {
  std::vector<std::string> items;  ///< the value as written (one item unless a list)
  bool is_list = false;
  int scene = -1;                  ///< scene parameter index when bound to `$name`
  std::string file;                ///< where the value was written
  int line = 0;
  std::string field;               ///< `corner_fl.stiffness`: the instance's key that gave it
};

/// Where blocks are read: the scene itself, or the inside of one subsystem instance.
struct Scope {
  std::string file;                     ///< the file its blocks are written in
  std::string prefix;                   ///< "" in the scene; "corner_fl." inside instance corner_fl
  const SubsystemDefinition* definition = nullptr;  ///< null in the scene
  const SubsystemLibrary* library = nullptr;        ///< the subsystem types visible here
  std::map<std::string, Binding> bindings;          ///< subsystem parameter -> value
};

/// A number as written at file:line (field names it in errors): malformed and underflowing
/// numbers (denormal or zero as a double, 1e-320) are refused.
double scene_number(const std::string& text, const std::string& file, int line, const std::string& field);

/// "file:line" of a value for messages that name a second place.
std::string place(const std::string& file, int line);

/// The binding a `$name` written at `at` (in scope.file) refers to inside a subsystem; throws
/// naming the subsystem's parameters when there is no such parameter.
const Binding& find_binding(const Scope& scope, const YAML::Node& at, const std::string& field,
                            const std::string& name);

/// One block: `key` its name in the scope, `body` its mapping. `forced` (SETTING, VALUE)
/// replaces that setting where the type declares it. Consistency warnings go to `warnings`.
Node read_block(const Scope& scope, const YAML::Node& key, const YAML::Node& body, const Diagram& d,
                const std::vector<std::pair<std::string, std::string>>& forced,
                std::vector<std::string>& warnings);

}  // namespace dydp::engine
