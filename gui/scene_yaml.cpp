// Scene documents to and from YAML (docs/scenes.md). Reading keeps every value's text; writing
// emits the documented shape (flow mappings for time, solver, parameters and blocks) plus the
// `layout:` section the engine ignores.
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "engine/framework/errors.hpp"
#include "gui/scene_document.hpp"
#include "gui/subsystem_yaml.hpp"
#include "io/files.hpp"

namespace dydp::gui {
namespace {

using engine::InputError;

int line_of(const YAML::Node& n) { return n.Mark().is_null() ? 0 : n.Mark().line + 1; }

class Reader {
 public:
  explicit Reader(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const YAML::Node& at, const std::string& field, const std::string& msg) const {
    throw InputError(file_, line_of(at), field, msg);
  }
  std::string scalar(const YAML::Node& n, const std::string& field) const {
    if (!n.IsScalar()) fail(n, field, "expected a single value");
    return n.Scalar();
  }
  SceneValue value(const YAML::Node& n, const std::string& field) const {
    if (n.IsMap()) {
      SceneValue v;
      v.is_map = true;
      for (auto kv : n) {
        v.keys.push_back(scalar(kv.first, field));
        v.items.push_back(scalar(kv.second, field + "." + kv.first.Scalar()));
      }
      return v;
    }
    if (n.IsSequence()) {
      SceneValue v;
      v.is_list = true;
      for (auto item : n) v.items.push_back(scalar(item, field));
      return v;
    }
    return SceneValue::scalar(scalar(n, field));
  }
  Fields fields(const YAML::Node& n, const std::string& field) const {
    if (!n.IsMap()) fail(n, field, "expected a mapping");
    Fields f;
    for (auto kv : n) f.emplace_back(kv.first.Scalar(), scalar(kv.second, field + "." + kv.first.Scalar()));
    return f;
  }
  std::vector<std::string> list(const YAML::Node& n, const std::string& field) const {
    if (!n.IsSequence()) fail(n, field, "expected a list");
    std::vector<std::string> out;
    for (auto item : n) out.push_back(scalar(item, field));
    return out;
  }

