// A stiff scene (a lag of time constant 10 us behind a slow sine, feeding a mass): the implicit
// methods run it at steps far above the lag's time constant; RK4 at such a step reports the
// instability (block and time) instead of writing non-finite numbers.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "engine/analysis/run.hpp"
#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"

namespace dydp::engine {
namespace {

Diagram stiff_scene(const std::string& solver) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("dydp_stiff_test_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(path) << R"(scene: stiff
time: {start: 0.0, stop: 2.0, output_step: 0.01}
solver: )" << solver << R"(
parameters:
  tau: {value: 1.0e-5, unit: s}
  stiffness: {value: 40.0, unit: N/m}
sensitivities: [tau, stiffness]
blocks:
  drive: {type: source.sine, amplitude: 5.0, frequency: 1.0}
  actuator: {type: math.lag, tau: $tau}
  body: {type: mass_spring_damper, m: 1.0, k: $stiffness, c: 0.5}
  x_rms: {type: objective.rms}
connections:
  - drive.y -> actuator.u
  - actuator.y -> body.f
  - body.x -> x_rms.in
outputs: [body.x, x_rms]
)";
  return load_scene(path.string());
}

TEST(Stiff, ImplicitMethodsAgreeAtStepsFarAboveTheFastTimeConstant) {
  const RunResult bdf = run(stiff_scene("{method: bdf, rtol: 1.0e-9, atol: 1.0e-11}"));
  const RunResult sdirk = run(stiff_scene("{method: sdirk2, step: 0.001}"));
  ASSERT_EQ(bdf.objectives.size(), 1u);
  // SDIRK2 is second order: at h = 1 ms (100 x tau) it is within 1e-4 of the tight BDF run.
  EXPECT_NEAR(sdirk.objectives[0].value, bdf.objectives[0].value, 1e-4 * bdf.objectives[0].value);
  for (int d = 0; d < 2; ++d)
    EXPECT_NEAR(sdirk.objectives[0].sensitivity[d], bdf.objectives[0].sensitivity[d],
                1e-3 * std::fabs(bdf.objectives[0].sensitivity[d]) + 1e-12)
        << bdf.sensitivity_names[d];
  // BDF takes far fewer steps than the fast time constant would force on an explicit method.
  EXPECT_LT(bdf.stats.steps, 20000);
}

TEST(Stiff, Rk4ReportsTheInstabilityWithBlockAndTime) {
  try {
    run(stiff_scene("{method: rk4, step: 0.001}"));
    FAIL() << "RK4 at 100 x the lag's time constant must not complete";
  } catch (const SolverError& e) {
    EXPECT_EQ(e.block(), "actuator") << e.what();
    EXPECT_GT(e.time(), 0.0);
    EXPECT_LT(e.time(), 2.0);
    EXPECT_NE(std::string(e.what()).find("not finite"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace dydp::engine
