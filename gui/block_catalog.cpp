#include "gui/block_catalog.hpp"

#include <algorithm>
#include <map>

#include "engine/framework/errors.hpp"
#include "engine/framework/objective.hpp"

namespace dydp::gui {

BlockPorts ports_of(const engine::BlockType& type, const DocBlock& block) {
  BlockPorts out;
  engine::BlockSettings settings(block.name, "", 0);
  for (const engine::SettingSpec& s : type.settings) {
    if (const SceneValue* v = block.find(s.name)) {
      settings.set(s.name, {v->items, v->is_list, 0, {}});
    } else if (s.required) {
      out.error = "setting '" + s.name + "' is required (" + s.description + ")";
      return out;
    } else {
      settings.set(s.name, {{s.default_value}, false, 0, {}});
    }
  }
  try {
    const auto instance = type.make(settings);
    out.inputs = instance->inputs();
    out.outputs = instance->outputs();
    out.is_objective = dynamic_cast<const engine::Objective*>(instance.get()) != nullptr;
  } catch (const engine::InputError& e) {
    // The message carries "file:line: field: reason" with an empty file; keep the reason only.
    const std::string what = e.what();
    const auto at = what.find(e.field() + ": ");
    out.error = at == std::string::npos ? what : what.substr(at);
  } catch (const std::exception& e) {
    out.error = e.what();
  }
  return out;
}

std::string section_of_group(const std::string& group) {
  static const std::map<std::string, std::string> sections = {
      {"sources", "sources"},       {"source", "sources"},
      {"vehicle", "vehicle"},       {"multibody", "vehicle"},       {"mechanics", "vehicle"},
      {"suspension", "vehicle"},    {"chassis", "vehicle"},         {"steering", "vehicle"},
      {"tyres", "tyres and roads"}, {"tires", "tyres and roads"},   {"tyre", "tyres and roads"},
      {"roads", "tyres and roads"}, {"road", "tyres and roads"},
      {"tyres and roads", "tyres and roads"},
      {"hydraulics", "hydraulics"}, {"hydraulic", "hydraulics"},   {"dampers", "hydraulics"},
      {"objectives", "objectives"}, {"objective", "objectives"},
      {"math", "math"},
  };
  const auto it = sections.find(group);
  return it == sections.end() ? group : it->second;
}

std::vector<PaletteSection> palette_sections() {
  std::vector<PaletteSection> out;
  for (const char* title : {"sources", "vehicle", "tyres and roads", "hydraulics", "objectives", "math"})
    out.push_back({title, {}});
  for (const engine::BlockType* t : engine::Registry::global().all()) {
    const std::string title = section_of_group(t->group);
    auto it = std::find_if(out.begin(), out.end(), [&](const PaletteSection& s) { return s.title == title; });
    if (it == out.end()) {
      out.push_back({title, {}});
      it = out.end() - 1;
    }
    it->types.push_back(t);
  }
  for (auto& s : out)
    std::sort(s.types.begin(), s.types.end(), [](auto* a, auto* b) { return a->name < b->name; });
  out.erase(std::remove_if(out.begin(), out.end(), [](const PaletteSection& s) { return s.types.empty(); }),
            out.end());
  return out;
}

std::string name_stem(const std::string& type) {
  const auto dot = type.rfind('.');
  std::string stem = dot == std::string::npos ? type : type.substr(dot + 1);
  if (stem.empty()) stem = "block";
  return stem;
}

int parameter_index(const engine::BlockType& type, const std::string& key) {
  for (size_t i = 0; i < type.parameters.size(); ++i)
    if (type.parameters[i].name == key) return static_cast<int>(i);
  return -1;
}

int setting_index(const engine::BlockType& type, const std::string& key) {
  for (size_t i = 0; i < type.settings.size(); ++i)
    if (type.settings[i].name == key) return static_cast<int>(i);
  return -1;
}

}  // namespace dydp::gui
