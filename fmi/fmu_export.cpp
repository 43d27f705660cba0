#include "fmi/fmu_export.hpp"

#include <chrono>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "engine/framework/errors.hpp"
#include "fmi/exposure.hpp"
#include "fmi/fmu_archive.hpp"
#include "fmi/model_description.hpp"
#include "fmi/variable_table.hpp"

namespace dydp::fmi {
namespace {

namespace fs = std::filesystem;
using engine::InputError;

/// A C identifier from the archive's name (FMI 3.0: modelIdentifier names the shared object).
std::string identifier_of(const std::string& out) {
  std::string id = fs::path(out).stem().string();
  for (char& c : id)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) c = '_';
  if (id.empty() || std::isdigit(static_cast<unsigned char>(id[0]))) id = "fmu_" + id;
  return id;
}

std::string now_iso8601() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return text;
}

}  // namespace

std::string default_runtime_library() {
  if (const char* env = std::getenv("DYDP_FMU_RUNTIME"); env && *env) return env;
  return DYDP_FMU_RUNTIME_PATH;
}

ExportSummary export_fmu(const ExportOptions& o) {
  if (o.out.empty()) throw InputError("--out", 0, "", "the FMU's file name is missing");
  if (fs::path(o.out).extension() != ".fmu") throw InputError("--out", 0, "", o.out + ": expected NAME.fmu");
  if (!o.model_exchange && !o.co_simulation) throw InputError("--kind", 0, "", "neither Model Exchange nor Co-Simulation");
  const Exposure e = read_exposure(o.source);
  // Sensitivity outputs come from the integrator inside the FMU (its states' sensitivities): in
  // Model Exchange the importer's integrator owns the states, so there are none to give.
  if (!e.sensitivities.empty() && o.model_exchange)
    throw InputError(e.spec_file, e.sensitivities_line, "sensitivities",
                     "sensitivity outputs exist in Co-Simulation only (the FMU integrates them with its states); "
                     "export with --kind cs");
  engine::Diagram d = engine::load_scene(e.scene_file);
  const VariableTable t = build_variables(d, e);

  ExportSummary summary;
  summary.model_identifier = identifier_of(o.out);
  DescriptionOptions options;
  options.model_identifier = summary.model_identifier;
  options.model_name = e.model_name;
  options.description = e.description;
  options.model_exchange = o.model_exchange;
  options.co_simulation = o.co_simulation;
  options.generation_date = now_iso8601();
  summary.model_description = model_description_xml(d, t, options);

  // The resources: the scene, every file its blocks were written in (subsystems) and every file
  // a block reads (recordings, tables), under resources/model/ at their places relative to the
  // folder that holds them all, so that the scene's relative paths hold inside the FMU. A path
  // written absolute would point outside it: refused.
  std::set<std::string> files = {fs::absolute(e.scene_file).lexically_normal().string()};
  for (const engine::Node& n : d.nodes) {
    if (!n.file.empty()) files.insert(fs::absolute(n.file).lexically_normal().string());
    if (!n.settings) continue;
    for (const std::string& key : n.settings->files_read()) {
      if (fs::path(n.settings->text(key)).is_absolute())
        n.settings->fail(key, "an FMU carries the files its scene reads: write this path relative to the scene");
      files.insert(fs::absolute(n.settings->path(key)).lexically_normal().string());
    }
  }
  fs::path root = fs::path(*files.begin()).parent_path();
  for (const std::string& f : files)
    while (fs::path(f).lexically_relative(root).string().rfind("..", 0) == 0) root = root.parent_path();
  std::vector<ArchiveEntry> entries;
  entries.push_back({"modelDescription.xml", summary.model_description, ""});
  const std::string runtime = o.runtime_library.empty() ? default_runtime_library() : o.runtime_library;
  if (!fs::exists(runtime))
    throw std::runtime_error("the FMU runtime " + runtime + " is missing (build the target dydp_fmu, or set DYDP_FMU_RUNTIME)");
  entries.push_back({"binaries/x86_64-linux/" + summary.model_identifier + ".so", "", runtime, false});
  // yaml-cpp as a shared library beside it (Debian ships no position-independent archive of
  // it); the FMU's shared object finds it there (RUNPATH $ORIGIN).
  entries.push_back({std::string("binaries/x86_64-linux/") + DYDP_FMU_BUNDLED_SONAME, "", DYDP_FMU_BUNDLED_LIBRARY, false});
  for (const std::string& f : files)
    entries.push_back({"resources/model/" + fs::path(f).lexically_relative(root).generic_string(), "", f});

  std::vector<std::string> inputs, outputs, parameters;
  for (const Variable& v : t.variables) {
    if (v.role == Role::input) inputs.push_back(v.name);
    if (v.role == Role::parameter) parameters.push_back(v.name);
  }
  if (e.default_outputs) {
    for (const Variable& v : t.variables)
      if (v.role == Role::output_signal || v.role == Role::output_objective) outputs.push_back(v.name);
  } else {
    for (const ExposedName& n : e.outputs) outputs.push_back(n.name);
  }
  // The inputs as named (a whole port stays one entry) so the FMU builds the same table.
  std::vector<std::string> input_names, sensitivity_names;
  for (const ExposedName& n : e.inputs) input_names.push_back(n.name);
  for (const ExposedName& n : e.sensitivities) sensitivity_names.push_back(n.name);
  const std::string scene_rel =
      "model/" + fs::path(fs::absolute(e.scene_file).lexically_normal()).lexically_relative(root).generic_string();
  entries.push_back({"resources/fmu.yaml", exposure_text(e, scene_rel, input_names, outputs, parameters, sensitivity_names), ""});
  write_archive(o.out, entries);

  for (const Variable& v : t.variables) {
    summary.parameters += v.role == Role::parameter;
    summary.inputs += v.role == Role::input;
    summary.outputs += v.role == Role::output_signal || v.role == Role::output_objective ||
                       v.role == Role::output_sensitivity;
  }
  summary.states = t.num_states();
  summary.event_indicators = static_cast<int>(t.breakpoints.size());
  return summary;
}

}  // namespace dydp::fmi
