#include "fmi/exposure.hpp"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <set>
#include <sstream>

#include "engine/framework/errors.hpp"

namespace dydp::fmi {
namespace {

using engine::InputError;

int line_of(const YAML::Node& n) { return n.Mark().line >= 0 ? n.Mark().line + 1 : 0; }

std::vector<ExposedName> read_list(const YAML::Node& root, const std::string& key, const std::string& file) {
  const YAML::Node list = root[key];
  if (!list.IsSequence()) throw InputError(file, line_of(list), key, "expected a list of names");
  std::vector<ExposedName> out;
  std::set<std::string> seen;
  for (const YAML::Node& item : list) {
    if (!item.IsScalar() || item.Scalar().empty())
      throw InputError(file, line_of(item), key, "expected a name");
    if (!seen.insert(item.Scalar()).second)
      throw InputError(file, line_of(item), key, item.Scalar() + " is listed twice");
    out.push_back({item.Scalar(), line_of(item)});
  }
  return out;
}

}  // namespace

Exposure read_exposure(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw InputError(path, 0, "", "cannot read the file");
  } catch (const YAML::Exception& e) {
    throw InputError(path, e.mark.line + 1, "", e.msg);
  }
  if (!root.IsMap()) throw InputError(path, 1, "", "expected a scene (scene:) or an FMU description (fmu:)");
  Exposure e;
  e.spec_file = path;
  if (root["description"] && root["description"].IsScalar()) e.description = root["description"].Scalar();
  if (!root["fmu"]) {
    if (!root["scene"] || !root["scene"].IsScalar())
      throw InputError(path, 1, "scene", root["subsystem"] ? "a subsystem file: export it through a scene that uses it "
                                                             "(an FMU description, docs/fmi.md)"
                                                           : "expected a scene (scene:) or an FMU description (fmu:)");
    e.model_name = root["scene"].Scalar();
    e.scene_file = path;
    return e;
  }
  static const std::set<std::string> keys = {"fmu", "description", "scene", "inputs", "outputs", "parameters",
                                           "sensitivities"};
  for (const auto& kv : root) {
    const std::string key = kv.first.as<std::string>();
    if (!keys.count(key))
      throw InputError(path, line_of(kv.first), key,
                       "unknown key of an FMU description (fmu, description, scene, inputs, outputs, parameters, "
                       "sensitivities)");
  }
  if (!root["fmu"].IsScalar() || root["fmu"].Scalar().empty())
    throw InputError(path, line_of(root["fmu"]), "fmu", "expected the FMU's name");
  e.model_name = root["fmu"].Scalar();
  if (!root["scene"] || !root["scene"].IsScalar())
    throw InputError(path, line_of(root["fmu"]), "scene", "expected the path of the scene, relative to this file");
  e.scene_file = (std::filesystem::path(path).parent_path() / root["scene"].Scalar()).lexically_normal().string();
  if (!std::filesystem::exists(e.scene_file))
    throw InputError(path, line_of(root["scene"]), "scene", "no file " + e.scene_file);
  if (root["inputs"]) e.inputs = read_list(root, "inputs", path);
  if (root["outputs"]) e.outputs = read_list(root, "outputs", path), e.default_outputs = false;
  if (root["parameters"]) e.parameters = read_list(root, "parameters", path), e.default_parameters = false;
  if (root["sensitivities"]) {
    e.sensitivities = read_list(root, "sensitivities", path);
    for (const auto& kv : root)
      if (kv.first.as<std::string>() == "sensitivities") e.sensitivities_line = line_of(kv.first);
  }
  return e;
}

std::string exposure_text(const Exposure& e, const std::string& scene_name, const std::vector<std::string>& inputs,
                          const std::vector<std::string>& outputs, const std::vector<std::string>& parameters,
                          const std::vector<std::string>& sensitivities) {
  YAML::Emitter out;
  out << YAML::BeginMap << YAML::Key << "fmu" << YAML::Value << e.model_name;
  if (!e.description.empty()) out << YAML::Key << "description" << YAML::Value << e.description;
  out << YAML::Key << "scene" << YAML::Value << scene_name;
  out << YAML::Key << "inputs" << YAML::Value << YAML::Flow << inputs;
  out << YAML::Key << "outputs" << YAML::Value << YAML::Flow << outputs;
  out << YAML::Key << "parameters" << YAML::Value << YAML::Flow << parameters;
  if (!sensitivities.empty()) out << YAML::Key << "sensitivities" << YAML::Value << YAML::Flow << sensitivities;
  out << YAML::EndMap;
  return std::string("# What this FMU exposes (written by dydp fmu; docs/fmi.md).\n") + out.c_str() + "\n";
}

}  // namespace dydp::fmi
