#include "gui/scene_document.hpp"

#include <algorithm>

namespace dydp::gui {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  const auto e = s.find_last_not_of(" \t\r\n");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

}  // namespace

SceneValue SceneValue::parse(const std::string& text) {
  const std::string t = trim(text);
  const bool list = t.size() >= 2 && t.front() == '[' && t.back() == ']';
  const bool map = t.size() >= 2 && t.front() == '{' && t.back() == '}';
  if (!list && !map) return scalar(t);
  SceneValue v;
  v.is_list = list;
  v.is_map = map;
  const std::string inner = t.substr(1, t.size() - 2);
  if (trim(inner).empty()) return v;
  size_t start = 0;
  while (true) {
    const size_t comma = inner.find(',', start);
    const std::string item = trim(inner.substr(start, comma - start));
    if (map) {
      // "name: value"; an entry without a colon keeps its text as the name (the engine refuses it)
      const size_t colon = item.find(':');
      v.keys.push_back(trim(item.substr(0, colon)));
      v.items.push_back(colon == std::string::npos ? "" : trim(item.substr(colon + 1)));
    } else {
      v.items.push_back(item);
    }
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return v;
}

std::string SceneValue::text() const {
  if (is_map) {
    std::string s = "{";
    for (size_t i = 0; i < items.size(); ++i) s += (i ? ", " : "") + keys[i] + ": " + items[i];
    return s + "}";
  }
  if (!is_list) return items.empty() ? "" : items.front();
  std::string s = "[";
  for (size_t i = 0; i < items.size(); ++i) s += (i ? ", " : "") + items[i];
  return s + "]";
}

const std::string* find_field(const Fields& f, const std::string& key) {
  for (const auto& [k, v] : f)
    if (k == key) return &v;
  return nullptr;
}

void set_field(Fields& f, const std::string& key, const std::string& text) {
  auto it = std::find_if(f.begin(), f.end(), [&](const auto& kv) { return kv.first == key; });
  if (text.empty()) {
    if (it != f.end()) f.erase(it);
  } else if (it != f.end()) {
    it->second = text;
  } else {
    f.emplace_back(key, text);
  }
}

const SceneValue* DocBlock::find(const std::string& key) const {
  for (const auto& [k, v] : values)
    if (k == key) return &v;
  return nullptr;
}

void DocBlock::set(const std::string& key, const SceneValue& v) {
  auto it = std::find_if(values.begin(), values.end(), [&](const auto& kv) { return kv.first == key; });
  const bool erase = !v.is_list && !v.is_map && (v.items.empty() || v.items.front().empty());
  if (erase) {
    if (it != values.end()) values.erase(it);
  } else if (it != values.end()) {
    it->second = v;
  } else {
    values.emplace_back(key, v);
  }
}

bool PortRef::parse(const std::string& text, PortRef& out) {
  const std::string t = trim(text);
  const auto dot = t.find('.');
  if (dot == std::string::npos) return false;
  out.block = t.substr(0, dot);
  out.port = t.substr(dot + 1);
  return true;
}

DocBlock* DocSubsystem::find_block(const std::string& n) {
  for (auto& b : blocks)
    if (b.name == n) return &b;
  return nullptr;
}

const DocBlock* DocSubsystem::find_block(const std::string& name) const {
  for (const DocBlock& b : blocks)
    if (b.name == name) return &b;
  return nullptr;
}

const DocSubsystem* SceneDocument::find_subsystem(const std::string& name) const {
  for (const DocSubsystem& d : subsystems)
    if (d.name == name) return &d;
  return nullptr;
}

const DocSubsystem* SceneDocument::subsystem_of(const DocBlock& block) const {
  const std::string prefix = kSubsystemTypePrefix;
  if (block.type.rfind(prefix, 0) != 0) return nullptr;
  return find_subsystem(block.type.substr(prefix.size()));
}

DocBlock* SceneDocument::find_block(const std::string& name) {
  for (auto& b : blocks)
    if (b.name == name) return &b;
  return nullptr;
}

const DocBlock* SceneDocument::find_block(const std::string& name) const {
  return const_cast<SceneDocument*>(this)->find_block(name);
}

DocParameter* SceneDocument::find_parameter(const std::string& name) {
  for (auto& p : parameters)
    if (p.name == name) return &p;
  return nullptr;
}

const DocParameter* SceneDocument::find_parameter(const std::string& name) const {
  return const_cast<SceneDocument*>(this)->find_parameter(name);
}

const DocConnection* SceneDocument::driver_of(const PortRef& to) const {
  for (const auto& c : connections)
    if (c.to == to) return &c;
  return nullptr;
}

std::string SceneDocument::unique_block_name(const std::string& stem) const {
  if (!find_block(stem)) return stem;
  for (int i = 2;; ++i) {
    const std::string name = stem + std::to_string(i);
    if (!find_block(name)) return name;
  }
}

}  // namespace dydp::gui

namespace dydp::gui {

std::string SceneDocument::unique_parameter_name(const std::string& stem) const {
  if (!find_parameter(stem)) return stem;
  for (int i = 2;; ++i) {
    const std::string name = stem + std::to_string(i);
    if (!find_parameter(name)) return name;
  }
}

}  // namespace dydp::gui