 private:
  std::string file_;
};

DocParameter read_parameter(const Reader& r, const std::string& name, const YAML::Node& body) {
  DocParameter p;
  p.name = name;
  const std::string field = "parameters." + name;
  if (body.IsScalar()) {
    p.value = body.Scalar();
    return p;
  }
  if (!body.IsMap()) r.fail(body, field, "expected {value, unit, range}");
  for (auto kv : body) {
    const std::string key = kv.first.Scalar();
    if (key == "value") {
      p.value = r.scalar(kv.second, field + ".value");
    } else if (key == "unit") {
      p.unit = r.scalar(kv.second, field + ".unit");
    } else if (key == "description") {
      p.description = r.scalar(kv.second, field + ".description");
    } else if (key == "range") {
      const auto range = r.list(kv.second, field + ".range");
      if (range.size() != 2) r.fail(kv.second, field + ".range", "expected [low, high]");
      p.low = range[0];
      p.high = range[1];
    } else {
      r.fail(kv.first, field + "." + key, "unknown key");
    }
  }
  return p;
}

DocBlock read_block(const Reader& r, const std::string& name, const YAML::Node& body) {
  DocBlock b;
  b.name = name;
  if (!body.IsMap()) r.fail(body, name, "expected a mapping with a type");
  for (auto kv : body) {
    const std::string key = kv.first.Scalar();
    if (key == "type") b.type = r.scalar(kv.second, name + ".type");
    else b.values.emplace_back(key, r.value(kv.second, name + "." + key));
  }
  if (b.type.empty()) r.fail(body, name + ".type", "missing block type");
  return b;
}

void read_layout(const Reader& r, const YAML::Node& n, SceneDocument& doc) {
  if (!n.IsMap()) r.fail(n, "layout", "expected a mapping of block: [x, y]");
  for (auto kv : n) {
    DocBlock* b = doc.find_block(kv.first.Scalar());
    if (!b) continue;  // a stale position: the engine ignores layout, so do we
    const auto xy = r.list(kv.second, "layout." + b->name);
    if (xy.size() != 2) r.fail(kv.second, "layout." + b->name, "expected [x, y]");
    try {
      b->x = std::stod(xy[0]);
      b->y = std::stod(xy[1]);
      b->placed = true;
    } catch (const std::exception&) {
      r.fail(kv.second, "layout." + b->name, "expected numbers");
    }
  }
}

std::string leading_comment(const std::string& text) {
  std::istringstream in(text);
  std::string line, out;
  while (std::getline(in, line) && !line.empty() && line[0] == '#') out += line + "\n";
  return out;
}

// Emits a scalar as written; text that YAML would read as something else is quoted by yaml-cpp.
void emit_value(YAML::Emitter& e, const SceneValue& v) {
  if (v.is_map) {
    e << YAML::Flow << YAML::BeginMap;
    for (size_t i = 0; i < v.items.size(); ++i) e << YAML::Key << v.keys[i] << YAML::Value << v.items[i];
    e << YAML::EndMap;
    return;
  }
  if (!v.is_list) {
    e << (v.items.empty() ? std::string() : v.items.front());
    return;
  }
  e << YAML::Flow << YAML::BeginSeq;
  for (const auto& item : v.items) e << item;
  e << YAML::EndSeq;
}

void emit_fields(YAML::Emitter& e, const char* key, const Fields& f) {
  if (f.empty()) return;
  e << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginMap;
  for (const auto& [k, v] : f) e << YAML::Key << k << YAML::Value << v;
  e << YAML::EndMap;
}

std::string position_text(double v) {
  std::ostringstream s;
  s << std::lround(v);
  return s.str();
}

}  // namespace

SceneDocument parse_scene(const std::string& text, const std::string& file) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw InputError(file, e.mark.line + 1, "", "YAML syntax: " + e.msg);
  }
  if (!root.IsMap()) throw InputError(file, 1, "", "a scene is a YAML mapping");
  const Reader r(file);
  SceneDocument doc;
  doc.header_comment = leading_comment(text);
  YAML::Node layout;
  bool has_layout = false;
  for (auto kv : root) {
    const std::string key = kv.first.Scalar();
    const YAML::Node& v = kv.second;
    if (key == "scene") {
      doc.scene = r.scalar(v, key);
    } else if (key == "description") {
      doc.description = r.scalar(v, key);
    } else if (key == "time") {
      doc.time = r.fields(v, key);
    } else if (key == "solver") {
      doc.solver = r.fields(v, key);
    } else if (key == "initial") {
      YAML::Emitter text;  // on one line, as the Scene tab shows and edits it
      text << YAML::Flow << v;
      doc.initial = text.c_str();
    } else if (key == "parameters") {
      if (!v.IsMap()) r.fail(v, key, "expected a mapping");
      for (auto p : v) doc.parameters.push_back(read_parameter(r, p.first.Scalar(), p.second));
    } else if (key == "sensitivities") {
      doc.sensitivities = r.list(v, key);
    } else if (key == "directions") {
      if (!v.IsSequence()) r.fail(v, key, "expected a list of block parameters or groups");
      YAML::Emitter text;
      text << v;
      doc.directions = text.c_str();
    } else if (key == "subsystems") {
      doc.subsystems = read_subsystems(v, file);
    } else if (key == "blocks") {
      if (!v.IsMap()) r.fail(v, key, "expected a mapping of blocks");
      for (auto b : v) {
        if (doc.find_block(b.first.Scalar())) r.fail(b.first, b.first.Scalar(), "block defined twice");
        doc.blocks.push_back(read_block(r, b.first.Scalar(), b.second));
      }
    } else if (key == "connections") {
      if (!v.IsSequence()) r.fail(v, key, "expected a list of 'block.port -> block.port'");
      for (auto item : v) {
        const std::string c = r.scalar(item, key);
        const auto arrow = c.find("->");
        DocConnection conn;
        if (arrow == std::string::npos || !PortRef::parse(c.substr(0, arrow), conn.from) ||
            !PortRef::parse(c.substr(arrow + 2), conn.to))
          r.fail(item, key, "expected 'block.port -> block.port', got '" + c + "'");
        doc.connections.push_back(conn);
      }
    } else if (key == "outputs") {
      doc.outputs = r.list(v, key);
    } else if (key == "layout") {
      layout = v;
      has_layout = true;
    } else {
      r.fail(kv.first, key, "unknown key");
    }
  }
  if (has_layout) read_layout(r, layout, doc);
  return doc;
}

