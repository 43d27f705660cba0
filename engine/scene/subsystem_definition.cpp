#include "engine/scene/subsystem_definition.hpp"

#include <algorithm>
#include <filesystem>

#include "engine/framework/errors.hpp"
#include "engine/scene/duplicate_keys.hpp"

namespace dydp::engine {
namespace {

constexpr int kMaxIncludeDepth = 16;

int line_of(const YAML::Node& n) { return n.Mark().is_null() ? 0 : n.Mark().line + 1; }

std::string scalar(const YAML::Node& n, const std::string& file, const std::string& field) {
  if (!n.IsScalar()) throw InputError(file, line_of(n), field, "expected a single value");
  return n.Scalar();
}

/// A port name or an internal "block.port" must be a plain name or exactly one dot apart.
void check_port_name(const YAML::Node& key, const std::string& file, const std::string& field) {
  const std::string name = key.Scalar();
  if (name.empty() || name.find_first_of(". ") != std::string::npos)
    throw InputError(file, line_of(key), field, "port name '" + name + "' must be non-empty, without '.' or spaces");
}

Written internal_port(const YAML::Node& n, const std::string& file, const std::string& field) {
  Written w{scalar(n, file, field), file, line_of(n)};
  const auto dot = w.text.find('.');
  if (dot == std::string::npos || dot == 0 || dot + 1 == w.text.size() ||
      w.text.find('.', dot + 1) != std::string::npos)
    throw InputError(file, w.line, field, "expected an internal 'block.port', got '" + w.text + "'");
  return w;
}

void read_parameters(const YAML::Node& n, const std::string& file, const std::string& where,
                     SubsystemDefinition& def) {
  if (!n) return;
  if (!n.IsMap()) throw InputError(file, line_of(n), where + "parameters", "expected a mapping of name: {value, unit}");
  for (auto kv : n) {
    SubsystemParameter p;
    p.name = scalar(kv.first, file, where + "parameters");
    p.line = line_of(kv.first);
    const std::string field = where + "parameters." + p.name;
    if (p.name.empty() || p.name.find_first_of(". $") != std::string::npos)
      throw InputError(file, p.line, field, "parameter name must be non-empty, without '.', '$' or spaces");
    // The default: `value:` of a mapping, or the scalar or list itself; none (`{unit: ...}` or
    // an empty value) makes it required.
    std::vector<YAML::Node> value;
    if (kv.second.IsMap()) {
      for (auto entry : kv.second) {
        const std::string key = entry.first.Scalar();
        if (key == "value") value.push_back(entry.second);
        else if (key == "unit") p.unit = scalar(entry.second, file, field + ".unit");
        else if (key == "description") p.description = scalar(entry.second, file, field + ".description");
        else throw InputError(file, line_of(entry.first), field + "." + key, "unknown key (value, unit, description)");
      }
    } else if (!kv.second.IsNull()) {
      value.push_back(kv.second);
    }
    if (!value.empty()) {
      p.has_default = true;
      if (value.front().IsSequence()) {
        p.default_is_list = true;
        for (auto item : value.front()) p.default_items.push_back(scalar(item, file, field + ".value"));
      } else {
        p.default_items.push_back(scalar(value.front(), file, field + ".value"));
      }
    }
    def.parameters.push_back(std::move(p));
  }
}

void read_ports(const YAML::Node& in, const YAML::Node& out, const std::string& file,
                const std::string& where, SubsystemDefinition& def) {
  if (in) {
    if (!in.IsMap())
      throw InputError(file, line_of(in), where + "inputs", "expected a mapping of port: [block.port, ...]");
    for (auto kv : in) {
      const std::string field = where + "inputs." + kv.first.Scalar();
      check_port_name(kv.first, file, field);
      std::vector<Written> targets;
      if (kv.second.IsSequence()) {
        for (auto item : kv.second) targets.push_back(internal_port(item, file, field));
      } else {
        targets.push_back(internal_port(kv.second, file, field));
      }
      if (targets.empty()) throw InputError(file, line_of(kv.first), field, "drives no internal input");
      def.inputs.emplace_back(kv.first.Scalar(), std::move(targets));
    }
  }
  if (out) {
    if (!out.IsMap())
      throw InputError(file, line_of(out), where + "outputs", "expected a mapping of port: block.port");
    for (auto kv : out) {
      const std::string field = where + "outputs." + kv.first.Scalar();
      check_port_name(kv.first, file, field);
      if (def.find_input(kv.first.Scalar()))
        throw InputError(file, line_of(kv.first), field, "also the name of an input port");
      def.outputs.emplace_back(kv.first.Scalar(), internal_port(kv.second, file, field));
    }
  }
}

/// The body of a definition, inline (`where`: "subsystems.NAME.") or a file's top level ("").
std::shared_ptr<SubsystemDefinition> read_body(const YAML::Node& body, const std::string& name,
                                               const std::string& file, const std::string& where,
                                               int line, const SubsystemLibrary& parent, int depth) {
  auto def = std::make_shared<SubsystemDefinition>();
  def->name = name;
  def->file = file;
  def->line = line;
  def->library.parent = &parent;
  const bool own_file = where.empty();
  for (auto kv : body) {
    const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : std::string();
    static const char* const inline_keys[] = {"description", "parameters", "inputs", "outputs",
                                              "blocks", "connections", "subsystems", "layout"};
    const bool known = std::find(std::begin(inline_keys), std::end(inline_keys), key) != std::end(inline_keys) ||
                       (own_file && key == "subsystem");
    if (!known) throw InputError(file, line_of(kv.first), where + key, "unknown key of a subsystem");
  }
  if (body["description"]) def->description = scalar(body["description"], file, where + "description");
  read_parameters(body["parameters"], file, where, *def);
  read_ports(body["inputs"], body["outputs"], file, where, *def);
  const YAML::Node blocks = body["blocks"];
  if (!blocks || !blocks.IsMap() || blocks.size() == 0)
    throw InputError(file, line_of(blocks ? blocks : body), where + "blocks", "a subsystem needs a mapping of blocks");
  def->blocks = blocks;
  if (const YAML::Node connections = body["connections"]) {
    def->connections = connections;
    def->has_connections = true;
  }
  read_subsystem_section(body["subsystems"], file, def->library, depth + 1);
  return def;
}

std::shared_ptr<SubsystemDefinition> read_file(const YAML::Node& ref, const std::string& name,
                                               const std::string& including_file, const std::string& field,
                                               const SubsystemLibrary& parent, int depth) {
  const std::string text = scalar(ref, including_file, field);
  namespace fs = std::filesystem;
  const fs::path rel(text);
  const std::string path =
      rel.is_absolute() ? text : (fs::path(including_file).parent_path() / rel).lexically_normal().string();
  if (depth > kMaxIncludeDepth)
    throw InputError(including_file, line_of(ref), field,
                     "subsystem files included more than " + std::to_string(kMaxIncludeDepth) + " deep (a file including itself?)");
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw InputError(including_file, line_of(ref), field, "'" + path + "' is a folder, not a subsystem file");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw InputError(including_file, line_of(ref), field, "cannot open the subsystem file '" + path + "'");
  } catch (const YAML::ParserException& e) {
    throw InputError(path, e.mark.line + 1, "", "YAML syntax: " + e.msg);
  }
  if (!root.IsMap()) throw InputError(path, 1, "", "a subsystem file is a YAML mapping");
  refuse_duplicate_keys(root, path);
  const YAML::Node declared = root["subsystem"];
  if (!declared) throw InputError(path, 1, "subsystem", "missing: a subsystem file starts with 'subsystem: NAME'");
  const std::string own = scalar(declared, path, "subsystem");
  if (own != name)
    throw InputError(including_file, line_of(ref), field,
                     "'" + path + "' defines subsystem '" + own + "', not '" + name + "'");
  return read_body(root, name, path, "", line_of(declared), parent, depth);
}

}  // namespace

