// A subsystem: a named, parameterised sub-diagram with its own input and output ports, written
// in a scene's `subsystems:` section or in a file of its own (docs/scenes.md, "Subsystems").
// This file reads definitions; scene_flattener.cpp instantiates them as prefixed blocks.
#pragma once

#include <yaml-cpp/yaml.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace dydp::engine {

/// Something written at a place: the text, and the file and line it was written at.
struct Written {
  std::string text;
  std::string file;
  int line = 0;
};

struct SubsystemParameter {
  std::string name;
  bool has_default = false;
  std::vector<std::string> default_items;  ///< the default as written (one item unless a list)
  bool default_is_list = false;
  std::string unit;
  std::string description;
  int line = 0;
};

struct SubsystemDefinition;

/// The definitions visible from one place: its own `subsystems:` section, then the enclosing ones.
struct SubsystemLibrary {
  std::map<std::string, std::shared_ptr<const SubsystemDefinition>> definitions;
  const SubsystemLibrary* parent = nullptr;

  const SubsystemDefinition* find(const std::string& name) const;
  /// "corner, rig_pad" or "none": for messages.
  std::string names() const;
};

struct SubsystemDefinition {
  std::string name;
  std::string file;   ///< where the definition's body is written
  int line = 0;       ///< of its name (inline) or of `subsystem:` (own file)
  std::string description;
  std::vector<SubsystemParameter> parameters;
  /// Input port -> the internal inputs it drives ("damper.stroke"), each with its line.
  std::vector<std::pair<std::string, std::vector<Written>>> inputs;
  /// Output port -> the internal output it shows ("damper.force").
  std::vector<std::pair<std::string, Written>> outputs;
  YAML::Node blocks;       ///< the `blocks:` mapping, read by the flattener
  YAML::Node connections;  ///< the `connections:` list, when has_connections
  bool has_connections = false;
  SubsystemLibrary library;  ///< its own nested definitions; parent: where it was defined

  const SubsystemParameter* find_parameter(const std::string& name) const;
  const std::vector<Written>* find_input(const std::string& port) const;
  const Written* find_output(const std::string& port) const;
  std::string parameter_names() const;
  std::string input_names() const;
  std::string output_names() const;
};

/// Reads a scene's or a subsystem file's `subsystems:` section (undefined: none) into `library`,
/// whose parent must already be set. `file`: the file the section is written in; a definition
/// `{file: PATH}` is read from PATH relative to that file's folder. `depth` bounds nested includes.
/// Throws InputError naming file, line and field.
void read_subsystem_section(const YAML::Node& section, const std::string& file,
                            SubsystemLibrary& library, int depth = 0);

}  // namespace dydp::engine
