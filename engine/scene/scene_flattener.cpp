#include "engine/scene/scene_flattener.hpp"

#include <algorithm>

#include "engine/framework/errors.hpp"

namespace dydp::engine {
namespace {

int line_of(const YAML::Node& n) { return n.Mark().is_null() ? 0 : n.Mark().line + 1; }

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  const auto e = s.find_last_not_of(" \t");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

std::string scalar(const YAML::Node& n, const std::string& file, const std::string& field) {
  if (!n.IsScalar()) throw InputError(file, line_of(n), field, "expected a single value");
  return n.Scalar();
}

constexpr const char* kSubsystemPrefix = "subsystem.";

}  // namespace

void SceneFlattener::add_scene(const std::string& file, const SubsystemLibrary& library,
                               const YAML::Node& blocks, const YAML::Node& connections) {
  scene_.scope.file = file;
  scene_.scope.library = &library;
  expand(scene_, blocks, connections ? &connections : nullptr);
}

void SceneFlattener::expand(Level& level, const YAML::Node& blocks, const YAML::Node* connections) {
  const std::string& file = level.scope.file;
  for (auto kv : blocks) {
    const std::string local = kv.first.IsScalar() ? kv.first.Scalar() : std::string();
    const std::string flat = level.scope.prefix + local;
    if (local.empty() || local.find_first_of(". ") != std::string::npos)
      throw InputError(file, line_of(kv.first), level.scope.prefix.empty() ? "blocks" : flat,
                       "block name '" + local + "' must be non-empty, without '.' or spaces");
    if (level.blocks.count(local) || level.instances.count(local))
      throw InputError(file, line_of(kv.first), flat, "block defined twice");
    const YAML::Node type = kv.second.IsMap() ? kv.second["type"] : YAML::Node();
    const std::string type_name = type && type.IsScalar() ? type.Scalar() : std::string();
    if (type_name.rfind(kSubsystemPrefix, 0) == 0) {
      const std::string name = type_name.substr(std::string(kSubsystemPrefix).size());
      const SubsystemDefinition* def = level.scope.library->find(name);
      if (!def)
        throw InputError(file, line_of(type), flat + ".type",
                         "unknown subsystem '" + name + "' (defined: " + level.scope.library->names() + ")");
      instantiate(level, kv.first, kv.second, *def, type);
      continue;
    }
    graph_.add_block(read_block(level.scope, kv.first, kv.second, d_, forced_, warnings_));
    level.blocks.insert(local);
  }

  if (connections) {
    if (!connections->IsSequence())
      throw InputError(file, line_of(*connections), level.scope.prefix + "connections",
                       "expected a list of 'block.port -> block.port'");
    for (auto item : *connections) connect(level, item);
  }
  // An instance's input port left open would leave its internal inputs undriven: say so here,
  // where the instance is written, rather than inside the subsystem.
  for (const auto& [local, inside] : level.instances)
    for (const auto& [port, targets] : inside->scope.definition->inputs)
      if (!inside->driven.count(port))
        throw InputError(inside->file, inside->line, inside->name + "." + port, "input is not connected");
}

void SceneFlattener::instantiate(Level& outer, const YAML::Node& key, const YAML::Node& body,
                                 const SubsystemDefinition& def, const YAML::Node& type_node) {
  const std::string& file = outer.scope.file;
  const std::string local = key.Scalar();
  auto inside = std::make_unique<Level>();
  inside->name = outer.scope.prefix + local;
  inside->file = file;
  inside->line = line_of(key);
  if (std::find(open_.begin(), open_.end(), &def) != open_.end()) {
    std::string chain;
    for (const SubsystemDefinition* open : open_) chain += open->name + " -> ";
    throw InputError(file, line_of(type_node), inside->name + ".type",
                     "subsystem '" + def.name + "' contains itself (" + chain + def.name + ")");
  }
  Scope& scope = inside->scope;
  scope.file = def.file;
  scope.prefix = inside->name + ".";
  scope.definition = &def;
  scope.library = &def.library;

  for (auto kv : body) {
    const std::string k = kv.first.Scalar();
    if (k == "type") continue;
    const std::string field = inside->name + "." + k;
    if (!def.find_parameter(k))
      throw InputError(file, line_of(kv.first), field,
                       "unknown parameter of subsystem." + def.name + " (known:" + def.parameter_names() + ")");
    Binding b;
    b.file = file;
    b.line = line_of(kv.second);
    b.field = field;
    if (kv.second.IsSequence()) {
      b.is_list = true;
      for (auto item : kv.second) b.items.push_back(scalar(item, file, field));
    } else {
      const std::string text = scalar(kv.second, file, field);
      if (!text.empty() && text[0] == '$') {
        if (outer.scope.definition) {
          b = find_binding(outer.scope, kv.second, field, text.substr(1));
        } else {
          b.scene = d_.find_parameter(text.substr(1));
          if (b.scene < 0) throw InputError(file, b.line, field, "unknown scene parameter '" + text + "'");
          b.items.push_back(text);
        }
      } else {
        b.items.push_back(text);
      }
    }
    scope.bindings.emplace(k, std::move(b));
  }
  for (const SubsystemParameter& p : def.parameters) {
    if (scope.bindings.count(p.name)) continue;
    if (!p.has_default)
      throw InputError(file, line_of(key), inside->name + "." + p.name,
                       "required parameter of subsystem " + def.name + " is missing (defined at " +
                           place(def.file, p.line) + ")");
    scope.bindings.emplace(p.name, Binding{p.default_items, p.default_is_list, -1, def.file, p.line,
                                           inside->name + "." + p.name});
  }

  open_.push_back(&def);
  expand(*inside, def.blocks, def.has_connections ? &def.connections : nullptr);
  open_.pop_back();
  // Every port must stand for something inside, used or not.
  std::vector<FlatPort> unused;
  for (const auto& [port, targets] : def.inputs)
    for (const Written& t : targets) this->targets(*inside, t.text, t.file, t.line, unused, false);
  for (const auto& [port, s] : def.outputs) source(*inside, s.text, s.file, s.line);
  outer.instances.emplace(local, std::move(inside));
}

void SceneFlattener::connect(Level& level, const YAML::Node& item) {
  const std::string& file = level.scope.file;
  const std::string text = scalar(item, file, "connections");
  const int line = line_of(item);
  const auto arrow = text.find("->");
  if (arrow == std::string::npos)
    throw InputError(file, line, "connections", "expected 'block.port -> block.port', got '" + text + "'");
  const std::string from = trim(text.substr(0, arrow)), to = trim(text.substr(arrow + 2));
  const auto is_block_port = [](const std::string& end) {
    const auto dot = end.find('.');
    return dot != std::string::npos && dot > 0 && dot + 1 < end.size();
  };
  if (!is_block_port(from) || !is_block_port(to))
    throw InputError(file, line, "connections", "both ends need block.port, got '" + text + "'");
  const FlatPort src = source(level, from, file, line);
  std::vector<FlatPort> dsts;
  targets(level, to, file, line, dsts, true);
  for (const FlatPort& dst : dsts) graph_.connect(src.first, src.second, dst.first, dst.second, line, file);
}

SceneFlattener::FlatPort SceneFlattener::source(const Level& level, const std::string& text,
                                                const std::string& file, int line) const {
  const auto dot = text.find('.');
  const std::string local = text.substr(0, dot), port = text.substr(dot + 1);
  const auto inside = level.instances.find(local);
  if (inside == level.instances.end()) {
    // A plain block, or an unknown one: the graph names either.
    const FlatPort flat{level.scope.prefix + local, port};
    graph_.check_port(flat.first, flat.second, false, line, file);
    return flat;
  }
  const SubsystemDefinition& def = *inside->second->scope.definition;
  const Written* shown = def.find_output(port);
  if (!shown)
    throw InputError(file, line, level.scope.prefix + text,
                     "subsystem instance '" + inside->second->name + "' (subsystem." + def.name +
                         ") has no output port '" + port + "' (outputs:" + def.output_names() + ")");
  return source(*inside->second, shown->text, shown->file, shown->line);
}

void SceneFlattener::targets(const Level& level, const std::string& text, const std::string& file,
                             int line, std::vector<FlatPort>& out, bool mark_driven) const {
  const auto dot = text.find('.');
  const std::string local = text.substr(0, dot), port = text.substr(dot + 1);
  const auto inside = level.instances.find(local);
  if (inside == level.instances.end()) {
    const FlatPort flat{level.scope.prefix + local, port};
    graph_.check_port(flat.first, flat.second, true, line, file);
    out.push_back(flat);
    return;
  }
  Level& instance = *inside->second;
  const SubsystemDefinition& def = *instance.scope.definition;
  const std::vector<Written>* internal = def.find_input(port);
  if (!internal)
    throw InputError(file, line, level.scope.prefix + text,
                     "subsystem instance '" + instance.name + "' (subsystem." + def.name +
                         ") has no input port '" + port + "' (inputs:" + def.input_names() + ")");
  if (mark_driven) instance.driven.insert(port);
  for (const Written& t : *internal) targets(instance, t.text, t.file, t.line, out, false);
}

void SceneFlattener::request_output(const std::string& text, const std::string& file, int line) {
  const std::string item = trim(text);
  request(scene_, item, item, file, line);
}

void SceneFlattener::request(const Level& level, const std::string& text, const std::string& shown,
                             const std::string& file, int line) {
  const auto dot = text.find('.');
  const std::string local = text.substr(0, dot);
  const std::string rest = dot == std::string::npos ? "" : text.substr(dot + 1);
  const auto inside = level.instances.find(local);
  if (inside == level.instances.end()) {
    graph_.request_output(level.scope.prefix + local, rest, line, file, rest.empty() ? "" : shown);
    return;
  }
  const Level& instance = *inside->second;
  const SubsystemDefinition& def = *instance.scope.definition;
  if (rest.empty()) {
    if (def.outputs.empty())
      throw InputError(file, line, shown, "subsystem instance '" + instance.name + "' has no output ports");
    for (const auto& [port, s] : def.outputs) {
      const FlatPort src = source(instance, s.text, s.file, s.line);
      graph_.request_output(src.first, src.second, line, file, shown + "." + port);
    }
    return;
  }
  if (rest.find('.') == std::string::npos && def.find_output(rest)) {
    const Written& s = *def.find_output(rest);
    const FlatPort src = source(instance, s.text, s.file, s.line);
    graph_.request_output(src.first, src.second, line, file, shown);
    return;
  }
  const auto next = rest.find('.');
  const std::string inner = rest.substr(0, next);
  if (!instance.blocks.count(inner) && !instance.instances.count(inner))
    throw InputError(file, line, shown,
                     "subsystem instance '" + instance.name + "' (subsystem." + def.name +
                         ") has no output port or block '" + inner + "' (outputs:" + def.output_names() + ")");
  request(instance, rest, shown, file, line);
}

}  // namespace dydp::engine
