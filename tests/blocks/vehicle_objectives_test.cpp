// objective.slip_angle: its quadrature tangent, and the objective with its sensitivity through
// the engine against the closed form beta = atan(vy / vx).
#include <gtest/gtest.h>

#include <cmath>

#include "tests/blocks/scene_helpers.hpp"
#include "tests/blocks/tangent_check.hpp"

namespace dydp::test {
namespace {

TEST(SlipAngle, TangentsMatchFiniteDifferences) {
  BlockCase c;
  c.type = "objective.slip_angle";
  c.inputs = {{{15.0, 10.0}}, {{0.0, 3.0}}};
  c.samples = 20;
  check_tangents(c);
}

TEST(SlipAngle, MeanAndSensitivityThroughTheEngine) {
  const std::string scene = R"(scene: slip
time: {start: 0.0, stop: 3.0, output_step: 0.01}
solver: {method: bdf, rtol: 1.0e-10, atol: 1.0e-12}
parameters:
  vy: {value: 1.5, unit: m/s}
sensitivities: [vy]
blocks:
  vx: {type: source.constant, value: 20.0}
  vy_in: {type: source.ramp, start: 0.0, slope: 0.0, offset: $vy}
  beta: {type: objective.slip_angle, window: [1.0, 3.0]}
connections:
  - vx.y -> beta.vx
  - vy_in.y -> beta.vy
outputs: [beta]
)";
  const auto r = run_scene(write_scene("slip.yaml", scene));
  const auto& o = objective(r, "beta");
  EXPECT_NEAR(o.value, std::atan(1.5 / 20.0), 1e-9);
  EXPECT_NEAR(o.sensitivity.at(0), 20.0 / (400.0 + 1.5 * 1.5), 1e-8);
}

}  // namespace
}  // namespace dydp::test
