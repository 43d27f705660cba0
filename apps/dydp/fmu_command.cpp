// dydp fmu: a scene, a subsystem's scene or a single block's scene as an FMI 3.0 FMU
// (docs/fmi.md), with Model Exchange, Co-Simulation or both.
#include <unistd.h>

#include <filesystem>
#include <iostream>

#include "apps/dydp/commands.hpp"
#include "engine/framework/errors.hpp"
#include "fmi/fmu_export.hpp"

namespace dydp::apps {

int fmu_command(const FmuArgs& args) {
  namespace fs = std::filesystem;
  const fs::path out(args.out);
  if (out.extension() != ".fmu") throw engine::InputError("--out", 0, "", args.out + ": expected NAME.fmu");
  const fs::path folder = out.parent_path().empty() ? fs::path(".") : out.parent_path();
  if (!fs::is_directory(folder))
    throw engine::InputError("--out", 0, "", args.out + ": no folder " + folder.string());
  if (::access(folder.c_str(), W_OK) != 0)
    throw engine::InputError("--out", 0, "", args.out + ": the folder " + folder.string() + " is not writable");
  if (fs::is_directory(out)) throw engine::InputError("--out", 0, "", args.out + " is a folder");
  fmi::ExportOptions o;
  o.source = args.scene;
  o.out = args.out;
  o.model_exchange = args.kind != "cs";
  o.co_simulation = args.kind != "me";
  const fmi::ExportSummary s = fmi::export_fmu(o);
  std::cout << "wrote " << args.out << " (FMI 3.0, " << (args.kind == "both" ? "Model Exchange and Co-Simulation"
                                                          : args.kind == "me" ? "Model Exchange" : "Co-Simulation")
            << "; model identifier " << s.model_identifier << "): " << s.inputs << " inputs, " << s.outputs
            << " outputs, " << s.parameters << " parameters, " << s.states << " continuous states, "
            << s.event_indicators << " event indicators\n";
  return 0;
}

}  // namespace dydp::apps
