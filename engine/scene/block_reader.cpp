#include "engine/scene/block_reader.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <set>

#include "engine/framework/errors.hpp"
#include "engine/scene/consistency_checks.hpp"
#include "engine/scene/nominal_overrides.hpp"
#include "engine/scene/subsystem_definition.hpp"

namespace dydp::engine {
namespace {

int line_of(const YAML::Node& n) { return n.Mark().is_null() ? 0 : n.Mark().line + 1; }

/// A number, not zero as written, so small that it is denormal or zero as a double (1e-320).
bool underflows(const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && std::fabs(v) < std::numeric_limits<double>::min() &&
         text.find_first_of("123456789") < text.find_first_of("eE");
}

std::string scalar(const YAML::Node& n, const std::string& file, const std::string& field) {
  if (!n.IsScalar()) throw InputError(file, line_of(n), field, "expected a single value");
  return n.Scalar();
}

/// A numeric block parameter's value: the number, the scene parameter driving it (or -1), and
/// where the value was written.
struct ParameterValue {
  double value = 0;
  int scene = -1;
  std::string file;
  int line = 0;
};

ParameterValue parameter_value(const Scope& scope, const YAML::Node& v, const Diagram& d,
                               const std::string& field) {
  ParameterValue out{0, -1, scope.file, line_of(v)};
  const std::string text = scalar(v, scope.file, field);
  if (text.empty() || text[0] != '$') {
    out.value = scene_number(text, scope.file, out.line, field);
    return out;
  }
  if (!scope.definition) {
    out.scene = d.find_parameter(text.substr(1));
    if (out.scene < 0) throw InputError(scope.file, out.line, field, "unknown scene parameter '" + text + "'");
    out.value = d.parameters[out.scene].value;
    return out;
  }
  const Binding& b = find_binding(scope, v, field, text.substr(1));
  out.file = b.file;
  out.line = b.line;
  if (b.is_list)
    throw InputError(b.file, b.line, b.field, "a list, but " + field + " (" + place(scope.file, line_of(v)) +
                                                  ") takes a number");
  if (b.scene >= 0) {
    out.scene = b.scene;
    out.value = d.parameters[b.scene].value;
    return out;
  }
  out.value = scene_number(b.items.front(), b.file, b.line, b.field);
  return out;
}

/// A setting's value; inside a subsystem a `$name` (the whole value or one item of a list)
/// takes the instance's value for that parameter.
BlockSettings::Value setting_value(const Scope& scope, const YAML::Node& v, const Diagram& d,
                                   const std::string& field) {
  BlockSettings::Value out;
  out.line = line_of(v);
  const auto substitute = [&](const YAML::Node& item, bool whole) {
    const std::string text = scalar(item, scope.file, field);
    if (!scope.definition || text.empty() || text[0] != '$') return out.items.push_back(text);
    const Binding& b = find_binding(scope, item, field, text.substr(1));
    if (b.scene >= 0)
      throw InputError(b.file, b.line, b.field,
                       "bound to scene parameter '$" + d.parameters[b.scene].name + "', but " + field + " (" +
                           place(scope.file, line_of(item)) + ") is a setting: it takes a plain value");
    if (b.is_list && !whole)
      throw InputError(b.file, b.line, b.field, "a list, but it is one item of " + field + " (" +
                                                    place(scope.file, line_of(item)) + ")");
    out.items.insert(out.items.end(), b.items.begin(), b.items.end());
    out.is_list = out.is_list || b.is_list;
    out.line = b.line;
    out.file = b.file;
  };
  if (v.IsSequence()) {
    out.is_list = true;
    for (auto item : v) substitute(item, false);
  } else {
    substitute(v, true);
  }
  return out;
}

}  // namespace

double scene_number(const std::string& text, const std::string& file, int line, const std::string& field) {
  double v = 0;
  if (!parse_number(text, v)) {
    if (underflows(text))
      throw InputError(file, line, field,
                       "value " + text + " underflows (denormal or zero as a double, below " +
                           format_number(std::numeric_limits<double>::min()) + ")");
    throw InputError(file, line, field, "malformed number '" + text + "'");
  }
  return v;
}

std::string place(const std::string& file, int line) {
  return line > 0 ? file + ":" + std::to_string(line) : file;
}

const Binding& find_binding(const Scope& scope, const YAML::Node& at, const std::string& field,
                            const std::string& name) {
  const auto it = scope.bindings.find(name);
  if (it == scope.bindings.end())
    throw InputError(scope.file, line_of(at), field,
                     "unknown parameter '$" + name + "' of subsystem " + scope.definition->name +
                         " (parameters:" + scope.definition->parameter_names() + ")");
  return it->second;
}

Node read_block(const Scope& scope, const YAML::Node& key, const YAML::Node& body, const Diagram& d,
                const std::vector<std::pair<std::string, std::string>>& forced,
                std::vector<std::string>& warnings) {
  const std::string& file = scope.file;
  const std::string local = key.Scalar();
  Node node;
  node.name = scope.prefix + local;
  node.file = file;
  node.line = line_of(key);
  const auto fail = [&](const YAML::Node& at, const std::string& field, const std::string& message) {
    throw InputError(file, line_of(at), field, message);
  };
  if (!body.IsMap() || !body["type"]) fail(key, node.name + ".type", "missing block type");
  const std::string type_name = scalar(body["type"], file, node.name + ".type");
  node.type = Registry::global().find(type_name);
  if (!node.type) fail(body["type"], node.name + ".type", "unknown block type '" + type_name + "'");
  const BlockType& type = *node.type;

  BlockSettings settings(node.name, file, node.line);
  for (auto kv : body) {
    const std::string k = kv.first.Scalar();
    const std::string field = node.name + "." + k;
    if (k == "type" || k == "nominal") continue;
    auto ps = std::find_if(type.parameters.begin(), type.parameters.end(),
                           [&](const ParamSpec& s) { return s.name == k; });
    auto ss = std::find_if(type.settings.begin(), type.settings.end(),
                           [&](const SettingSpec& s) { return s.name == k; });
    if (ps == type.parameters.end() && ss == type.settings.end()) {
      std::string known;
      for (const auto& s : type.parameters) known += " " + s.name;
      for (const auto& s : type.settings) known += " " + s.name;
      fail(kv.first, field, "unknown parameter of " + type_name + " (known:" + known + ")");
    }
    if (ss != type.settings.end()) {
      BlockSettings::Value v = setting_value(scope, kv.second, d, field);
      if (v.file.empty()) v.line = line_of(kv.first);
      settings.set(k, std::move(v));
    }
  }
  // Not a structured binding: clang 14 (the fuzz build) cannot capture one in the lambda.
  for (const auto& setting : forced)
    if (std::any_of(type.settings.begin(), type.settings.end(),
                    [&](const SettingSpec& s) { return s.name == setting.first; }))
      settings.set(setting.first, {{setting.second}, false, node.line, {}});
  for (const SettingSpec& s : type.settings) {
    if (settings.has(s.name)) continue;
    if (s.required) fail(key, node.name + "." + s.name, "required setting is missing");
    settings.set(s.name, {{s.default_value}, false, node.line, {}});
  }

  for (const ParamSpec& s : type.parameters) {
    const std::string field = node.name + "." + s.name;
    const YAML::Node v = body[s.name];
    ParameterValue pv{s.default_value, -1, file, 0};
    if (v) {
      pv = parameter_value(scope, v, d, field);
    } else if (s.required) {
      fail(key, field, "required parameter is missing");
    }
    if (pv.value < s.lower || pv.value > s.upper)
      throw InputError(pv.line > 0 ? pv.file : file, pv.line > 0 ? pv.line : node.line, field,
                       "value " + format_number(pv.value) + " outside [" + format_number(s.lower) + ", " +
                           format_number(s.upper) + "]" + (s.unit.empty() ? "" : " " + s.unit));
    node.p.push_back(pv.value);
    node.p_scene.push_back(pv.scene);
    node.p_line.push_back(pv.line);
    node.p_file.push_back(pv.file == file ? std::string() : pv.file);
  }
  node.block = type.make(settings);
  node.state_nominal = body["nominal"] ? read_nominal_overrides(file, node.name, body["nominal"], *node.block)
                                       : node.block->state_nominals();
  node.objective = dynamic_cast<const Objective*>(node.block.get());
  node.settings = std::make_shared<const BlockSettings>(std::move(settings));
  check_block(file, node, node.p, d.time, &warnings);
  return node;
}

}  // namespace dydp::engine
