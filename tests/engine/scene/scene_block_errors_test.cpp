// Scene validation of blocks: an unknown or missing block type, a block defined twice, an unknown
// parameter key, a missing required setting, a parameter outside its bounds or not a number: each
// an InputError naming the file, the line and the field where it was written.
#include <gtest/gtest.h>

#include <string>

#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"
#include "tests/engine/scene/scene_validation.hpp"

namespace dydp::engine {
namespace {

TEST_F(SceneValidation, UnknownBlockType) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
  g:
    type: math.gian
connections:
  - src.y -> g.u
outputs: [g.y]
)");
  expect_error(load_error(path), path, 6, "g.type", "unknown block type 'math.gian'");
}

TEST_F(SceneValidation, BlockDefinedTwice) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
  src: {type: source.constant}
outputs: [src.y]
)");
  expect_error(load_error(path), path, 5, "src", "block defined twice");
}

TEST_F(SceneValidation, BlockParameterOutOfBounds) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src:
    type: source.sine
    amplitude: 2.0
    frequency: -1.0
outputs: [src.y]
)");
  expect_error(load_error(path), path, 7, "src.frequency", "outside [0");
}

TEST_F(SceneValidation, BlockParameterOutOfBoundsThroughSceneParameter) {
  // The scene parameter is within its own range, but not within the block's bounds.
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
parameters:
  f: {value: -2.0, range: [-5.0, 5.0]}
blocks:
  src:
    type: source.sine
    frequency: $f
outputs: [src.y]
)");
  expect_error(load_error(path), path, 8, "src.frequency", "outside [0");
}

TEST_F(SceneValidation, MalformedBlockParameterNumber) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src:
    type: source.sine
    amplitude: 1.2.3
outputs: [src.y]
)");
  expect_error(load_error(path), path, 6, "src.amplitude", "malformed number '1.2.3'");
}

TEST_F(SceneValidation, NonFiniteNumberIsMalformed) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src:
    type: source.sine
    amplitude: 1e999
outputs: [src.y]
)");
  expect_error(load_error(path), path, 6, "src.amplitude", "malformed number '1e999'");
}

TEST_F(SceneValidation, UnknownBlockParameterKey) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src:
    type: source.sine
    amplitud: 2.0
outputs: [src.y]
)");
  const InputError e = load_error(path);
  expect_error(e, path, 6, "src.amplitud", "unknown parameter of source.sine");
  // The message lists what the type knows.
  EXPECT_NE(std::string(e.what()).find("amplitude"), std::string::npos) << e.what();
}

TEST_F(SceneValidation, MissingRequiredSetting) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  road:
    type: source.table
    file: road.csv
outputs: [road.y]
)");
  expect_error(load_error(path), path, 4, "road.column", "required setting is missing");
}

TEST_F(SceneValidation, MissingBlockType) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {amplitude: 1.0}
outputs: [src.y]
)");
  expect_error(load_error(path), path, 4, "src.type", "missing block type");
}

}  // namespace
}  // namespace dydp::engine
