// Scene validation of the `time:` and `solver:` keys: malformed or unknown keys, non-positive
// output steps, a stop not after the start, unknown solver methods, tolerances, minimum steps,
// the Newton coefficient, the maximum order per method and the true/false switches.
#include <gtest/gtest.h>

#include <string>

#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"
#include "tests/engine/scene/scene_validation.hpp"

namespace dydp::engine {
namespace {

TEST_F(SceneValidation, MalformedTimeNumber) {
  const std::string path = write("s.yaml", R"(scene: t
time:
  start: 0.0
  stop: ten
blocks:
  src: {type: source.sine}
outputs: [src.y]
)");
  expect_error(load_error(path), path, 4, "time.stop", "malformed number 'ten'");
}

TEST_F(SceneValidation, UnknownKeyInTime) {
  const std::string path = write("s.yaml", R"(scene: t
time:
  stop: 1.0
  outputstep: 0.1
blocks:
  src: {type: source.sine}
outputs: [src.y]
)");
  expect_error(load_error(path), path, 4, "time.outputstep", "unknown key");
}

TEST_F(SceneValidation, ZeroOutputStep) {
  const std::string path = write("s.yaml", R"(scene: t
time:
  start: 0.0
  stop: 1.0
  output_step: 0
blocks:
  src: {type: source.sine}
outputs: [src.y]
)");
  expect_error(load_error(path), path, 5, "time.output_step", "must be positive");
}

TEST_F(SceneValidation, NegativeOutputStep) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: -0.1}
blocks:
  src: {type: source.sine}
outputs: [src.y]
)");
  expect_error(load_error(path), path, 2, "time.output_step", "must be positive");
}

TEST_F(SceneValidation, StopNotAfterStart) {
  const std::string path = write("s.yaml", R"(scene: t
time:
  start: 2.0
  stop: 1.0
blocks:
  src: {type: source.sine}
outputs: [src.y]
)");
  expect_error(load_error(path), path, 4, "time.stop", "must be greater than time.start");
}

TEST_F(SceneValidation, UnknownSolverMethod) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
solver:
  rtol: 1.0e-6
  method: euler
blocks:
  src: {type: source.sine}
outputs: [src.y]
)");
  expect_error(load_error(path), path, 5, "solver.method", "unknown method 'euler'");
}

/// A scene whose solver block has `method: bdf` and then `setting` on line 5.
std::string scene_with_solver_setting(const std::string& setting) {
  return R"(scene: t
time: {stop: 1.0, output_step: 0.1}
solver:
  method: bdf
  )" + setting + R"(
blocks:
  src: {type: source.sine}
outputs: [src.y]
)";
}

TEST_F(SceneValidation, NonPositiveTolerance) {
  const std::string path = write("s.yaml", scene_with_solver_setting("atol: -1.0e-8"));
  expect_error(load_error(path), path, 5, "solver.atol", "must be positive");
}

TEST_F(SceneValidation, NegativeMinStep) {
  const std::string path = write("s.yaml", scene_with_solver_setting("min_step: -1.0e-12"));
  expect_error(load_error(path), path, 5, "solver.min_step", "must not be negative");
}

TEST_F(SceneValidation, NewtonCoefficientOutsideTheUnitInterval) {
  for (const char* value : {"0.0", "-0.1", "1.5"}) {
    const std::string path = write("s.yaml", scene_with_solver_setting(std::string("newton_coefficient: ") + value));
    expect_error(load_error(path), path, 5, "solver.newton_coefficient", "must be in (0, 1]");
  }
}

TEST_F(SceneValidation, MaxOrderIsAnOrderTheMethodHas) {
  struct Case {
    std::string setting, message;
  };
  for (const Case& c : {Case{"max_order: 0", "value 0 must be a whole number in [1, 12]"},
                        Case{"max_order: 2.5", "value 2.5 must be a whole number in [1, 12]"},
                        Case{"max_order: 13", "value 13 must be a whole number in [1, 12]"},
                        Case{"max_order: 6", "value 6 must be a whole number in [1, 5] for bdf"}}) {
    const std::string path = write("s.yaml", scene_with_solver_setting(c.setting));
    expect_error(load_error(path), path, 5, "solver.max_order", c.message);
  }
  std::string fixed = scene_with_solver_setting("max_order: 2");
  fixed.replace(fixed.find("method: bdf"), 11, "method: rk4");
  const std::string path = write("s.yaml", fixed);
  expect_error(load_error(path), path, 5, "solver.max_order", "applies to bdf and adams only");
  std::string adams = scene_with_solver_setting("max_order: 8");
  adams.replace(adams.find("method: bdf"), 11, "method: adams");
  EXPECT_EQ(load_scene(write("a.yaml", adams)).solver.max_order, 8);
}

TEST_F(SceneValidation, SolverSwitchesAreTrueOrFalse) {
  for (const char* key : {"sens_error_test", "nominal_scaling", "refresh_local_jacobians"}) {
    const std::string path = write("s.yaml", scene_with_solver_setting(std::string(key) + ": maybe"));
    expect_error(load_error(path), path, 5, std::string("solver.") + key, "expected true or false");
  }
}

}  // namespace
}  // namespace dydp::engine