SceneDocument read_scene_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, "", "cannot open the scene file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_scene(text.str(), path);
}

std::string write_scene(const SceneDocument& doc) {
  YAML::Emitter e;
  e.SetIndent(2);
  e << YAML::BeginMap;
  if (!doc.scene.empty()) e << YAML::Key << "scene" << YAML::Value << doc.scene;
  if (!doc.description.empty()) e << YAML::Key << "description" << YAML::Value << doc.description;
  emit_fields(e, "time", doc.time);
  emit_fields(e, "solver", doc.solver);
  if (!doc.initial.empty()) e << YAML::Key << "initial" << YAML::Value << YAML::Load(doc.initial);
  if (!doc.parameters.empty()) {
    e << YAML::Key << "parameters" << YAML::Value << YAML::BeginMap;
    for (const DocParameter& p : doc.parameters) {
      e << YAML::Key << p.name << YAML::Value << YAML::Flow << YAML::BeginMap;
      e << YAML::Key << "value" << YAML::Value << p.value;
      if (!p.unit.empty()) e << YAML::Key << "unit" << YAML::Value << p.unit;
      if (!p.low.empty() || !p.high.empty())
        e << YAML::Key << "range" << YAML::Value << YAML::Flow << YAML::BeginSeq << p.low << p.high
          << YAML::EndSeq;
      if (!p.description.empty()) e << YAML::Key << "description" << YAML::Value << p.description;
      e << YAML::EndMap;
    }
    e << YAML::EndMap;
  }
  if (!doc.directions.empty()) e << YAML::Key << "directions" << YAML::Value << YAML::Load(doc.directions);
  if (!doc.sensitivities.empty())
    e << YAML::Key << "sensitivities" << YAML::Value << YAML::Flow << doc.sensitivities;
  emit_subsystems(e, doc.subsystems);
  e << YAML::Key << "blocks" << YAML::Value << YAML::BeginMap;
  for (const DocBlock& b : doc.blocks) {
    e << YAML::Key << b.name << YAML::Value << YAML::Flow << YAML::BeginMap;
    e << YAML::Key << "type" << YAML::Value << b.type;
    for (const auto& [k, v] : b.values) {
      e << YAML::Key << k << YAML::Value;
      emit_value(e, v);
    }
    e << YAML::EndMap;
  }
  e << YAML::EndMap;
  if (!doc.connections.empty()) {
    e << YAML::Key << "connections" << YAML::Value << YAML::BeginSeq;
    for (const DocConnection& c : doc.connections) e << c.text();
    e << YAML::EndSeq;
  }
  e << YAML::Key << "outputs" << YAML::Value << YAML::Flow << doc.outputs;
  e << YAML::Key << "layout" << YAML::Value << YAML::BeginMap;
  for (const DocBlock& b : doc.blocks)
    e << YAML::Key << b.name << YAML::Value << YAML::Flow << YAML::BeginSeq << position_text(b.x)
      << position_text(b.y) << YAML::EndSeq;
  e << YAML::EndMap;
  e << YAML::EndMap;
  std::string out = doc.header_comment;
  out += e.c_str();
  out += "\n";
  return out;
}

void write_scene_file(const SceneDocument& doc, const std::string& path) {
  io::write_file_atomically(path, write_scene(doc));
}

}  // namespace dydp::gui
