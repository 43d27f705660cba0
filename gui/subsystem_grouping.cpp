#include "gui/subsystem_grouping.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <set>

#include "gui/subsystem_yaml.hpp"

namespace dydp::gui {
namespace {

constexpr double kInsideOrigin = 40;  // [px] the inside's top-left block in the definition's layout

bool member(const std::set<std::string>& s, const std::string& name) { return s.count(name) > 0; }

/// The `of` paths and patterns of the scene's `directions:` entries (and plain entries).
std::vector<std::string> direction_paths(const std::string& directions) {
  std::vector<std::string> out;
  if (directions.empty()) return out;
  const YAML::Node list = YAML::Load(directions);
  const auto add = [&](const YAML::Node& n) {
    if (n.IsScalar()) out.push_back(n.Scalar());
    else if (n.IsSequence())
      for (auto item : n)
        if (item.IsScalar()) out.push_back(item.Scalar());
  };
  for (auto entry : list) {
    if (entry.IsScalar()) out.push_back(entry.Scalar());
    else if (entry.IsMap() && entry["of"]) add(entry["of"]);
  }
  return out;
}

/// Whether path or pattern (`*` any characters) may name a parameter of `block`.
bool may_name_block(const std::string& path, const std::string& block) {
  const std::string head = block + ".";
  const auto star = path.find('*');
  if (star == std::string::npos) return path.rfind(head, 0) == 0;
  // A pattern: its text before the first `*` must agree with "block." as far as both go.
  const std::string literal = path.substr(0, star);
  const size_t n = std::min(literal.size(), head.size());
  return literal.compare(0, n, head, 0, n) == 0;
}

/// A port name not yet in `used`: the internal port's (`stroke_rate`), else `block_port` (also
/// for names too short to say anything, such as a gain's `u` and `y`), else numbered.
std::string port_name(const PortRef& inside, std::set<std::string>& used) {
  std::string name = inside.port;
  if (used.count(name) || name.size() <= 2) name = inside.block + "_" + inside.port;
  const std::string stem = name;
  for (int k = 2; used.count(name); ++k) name = stem + std::to_string(k);
  used.insert(name);
  return name;
}

/// The scene parameters a block's values refer to (`$name`), in order of first use.
void collect_references(const DocBlock& b, std::vector<std::string>& refs) {
  for (const auto& [key, value] : b.values)
    for (const std::string& item : value.items)
      if (item.size() > 1 && item[0] == '$' && std::find(refs.begin(), refs.end(), item.substr(1)) == refs.end())
        refs.push_back(item.substr(1));
}

/// Why `names` cannot be grouped ("" when they can): none, one not at the scene's level, or a
/// `directions:` entry that may name a parameter of one.
std::string refusal(const SceneDocument& doc, const std::vector<std::string>& names) {
  if (names.empty()) return "select the blocks to group first";
  for (const std::string& name : names)
    if (!doc.find_block(name)) return "no block '" + name + "' at the scene's level";
  for (const std::string& path : direction_paths(doc.directions))
    for (const std::string& name : names)
      if (may_name_block(path, name))
        return "directions: '" + path + "' may name a parameter of " + name +
               "; grouping would change what it names: edit the directions first";
  return {};
}

/// Copies the blocks `inside` into def (moved to the definition's origin) and their scene
/// parameters into refs; returns the top-left corner they had in the scene.
std::pair<double, double> copy_blocks(const SceneDocument& doc, const std::set<std::string>& inside,
                                      DocSubsystem& def, std::vector<std::string>& refs) {
  double left = 1e300, top = 1e300;
  for (const DocBlock& b : doc.blocks)
    if (member(inside, b.name)) {
      def.blocks.push_back(b);
      collect_references(b, refs);
      left = std::min(left, b.x);
      top = std::min(top, b.y);
    }
  for (DocBlock& b : def.blocks) {
    b.x += kInsideOrigin - left;
    b.y += kInsideOrigin - top;
    b.placed = true;
  }
  return {left, top};
}

/// Adds def's parameters and the instance's values passing refs through; returns the
/// definition's `parameters:` (with the scene's units).
YAML::Node pass_parameters(const SceneDocument& doc, const std::vector<std::string>& refs, DocSubsystem& def,
                           DocBlock& instance) {
  // A scene parameter used inside is passed through by a parameter of the same name.
  YAML::Node parameters(YAML::NodeType::Map);
  for (const std::string& ref : refs) {
    def.parameters.emplace_back(ref, SceneValue{});
    instance.values.emplace_back(ref, SceneValue::scalar("$" + ref));
    YAML::Node p(YAML::NodeType::Map);
    if (const DocParameter* sp = doc.find_parameter(ref); sp && !sp->unit.empty()) p["unit"] = sp->unit;
    p.SetStyle(YAML::EmitterStyle::Flow);
    parameters[ref] = p;
  }
  return parameters;
}

/// Sorts doc's wires into def's (inside, and its ports) and after's (the rest, through the
/// instance `name`).
void split_wires(const SceneDocument& doc, const std::set<std::string>& inside, const std::string& name,
                 DocSubsystem& def, SceneDocument& after) {
  // Wires: inside stay inside; a wire into the selection is an input port (one per source
  // outside, driving every internal input it drove), one out of it an output port (one per
  // internal source).
  std::set<std::string> port_names;
  std::vector<std::pair<PortRef, std::string>> input_of_source, output_of_source;
  const auto find_port = [](auto& list, const PortRef& r) {
    return std::find_if(list.begin(), list.end(), [&](const auto& e) { return e.first == r; });
  };
  after.connections.clear();
  for (const DocConnection& c : doc.connections) {
    const bool from_in = member(inside, c.from.block), to_in = member(inside, c.to.block);
    if (from_in && to_in) {
      def.connections.push_back(c);
    } else if (to_in) {
      auto it = find_port(input_of_source, c.from);
      if (it == input_of_source.end()) {
        input_of_source.emplace_back(c.from, port_name(c.to, port_names));
        def.inputs.emplace_back(input_of_source.back().second, std::vector<std::string>{});
        after.connections.push_back({c.from, {name, input_of_source.back().second}});
        it = input_of_source.end() - 1;
      }
      for (auto& [port, targets] : def.inputs)
        if (port == it->second) targets.push_back(c.to.text());
    } else if (from_in) {
      auto it = find_port(output_of_source, c.from);
      if (it == output_of_source.end()) {
        output_of_source.emplace_back(c.from, port_name(c.from, port_names));
        def.outputs.emplace_back(output_of_source.back().second, c.from.text());
        it = output_of_source.end() - 1;
      }
      after.connections.push_back({{name, it->second}, c.to});
    } else {
      after.connections.push_back(c);
    }
  }
}

/// The definition's inline YAML: description, parameters, inputs and outputs.
std::string definition_yaml(const DocSubsystem& def, const YAML::Node& parameters) {
  YAML::Node inputs(YAML::NodeType::Map), outputs(YAML::NodeType::Map);
  for (const auto& [port, targets] : def.inputs) {
    if (targets.size() == 1) {
      inputs[port] = targets.front();
      continue;
    }
    YAML::Node list(YAML::NodeType::Sequence);
    for (const std::string& t : targets) list.push_back(t);
    list.SetStyle(YAML::EmitterStyle::Flow);
    inputs[port] = list;
  }
  for (const auto& [port, source] : def.outputs) outputs[port] = source;
  YAML::Node body(YAML::NodeType::Map);
  body["description"] = def.description;
  if (parameters.size() > 0) body["parameters"] = parameters;
  if (inputs.size() > 0) body["inputs"] = inputs;
  if (outputs.size() > 0) body["outputs"] = outputs;
  return YAML::Dump(body);
}

/// Puts the instance in place of the blocks `inside` and def among after's subsystems, and
/// renames the outputs and sensitivities of those blocks through the instance.
void put_instance(const std::set<std::string>& inside, const DocBlock& instance, const DocSubsystem& def,
                  SceneDocument& after) {
  // The scene: the instance where the blocks were; outputs and directions through it.
  // The instance takes the place of the first block grouped, so that the flattened scene lists
  // its blocks where they were (the engine orders states by the blocks' order).
  const std::string& name = instance.name;
  const auto first = std::find_if(after.blocks.begin(), after.blocks.end(),
                                  [&](const DocBlock& b) { return member(inside, b.name); });
  *first = instance;
  std::erase_if(after.blocks, [&](const DocBlock& b) { return member(inside, b.name); });
  after.subsystems.push_back(def);
  for (std::string& o : after.outputs) {
    PortRef r;
    if (member(inside, o) || (PortRef::parse(o, r) && member(inside, r.block))) o = name + "." + o;
  }
  for (std::string& s : after.sensitivities) {
    PortRef r;
    if (PortRef::parse(s, r) && member(inside, r.block)) s = name + "." + s;
  }
}

}  // namespace

Grouping group_into_subsystem(const SceneDocument& doc, const std::vector<std::string>& names) {
  Grouping g;
  g.error = refusal(doc, names);
  if (!g.error.empty()) return g;
  const std::set<std::string> inside(names.begin(), names.end());

  // One name for the definition and the instance, free as both.
  std::string name = "group";
  for (int k = 2; doc.find_block(name) || doc.find_subsystem(name); ++k) name = "group" + std::to_string(k);
  g.instance = name;

  DocSubsystem def;
  def.name = name;
  def.description = "grouped from " + std::to_string(names.size()) + " blocks of the scene";
  std::vector<std::string> refs;
  const auto [left, top] = copy_blocks(doc, inside, def, refs);

  DocBlock instance;
  instance.name = name;
  instance.type = std::string(kSubsystemTypePrefix) + name;
  instance.x = left;
  instance.y = top;
  instance.placed = true;
  const YAML::Node parameters = pass_parameters(doc, refs, def, instance);

  SceneDocument& after = g.after;
  after = doc;
  split_wires(doc, inside, name, def, after);
  def.inline_yaml = definition_yaml(def, parameters);
  store_inside(def);

  put_instance(inside, instance, def, after);
  return g;
}

}  // namespace dydp::gui
