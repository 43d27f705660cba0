// The sedan's suspension geometry as sensitivity directions: the lower mounts of the front
// struts and of the rear dampers and springs, and the sprung mass's centre height, are symbols
// of the generated model. Their exact sensitivities through the shipped scenes match central
// differences whose error falls as h^2, and the handling scene's roll grows with the centre
// height as the lateral load transfer says it must.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "engine/analysis/run.hpp"
#include "engine/framework/diagram.hpp"
#include "tests/temp_folder_test.hpp"

namespace dydp::engine {
namespace {

const std::vector<std::string> kGeometry = {"strut_mount_front", "shock_mount_rear", "spring_seat_rear", "com_height"};

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void replace(std::string& text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  ASSERT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
}

class SedanGeometry : public test::TempFolderTest {
 protected:
  SedanGeometry() : TempFolderTest("dydp_sedan_geometry_") {}

  // The shipped comfort scene over its first 2 s (objective windows [1, 2] s; under the
  // sanitizers 1 s, windows [0.5, 1] s), its subsystem file named by its absolute path.
  std::string short_comfort_scene() {
    const std::string scenes = std::string(DYDP_SOURCE_DIR) + "/scenarios/";
    std::string text = read(scenes + "fourposter_comfort.yaml");
    const std::string stop = DYDP_SANITIZED ? "1.0" : "2.0", window = DYDP_SANITIZED ? "[0.5, 1.0]" : "[1.0, 2.0]";
    replace(text, "stop: 20.0", "stop: " + stop);
    replace(text, "comfort: {type: objective.rms, window: [2.0, 20.0]}", "comfort: {type: objective.rms, window: " + window + "}");
    replace(text, "comfort_wk: {type: objective.rms, window: [2.0, 20.0]}",
            "comfort_wk: {type: objective.rms, window: " + window + "}");
    replace(text, "file: subsystems/", "file: " + scenes + "subsystems/");
    return write("comfort.yaml", text);
  }
};

// The scene's solver tightened (rtol 1e-9, sensitivities in the error test), so that the
// difference quotients below are not drowned by the solver's own error (at the shipped rtol
// 1e-7 psi carries about 1e-7 of noise, which over h = 0.1 % of a mount is 1e-4 of dpsi/dp).
Diagram tight(const std::string& scene) {
  Diagram d = load_scene(scene);
  d.solver.rtol = 1e-9;
  d.solver.atol = 1e-11;
  d.solver.sens_error_test = true;
  return d;
}

// psi at the direction's value moved by h (no sensitivities).
double value_at(const std::string& scene, int parameter, double value, int objective) {
  Diagram d = tight(scene);
  d.set_parameter(parameter, value);
  RunOptions options;
  options.sensitivities = false;
  return run(d, options).objectives[objective].value;
}

void expect_central_differences_converge(const std::string& scene, const std::vector<std::string>& names) {
  Diagram d = tight(scene);
  std::vector<int> directions;
  for (const std::string& name : names) {
    const int i = d.find_parameter(name);
    ASSERT_GE(i, 0) << name;
    directions.push_back(i);
  }
  d.set_sensitivities(directions);
  const RunResult exact = run(d);
  for (std::size_t k = 0; k < directions.size(); ++k) {
    const double p = d.parameters[directions[k]].value;
    for (std::size_t o = 0; o < exact.objectives.size(); ++o) {
      SCOPED_TRACE(names[k] + " on " + exact.objectives[o].name);
      const double derivative = exact.objectives[o].sensitivity[k];
      ASSERT_TRUE(std::isfinite(derivative));
      ASSERT_NE(derivative, 0.0);
      // Steps of 1 %, 0.1 % and 0.01 % of the coordinate: the difference quotient's error is
      // its h^2 term (a tenfold smaller step, a hundredfold smaller error) until the solver's
      // error in psi (about 10 rtol |psi|), divided by h, takes over; then it is below that.
      double previous = INFINITY, best = INFINITY;
      for (double relative : {1e-2, 1e-3, 1e-4}) {
        const double h = relative * std::fabs(p);
        const double fd = (value_at(scene, directions[k], p + h, static_cast<int>(o)) -
                           value_at(scene, directions[k], p - h, static_cast<int>(o))) /
                          (2 * h);
        const double error = std::fabs(fd - derivative) / std::fabs(derivative);
        const double noise = 10 * d.solver.rtol * std::fabs(exact.objectives[o].value) / (h * std::fabs(derivative));
        EXPECT_TRUE(error < previous / 20 || error < noise)
            << "h = " << h << ": fd " << fd << ", exact " << derivative << ", error " << error << " after "
            << previous << ", noise bound " << noise;
        previous = error;
        best = std::min(best, error);
      }
      EXPECT_LT(best, 1e-4);
    }
  }
}

TEST_F(SedanGeometry, ComfortSensitivitiesToTheMountsAndCentreHeightMatchCentralDifferences) {
  expect_central_differences_converge(short_comfort_scene(), kGeometry);
}

TEST_F(SedanGeometry, HandlingSensitivitiesToTheCentreHeightMatchCentralDifferencesAndRollGrowsWithIt) {
  const std::string scene = std::string(DYDP_SOURCE_DIR) + "/scenarios/cornering_arb.yaml";
  expect_central_differences_converge(scene, {"com_height", "strut_mount_front"});

  // A higher centre of mass carries more lateral load transfer for the same roll stiffness:
  // d(roll)/d(height) is positive and of the size m a_y / K_roll gives (roll / arm, the arm the
  // height above the roll axis: a few tenths of a metre).
  Diagram d = load_scene(scene);
  const int height = d.find_parameter("com_height");
  d.set_sensitivities({height});
  const RunResult r = run(d);
  const auto roll = std::find_if(r.objectives.begin(), r.objectives.end(), [](const auto& o) { return o.name == "roll"; });
  ASSERT_NE(roll, r.objectives.end());
  ASSERT_GT(roll->value, 0.0);
  const double arm = roll->value / roll->sensitivity[0];
  EXPECT_GT(roll->sensitivity[0], 0.0);
  EXPECT_GT(arm, 0.1);
  EXPECT_LT(arm, 0.6);
}

}  // namespace
}  // namespace dydp::engine
