// libFuzzer target: any bytes as a scene file, loaded with `load_scene` and, when it loads, RUN
// with its sensitivities for a bounded simulated time, so that the blocks' outputs, derivatives
// and tangents, the passes and the integrators are fuzzed, not only the loader. The bounds, set
// on the loaded diagram as the command line's solver options are: the run ends at most 0.05 s
// after the scene's start; at most 50 output intervals; at most 2000 steps an interval
// (solver.max_steps); a fixed step (rk4, sdirk2) of at least 1e-4 s. A run must give a result
// or throw InputError (bad input found at run time), SolverError or OutOfDomain (the failures
// dydp reports with exit 1); any other exception, a crash, a leak, undefined behaviour or a hang
// is a finding, and so is a result whose arrays do not have the sizes its grid says.
// Seeds: scenarios/ (scripts/fuzz_run.sh); the input is written where the shipped scenes'
// subsystem includes resolve, as for scene_loader_fuzz.
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <string>

#include "engine/analysis/run.hpp"
#include "engine/framework/block.hpp"
#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"
#include "engine/studies/initial_equilibrium.hpp"
#include "tests/fuzz/fuzz_input_file.hpp"

namespace {

namespace fs = std::filesystem;

constexpr double kMaxSimulatedTime = 0.05;  ///< [s] after the scene's start
constexpr int kMaxOutputIntervals = 50;
constexpr long kMaxStepsPerInterval = 2000;
constexpr double kMinFixedStep = 1e-4;      ///< [s]

/// A private folder with a copy of scenarios/subsystems (as scene_loader_fuzz), removed at exit.
class SceneFolder {
 public:
  SceneFolder() : root_(fs::temp_directory_path() / ("dydp_fuzz_run_" + std::to_string(::getpid()))) {
    fs::remove_all(root_);
    fs::create_directories(root_ / "scene");
    fs::copy(fs::path(DYDP_SOURCE_DIR) / "scenarios" / "subsystems", root_ / "subsystems", fs::copy_options::recursive);
    fs::create_directory_symlink("../subsystems", root_ / "scene" / "subsystems");
  }
  ~SceneFolder() {
    std::error_code ignored;
    fs::remove_all(root_, ignored);
  }
  fs::path scene_folder() const { return root_ / "scene"; }

 private:
  fs::path root_;
};

void bound(dydp::engine::Diagram& d) {
  auto& t = d.time;
  t.stop = std::min(t.stop, t.start + kMaxSimulatedTime);
  t.output_step = std::max(t.output_step, (t.stop - t.start) / kMaxOutputIntervals);
  d.solver.max_steps = std::min(d.solver.max_steps, kMaxStepsPerInterval);
  const bool fixed_step = d.solver.method == "rk4" || d.solver.method == "sdirk2";
  if (fixed_step) {
    const double step = d.solver.step > 0.0 ? d.solver.step : t.output_step / 10.0;
    d.solver.step = std::max(step, kMinFixedStep);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const SceneFolder folder;
  static dydp::fuzz::InputFile file(".yaml", folder.scene_folder());
  const std::string& path = file.write(data, size);
  dydp::engine::Diagram d;
  try {
    d = dydp::engine::load_scene(path);
  } catch (const dydp::engine::InputError&) {
    return 0;  // refused, as bad input must be
  }
  bound(d);
  try {
    // `initial: equilibrium`: its start first, as every command runs a scene
    const dydp::engine::RunResult r = dydp::engine::run_from_initial(d);
    const size_t samples = r.t.size();
    const size_t signals = r.signal_names.size();
    if (r.values.size() != samples * signals) __builtin_trap();
    if (r.tangents.size() != samples * signals * r.sensitivity_names.size()) __builtin_trap();
    if (r.sensitivity_names.size() != d.sensitivities.size()) __builtin_trap();
  } catch (const dydp::engine::InputError&) {
  } catch (const dydp::engine::SolverError&) {
  } catch (const dydp::engine::OutOfDomain&) {
  }
  return 0;
}
