// The GUI's model of a scene file: blocks (type, name, position, parameter values or $refs,
// settings), connections, scene parameters, sensitivities, time, solver and outputs, kept as
// the text the user wrote, so that a scene opened and saved again keeps its meaning exactly.
// Reading and writing YAML live in scene_yaml.cpp; validation is the engine's (load_scene).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace dydp::gui {

/// A value as written in a scene: one scalar, a list of scalars (`window: [2.0, 10.0]`), or a
/// mapping of names to scalars (a block's state nominal magnitudes, `nominal: {x: 0.01}`).
struct SceneValue {
  std::vector<std::string> items;
  bool is_list = false;
  /// A mapping: keys[i] names items[i].
  std::vector<std::string> keys;
  bool is_map = false;

  static SceneValue scalar(std::string text) { return {{std::move(text)}, false, {}, false}; }
  /// "[a, b]" reads as a list, "{k: a, l: b}" as a mapping, anything else as one scalar
  /// (surrounding blanks removed).
  static SceneValue parse(const std::string& text);
  /// The inverse of parse: "1.5", "$mass", "[2.0, 10.0]", "{x: 0.01}".
  std::string text() const;
  bool operator==(const SceneValue&) const = default;
};

/// Keys with text values in the order they were written (time, solver).
using Fields = std::vector<std::pair<std::string, std::string>>;
const std::string* find_field(const Fields& f, const std::string& key);
/// Sets key to text; an empty text removes the key.
void set_field(Fields& f, const std::string& key, const std::string& text);

struct DocBlock {
  std::string name;
  std::string type;
  /// Parameters and settings of the block, in the order written (type excluded).
  std::vector<std::pair<std::string, SceneValue>> values;
  double x = 0.0, y = 0.0;  ///< canvas position of the block's top-left corner
  bool placed = false;      ///< the position came from the `layout:` section or the canvas

  const SceneValue* find(const std::string& key) const;
  /// Sets key; an empty scalar removes the key (the type's default applies).
  void set(const std::string& key, const SceneValue& v);
  bool operator==(const DocBlock&) const = default;
};

struct DocParameter {
  std::string name;
  std::string value;
  std::string unit;
  std::string low, high;     ///< both empty: no range
  std::string description;
  bool operator==(const DocParameter&) const = default;
};

struct PortRef {
  std::string block, port;
  std::string text() const { return block + "." + port; }
  /// "block.port"; false when there is no dot.
  static bool parse(const std::string& text, PortRef& out);
  bool operator==(const PortRef&) const = default;
};

struct DocConnection {
  PortRef from, to;  ///< output port -> input port
  std::string text() const { return from.text() + " -> " + to.text(); }
  bool operator==(const DocConnection&) const = default;
};

/// A subsystem definition of the scene (docs/scenes.md, "Subsystems"), included from a file or
/// written inline. An instance (`type: subsystem.NAME`) is drawn as one block with the
/// definition's ports; opening it shows the blocks inside, editable in an inline definition.
struct DocSubsystem {
  std::string name;
  std::string file;          ///< `{file: PATH}` as written; empty: inline
  std::string inline_yaml;   ///< inline: the definition as read, written back with the same meaning
  std::string source;        ///< the file the definition's body is read from
  std::string error;         ///< not empty: the definition could not be read (ports unknown)
  std::string description;
  /// Parameters and their defaults (no items: the instance must give a value).
  std::vector<std::pair<std::string, SceneValue>> parameters;
  std::vector<std::pair<std::string, std::vector<std::string>>> inputs;  ///< port -> internal block.port
  std::vector<std::pair<std::string, std::string>> outputs;              ///< port -> internal block.port
  std::vector<DocBlock> blocks;             ///< inside, positions from its `layout:` or by signal flow
  std::vector<DocConnection> connections;   ///< inside

  const DocBlock* find_block(const std::string& name) const;
  DocBlock* find_block(const std::string& name);
  bool operator==(const DocSubsystem&) const = default;
};

/// The prefix of an instance's type: `subsystem.corner` names the definition `corner`.
inline constexpr const char* kSubsystemTypePrefix = "subsystem.";

struct SceneDocument {
  std::string header_comment;  ///< leading `#` lines of the file, kept on save
  std::string scene;
  std::string description;
  Fields time;
  Fields solver;
  /// The `initial:` section (where runs start: `equilibrium`, or `{state, hold}`) as YAML text,
  /// kept on save as it was read; empty when the scene has none. The GUI does not edit it.
  std::string initial;
  std::vector<DocParameter> parameters;
  std::vector<std::string> sensitivities;
  /// The `directions:` list (directions named by block parameters, docs/scenes.md) as YAML text,
  /// kept on save as it was read; empty when the scene has none. The GUI does not edit it.
  std::string directions;
  std::vector<DocSubsystem> subsystems;
  std::vector<DocBlock> blocks;
  std::vector<DocConnection> connections;
  std::vector<std::string> outputs;

  DocBlock* find_block(const std::string& name);
  const DocBlock* find_block(const std::string& name) const;
  /// The definition an instance block refers to (null: not an instance, or no such definition).
  const DocSubsystem* subsystem_of(const DocBlock& block) const;
  const DocSubsystem* find_subsystem(const std::string& name) const;
  DocParameter* find_parameter(const std::string& name);
  const DocParameter* find_parameter(const std::string& name) const;
  /// The connection driving input `to`, or null.
  const DocConnection* driver_of(const PortRef& to) const;
  /// A block name not yet used, from a stem ("sine" -> "sine", "sine2", ...).
  std::string unique_block_name(const std::string& stem) const;
  /// A scene parameter name not yet used, from a stem.
  std::string unique_parameter_name(const std::string& stem) const;
  bool operator==(const SceneDocument&) const = default;
};

/// Reads a scene file. Throws engine::InputError (file, line) when the file is not YAML or not
/// shaped like a scene (the engine checks everything else when the scene is run).
SceneDocument read_scene_file(const std::string& path);
/// Parses scene text; `file` names it in errors.
SceneDocument parse_scene(const std::string& text, const std::string& file);
/// The scene as YAML in the documented shape, with a `layout:` section of block positions.
std::string write_scene(const SceneDocument& doc);
/// Writes write_scene(doc) to path atomically.
void write_scene_file(const SceneDocument& doc, const std::string& path);

}  // namespace dydp::gui
