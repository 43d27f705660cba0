// Shared set-up of the FMI tests: the FMUs of the quarter car, the CDC damper (with its stroke
// and rate as inputs) and the damper's rig scene exported once per test program into a
// temporary folder, and the small numerics the importers need.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Dense>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "fmi/fmu_export.hpp"
#include "tests/fmi/fmu_importer.hpp"

namespace dydp::test {

inline const std::string kQuarterCar = std::string(DYDP_SOURCE_DIR) + "/scenarios/quarter_car_cdc.yaml";
inline const std::string kDamper = std::string(DYDP_SOURCE_DIR) + "/scenarios/fmu/cdc_damper.yml";
inline const std::string kDamperRig = std::string(DYDP_SOURCE_DIR) + "/scenarios/fmu/cdc_damper_rig.yaml";
inline const std::string kCornerRig = std::string(DYDP_SOURCE_DIR) + "/scenarios/fmu/corner_rig.yml";

/// The folder of this test program's FMUs, made once and removed at exit.
class FmuFolder : public ::testing::Environment {
 public:
  static std::filesystem::path path() {
    static const std::filesystem::path p = std::filesystem::temp_directory_path() /
                                           ("dydp_fmi_" + std::to_string(::getpid()));
    return p;
  }
  void SetUp() override { std::filesystem::create_directories(path()); }
  void TearDown() override { std::filesystem::remove_all(path()); }
};

/// The FMU of `source` (exported on first use, both kinds or Co-Simulation only) unpacked and
/// loaded, one copy per `tag`.
inline std::unique_ptr<Fmu> load_fmu(const std::string& source, const std::string& name, const std::string& tag,
                                     bool cs_only = false) {
  namespace fs = std::filesystem;
  const fs::path archive = FmuFolder::path() / (name + ".fmu");
  if (!fs::exists(archive)) {
    fmi::ExportOptions o;
    o.source = source;
    o.out = archive.string();
    o.model_exchange = !cs_only;
    fmi::export_fmu(o);
  }
  return std::make_unique<Fmu>(archive.string(), (FmuFolder::path() / (name + "_" + tag)).string());
}

/// A copy of the CDC damper's description (scenarios/fmu/cdc_damper.yml) in the test folder with
/// `sensitivities: [valve_current, pipe_length]`; without_inputs, the rig's sources drive the
/// damper inside the FMU (as in the native run of the rig scene). Returns its path.
inline std::string damper_sensitivity_description(bool without_inputs) {
  const std::filesystem::path p =
      FmuFolder::path() / (without_inputs ? "cdc_damper_sens_rig.yml" : "cdc_damper_sens.yml");
  std::ofstream out(p);
  out << "fmu: " << p.stem().string() << "\n"
      << "description: CDC damper with the sensitivities to its valve current and pipe length.\n"
      << "scene: " << std::string(DYDP_SOURCE_DIR) << "/scenarios/fmu/cdc_damper_rig.yaml\n"
      << (without_inputs ? "" : "inputs: [stroke.y, stroke_rate.y]\n")
      << "outputs: [damper.force, damper.p_rebound, damper.p_compression, damper.power]\n"
      << "parameters: [valve_current, pipe_length]\n"
      << "sensitivities: [valve_current, pipe_length]\n";
  return p.string();
}

/// The sine sources of scenarios/fmu/cdc_damper_rig.yaml, as source.sine computes them.
inline double rig_stroke(double t) { return 0.02 * std::sin(2 * std::numbers::pi * 2.0 * t + 0.0); }
inline double rig_stroke_rate(double t) {
  return 0.25132741228718347 * std::sin(2 * std::numbers::pi * 2.0 * t + 1.5707963267948966);
}

/// A copy of `scene` in this test program's FMU folder, named `name`, that starts at its static
/// equilibrium (`initial: equilibrium` added); returns its path.
inline std::string scene_at_equilibrium(const std::string& scene, const std::string& name) {
  std::ifstream in(scene);
  std::stringstream text;
  text << in.rdbuf();
  const std::string copy = (FmuFolder::path() / name).string();
  std::ofstream(copy) << text.str() << "initial: equilibrium\n";
  return copy;
}

/// Largest |a - b| over a column, relative to the column's largest |b| (floor `tiny`).
inline double column_error(const std::vector<double>& a, const std::vector<double>& b, double tiny = 1e-300) {
  double err = 0.0, scale = tiny;
  for (size_t k = 0; k < a.size(); ++k) err = std::max(err, std::fabs(a[k] - b[k])), scale = std::max(scale, std::fabs(b[k]));
  return err / scale;
}

}  // namespace dydp::test
