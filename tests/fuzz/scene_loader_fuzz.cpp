// libFuzzer target: any bytes as a scene file. Loading must either give a diagram or throw
// InputError (file:line: field: message, exit 2 in dydp); any other exception, a crash, a leak
// or undefined behaviour is a finding. Seeds: scenarios/ (scripts/fuzz_run.sh).
//
// The input is written where the shipped scenes' subsystem includes resolve: a private folder
// holding a copy of scenarios/subsystems, the input one level below it beside a link to that
// copy, so that both `subsystems/corner_rig.yaml` (scenarios/) and `../subsystems/...`
// (scenarios/stress/) reach the corner definitions and the flattener is fuzzed through them.
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <string>

#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"
#include "tests/fuzz/fuzz_input_file.hpp"

namespace {

namespace fs = std::filesystem;

/// The private folder, removed at exit.
class SceneFolder {
 public:
  SceneFolder() : root_(fs::temp_directory_path() / ("dydp_fuzz_scenes_" + std::to_string(::getpid()))) {
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

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const SceneFolder folder;
  static dydp::fuzz::InputFile file(".yaml", folder.scene_folder());
  const std::string& path = file.write(data, size);
  try {
    const dydp::engine::Diagram d = dydp::engine::load_scene(path);
  } catch (const dydp::engine::InputError&) {
    // refused, as bad input must be
  }
  return 0;
}
