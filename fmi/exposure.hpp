// What an FMU exposes (docs/fmi.md): its scene, and the scene's signals driven from outside
// (inputs), the signals and objectives it gives (outputs), the scene parameters it lets the
// importer tune. Read from a scene (its logged outputs, objectives and parameters) or from an
// FMU description file that names a scene and lists them (`fmu:` at its top level).
#pragma once

#include <string>
#include <vector>

namespace dydp::fmi {

/// A name as written in the description file, with where it was written.
struct ExposedName {
  std::string name;
  int line = 0;
};

struct Exposure {
  std::string model_name;       ///< the FMU's modelName: `fmu:` or the scene's `scene:`
  std::string description;      ///< `description:` of the file, if any
  std::string scene_file;       ///< the scene, as a path
  std::string spec_file;        ///< the file the lists were read from (the scene itself by default)
  bool default_outputs = true;  ///< outputs: the scene's logged signals and requested objectives
  bool default_parameters = true;  ///< parameters: every scene parameter
  std::vector<ExposedName> inputs;      ///< signals (BLOCK.PORT or BLOCK.PORT[i]) the importer sets
  std::vector<ExposedName> outputs;     ///< signals or objective block names
  std::vector<ExposedName> parameters;  ///< scene parameter names
  /// Sensitivity directions (scene parameters or declared directions): each output gets its
  /// derivative along each as an output of its own, in Co-Simulation only.
  std::vector<ExposedName> sensitivities;
  int sensitivities_line = 0;  ///< of `sensitivities:` (0: not written)
};

/// Reads `path`: a scene (top-level `scene:`) or an FMU description (top-level `fmu:`, with
/// `scene:` a path relative to it, and optional `inputs:`, `outputs:`, `parameters:`,
/// `sensitivities:` lists, `description:`). Throws engine::InputError naming file, line and field.
Exposure read_exposure(const std::string& path);

/// The description file of an exposure whose lists are written out (the FMU's
/// resources/fmu.yaml): `scene_name` is the scene's path relative to it.
std::string exposure_text(const Exposure& e, const std::string& scene_name,
                          const std::vector<std::string>& inputs, const std::vector<std::string>& outputs,
                          const std::vector<std::string>& parameters, const std::vector<std::string>& sensitivities);

}  // namespace dydp::fmi
