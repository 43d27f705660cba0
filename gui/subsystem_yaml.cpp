#include "gui/subsystem_yaml.hpp"

#include <cmath>
#include <filesystem>

#include "engine/framework/errors.hpp"

namespace dydp::gui {
namespace {

int line_of(const YAML::Node& n) { return n.Mark().is_null() ? 0 : n.Mark().line + 1; }

SceneValue value_of(const YAML::Node& n) {
  SceneValue v;
  if (n.IsSequence()) {
    v.is_list = true;
    for (auto item : n) v.items.push_back(item.IsScalar() ? item.Scalar() : std::string());
  } else if (n.IsScalar()) {
    v.items.push_back(n.Scalar());
  }
  return v;
}

/// The definition's parameters, ports, blocks and connections; throws on a shape it cannot read.
void read_body(const YAML::Node& body, DocSubsystem& def) {
  if (!body.IsMap()) throw engine::InputError(def.source, line_of(body), "", "a subsystem is a mapping");
  if (body["description"] && body["description"].IsScalar()) def.description = body["description"].Scalar();
  if (const YAML::Node p = body["parameters"]; p && p.IsMap())
    for (auto kv : p) {
      SceneValue v;
      if (kv.second.IsMap()) {
        if (kv.second["value"]) v = value_of(kv.second["value"]);
      } else if (!kv.second.IsNull()) {
        v = value_of(kv.second);
      }
      def.parameters.emplace_back(kv.first.Scalar(), v);
    }
  if (const YAML::Node in = body["inputs"]; in && in.IsMap())
    for (auto kv : in) def.inputs.emplace_back(kv.first.Scalar(), value_of(kv.second).items);
  if (const YAML::Node out = body["outputs"]; out && out.IsMap())
    for (auto kv : out) def.outputs.emplace_back(kv.first.Scalar(), kv.second.IsScalar() ? kv.second.Scalar() : "");
  // The inside is read as a scene of its blocks, connections and layout.
  YAML::Node inside(YAML::NodeType::Map);
  for (const char* key : {"blocks", "connections", "layout"})
    if (body[key]) inside[key] = body[key];
  const SceneDocument doc = parse_scene(YAML::Dump(inside), def.source);
  def.blocks = doc.blocks;
  def.connections = doc.connections;
}

YAML::Node value_node(const SceneValue& v) {
  if (!v.is_list && !v.is_map) return YAML::Node(v.items.empty() ? std::string() : v.items.front());
  YAML::Node n(v.is_map ? YAML::NodeType::Map : YAML::NodeType::Sequence);
  for (size_t k = 0; k < v.items.size(); ++k) {
    if (v.is_map) n[v.keys[k]] = v.items[k];
    else n.push_back(v.items[k]);
  }
  n.SetStyle(YAML::EmitterStyle::Flow);
  return n;
}

}  // namespace

void store_inside(DocSubsystem& def) {
  const YAML::Node old = def.inline_yaml.empty() ? YAML::Node(YAML::NodeType::Map) : YAML::Load(def.inline_yaml);
  // Rebuilt key by key so that the order stays that of docs/scenes.md.
  YAML::Node body(YAML::NodeType::Map);
  for (const char* key : {"description", "parameters", "inputs", "outputs", "subsystems"})
    if (old[key]) body[key] = old[key];
  YAML::Node blocks(YAML::NodeType::Map), layout(YAML::NodeType::Map);
  for (const DocBlock& b : def.blocks) {
    YAML::Node block(YAML::NodeType::Map);
    block["type"] = b.type;
    for (const auto& [key, value] : b.values) block[key] = value_node(value);
    block.SetStyle(YAML::EmitterStyle::Flow);
    blocks[b.name] = block;
    YAML::Node at(YAML::NodeType::Sequence);
    at.push_back(static_cast<long>(std::lround(b.x)));
    at.push_back(static_cast<long>(std::lround(b.y)));
    at.SetStyle(YAML::EmitterStyle::Flow);
    layout[b.name] = at;
  }
  body["blocks"] = blocks;
  if (!def.connections.empty()) {
    YAML::Node connections(YAML::NodeType::Sequence);
    for (const DocConnection& c : def.connections) connections.push_back(c.text());
    body["connections"] = connections;
  }
  body["layout"] = layout;
  def.inline_yaml = YAML::Dump(body);
}

std::vector<DocSubsystem> read_subsystems(const YAML::Node& section, const std::string& file) {
  std::vector<DocSubsystem> out;
  if (!section.IsMap())
    throw engine::InputError(file, line_of(section), "subsystems", "expected a mapping of name: {file: PATH} or a definition");
  for (auto kv : section) {
    DocSubsystem def;
    def.name = kv.first.Scalar();
    const YAML::Node& body = kv.second;
    if (body.IsMap() && body["file"] && body["file"].IsScalar()) {
      def.file = body["file"].Scalar();
      const std::filesystem::path rel(def.file);
      def.source = rel.is_absolute() ? def.file
                                     : (std::filesystem::path(file).parent_path() / rel).lexically_normal().string();
      try {
        read_body(YAML::LoadFile(def.source), def);
      } catch (const std::exception& e) {
        def.error = e.what();
      }
    } else {
      def.source = file;
      def.inline_yaml = YAML::Dump(body);
      try {
        read_body(body, def);
      } catch (const std::exception& e) {
        def.error = e.what();
      }
    }
    out.push_back(std::move(def));
  }
  return out;
}

void emit_subsystems(YAML::Emitter& e, const std::vector<DocSubsystem>& subsystems) {
  if (subsystems.empty()) return;
  e << YAML::Key << "subsystems" << YAML::Value << YAML::BeginMap;
  for (const DocSubsystem& d : subsystems) {
    e << YAML::Key << d.name << YAML::Value;
    if (!d.file.empty())
      e << YAML::Flow << YAML::BeginMap << YAML::Key << "file" << YAML::Value << d.file << YAML::EndMap;
    else
      e << YAML::Load(d.inline_yaml);
  }
  e << YAML::EndMap;
}

}  // namespace dydp::gui
