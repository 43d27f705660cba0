// Scene validation of scene parameters and --set: unknown $references and sensitivity names,
// parameters that cannot be directions, values outside their ranges, reversed ranges, malformed
// --set values; and --set overriding a scene parameter and the block parameter it drives.
#include <gtest/gtest.h>

#include <string>

#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"
#include "tests/engine/scene/scene_validation.hpp"

namespace dydp::engine {
namespace {

TEST_F(SceneValidation, UnknownSceneParameterReference) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
parameters:
  gain_k: {value: 2.0}
blocks:
  src: {type: source.sine}
  g:
    type: math.gain
    k: $gain_kk
connections:
  - src.y -> g.u
outputs: [g.y]
)");
  expect_error(load_error(path), path, 9, "g.k", "unknown scene parameter '$gain_kk'");
}

TEST_F(SceneValidation, NonDifferentiableParameterAsSensitivityDirection) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
parameters:
  t_step: {value: 0.5, unit: s}
sensitivities: [t_step]
blocks:
  st:
    type: source.step
    after: 2.0
    time: $t_step
outputs: [st.y]
)");
  expect_error(load_error(path), path, 10, "st.time", "not differentiable");
}

TEST_F(SceneValidation, NonDifferentiableParameterWithoutSensitivityIsAccepted) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
parameters:
  t_step: {value: 0.5, unit: s}
  level: {value: 2.0}
sensitivities: [level]
blocks:
  st:
    type: source.step
    after: $level
    time: $t_step
outputs: [st.y]
)");
  EXPECT_NO_THROW(load_scene(path));
}

TEST_F(SceneValidation, UnknownSensitivityParameter) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
parameters:
  level: {value: 2.0}
sensitivities:
  - level
  - levle
blocks:
  src: {type: source.constant, value: $level}
outputs: [src.y]
)");
  expect_error(load_error(path), path, 7, "sensitivities", "unknown scene parameter 'levle'");
}

// Scene with one parameter `gain_k` (line 4) used by the gain, for the --set tests.
constexpr const char* kGainScene = R"(scene: t
time: {stop: 1.0, output_step: 0.1}
parameters:
  gain_k: {value: 0.5, range: [0.0, 1.0]}
blocks:
  src: {type: source.sine}
  g: {type: math.gain, k: $gain_k}
connections:
  - src.y -> g.u
outputs: [g.y]
)";

TEST_F(SceneValidation, SetUnknownParameter) {
  const std::string path = write("s.yaml", kGainScene);
  const InputError e = load_error(path, {{"gain", "0.2"}});
  expect_error(e, "--set", 0, "gain", "no scene parameter of that name");
}

TEST_F(SceneValidation, SetMalformedValue) {
  const std::string path = write("s.yaml", kGainScene);
  expect_error(load_error(path, {{"gain_k", "0.2x"}}), "--set", 0, "gain_k",
               "malformed number '0.2x'");
  expect_error(load_error(path, {{"gain_k", ""}}), "--set", 0, "gain_k", "malformed number");
}

TEST_F(SceneValidation, SetValueOutsideRange) {
  const std::string path = write("s.yaml", kGainScene);
  expect_error(load_error(path, {{"gain_k", "1.5"}}), path, 4, "parameters.gain_k",
               "outside its range");
}

TEST_F(SceneValidation, SetOverridesSceneParameterAndBlockParameter) {
  const std::string path = write("s.yaml", kGainScene);
  const Diagram d = load_scene(path, {{"gain_k", "0.25"}});
  const int k = d.find_parameter("gain_k");
  ASSERT_GE(k, 0);
  EXPECT_DOUBLE_EQ(d.parameters[k].value, 0.25);
  const int g = index_of(d, "g");
  ASSERT_GE(g, 0);
  ASSERT_EQ(d.nodes[g].p.size(), 1u);
  EXPECT_DOUBLE_EQ(d.nodes[g].p[0], 0.25);
  EXPECT_EQ(d.nodes[g].p_scene[0], k);
}

TEST_F(SceneValidation, SceneParameterValueOutsideItsRange) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
parameters:
  damping: {value: 1.2, range: [0.0, 1.0]}
blocks:
  src: {type: source.constant, value: $damping}
outputs: [src.y]
)");
  expect_error(load_error(path), path, 4, "parameters.damping", "outside its range");
}

TEST_F(SceneValidation, SceneParameterRangeReversed) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
parameters:
  damping: {value: 1.2, range: [2.0, 1.0]}
blocks:
  src: {type: source.constant, value: $damping}
outputs: [src.y]
)");
  expect_error(load_error(path), path, 4, "parameters.damping.range", "low is above high");
}

}  // namespace
}  // namespace dydp::engine