const SubsystemDefinition* SubsystemLibrary::find(const std::string& name) const {
  for (const SubsystemLibrary* l = this; l; l = l->parent) {
    auto it = l->definitions.find(name);
    if (it != l->definitions.end()) return it->second.get();
  }
  return nullptr;
}

std::string SubsystemLibrary::names() const {
  std::string out;
  for (const SubsystemLibrary* l = this; l; l = l->parent)
    for (const auto& [name, def] : l->definitions) out += (out.empty() ? "" : ", ") + name;
  return out.empty() ? "none" : out;
}

const SubsystemParameter* SubsystemDefinition::find_parameter(const std::string& n) const {
  for (const auto& p : parameters)
    if (p.name == n) return &p;
  return nullptr;
}

const std::vector<Written>* SubsystemDefinition::find_input(const std::string& port) const {
  for (const auto& [name, targets] : inputs)
    if (name == port) return &targets;
  return nullptr;
}

const Written* SubsystemDefinition::find_output(const std::string& port) const {
  for (const auto& [name, source] : outputs)
    if (name == port) return &source;
  return nullptr;
}

namespace {
template <class List, class Name>
std::string join_names(const List& list, Name name) {
  std::string out;
  for (const auto& item : list) out += " " + name(item);
  return out.empty() ? " none" : out;
}
}  // namespace

std::string SubsystemDefinition::parameter_names() const {
  return join_names(parameters, [](const SubsystemParameter& p) { return p.name; });
}
std::string SubsystemDefinition::input_names() const {
  return join_names(inputs, [](const auto& p) { return p.first; });
}
std::string SubsystemDefinition::output_names() const {
  return join_names(outputs, [](const auto& p) { return p.first; });
}

void read_subsystem_section(const YAML::Node& section, const std::string& file,
                            SubsystemLibrary& library, int depth) {
  if (!section) return;
  if (!section.IsMap())
    throw InputError(file, line_of(section), "subsystems", "expected a mapping of name: {file: PATH} or a definition");
  for (auto kv : section) {
    const std::string name = scalar(kv.first, file, "subsystems");
    const std::string field = "subsystems." + name;
    if (name.empty() || name.find_first_of(". ") != std::string::npos)
      throw InputError(file, line_of(kv.first), field, "subsystem name must be non-empty, without '.' or spaces");
    if (library.definitions.count(name))
      throw InputError(file, line_of(kv.first), field, "subsystem defined twice");
    const YAML::Node& body = kv.second;
    if (!body.IsMap())
      throw InputError(file, line_of(kv.first), field, "expected {file: PATH} or a definition with blocks");
    std::shared_ptr<SubsystemDefinition> def;
    if (body["file"]) {
      if (body.size() != 1)
        for (auto entry : body)
          if (entry.first.Scalar() != "file")
            throw InputError(file, line_of(entry.first), field + "." + entry.first.Scalar(),
                             "a subsystem included by file has no other keys here");
      def = read_file(body["file"], name, file, field + ".file", library, depth);
    } else {
      def = read_body(body, name, file, field + ".", line_of(kv.first), library, depth);
    }
    library.definitions.emplace(name, std::move(def));
  }
}

}  // namespace dydp::engine
