// `dydp fmu`: a scene, or an FMU description naming a scene and what it exposes, made into an
// FMI 3.0 FMU archive: modelDescription.xml, binaries/x86_64-linux/ID.so (the FMU runtime,
// fmi3_functions.cpp, with dydp linked in), and the scene with the subsystem files it uses
// under resources/.
#pragma once

#include <string>

namespace dydp::fmi {

struct ExportOptions {
  std::string source;  ///< a scene or an FMU description (exposure.hpp)
  std::string out;     ///< NAME.fmu
  bool model_exchange = true;
  bool co_simulation = true;
  std::string runtime_library;  ///< the FMU runtime's shared object; empty: default_runtime_library()
};

struct ExportSummary {
  std::string model_identifier;
  int parameters = 0, inputs = 0, outputs = 0, states = 0, event_indicators = 0;
  std::string model_description;  ///< the XML written
};

/// Writes the FMU. Throws engine::InputError for bad input (scene, description, names, options),
/// std::runtime_error when a file cannot be written; nothing is left at `out` then.
ExportSummary export_fmu(const ExportOptions& options);

/// The FMU runtime's shared object: $DYDP_FMU_RUNTIME, else the one built with this program.
std::string default_runtime_library();

}  // namespace dydp::fmi
