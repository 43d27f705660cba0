// Scene validation of the wiring: unknown ports and blocks in connections and outputs, width
// mismatches, unconnected inputs, inputs driven twice and algebraic loops (pruned parts
// included): each an InputError naming the file, the line and the field where it was written.
#include <gtest/gtest.h>

#include <string>

#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"
#include "tests/engine/scene/scene_validation.hpp"

namespace dydp::engine {
namespace {

TEST_F(SceneValidation, UnknownInputPort) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
  g: {type: math.gain}
connections:
  - src.y -> g.input
outputs: [g.y]
)");
  expect_error(load_error(path), path, 7, "g.input", "has no input port 'input'");
}

TEST_F(SceneValidation, UnknownOutputPortInConnection) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
  g: {type: math.gain}
connections:
  - src.u -> g.u
outputs: [g.y]
)");
  expect_error(load_error(path), path, 7, "src.u", "has no output port 'u'");
}

// Found by the scene fuzzer (docs/fuzzing.md): an end written "block." was taken for the
// whole block and indexed the block's ports at -1 (UBSan: pointer overflow in GraphBuilder).
TEST_F(SceneValidation, ConnectionEndWithoutPortName) {
  for (const char* wire : {"src.y -> g.", "src. -> g.u", ".y -> g.u"}) {
    const std::string path = write("s.yaml", std::string(R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
  g: {type: math.gain}
connections:
  - src.y -> g.u
  - )") + wire + R"(
outputs: [g.y]
)");
    expect_error(load_error(path), path, 8, "connections", "both ends need block.port");
  }
}

TEST_F(SceneValidation, UnknownOutputPortInOutputs) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
  g: {type: math.gain}
connections:
  - src.y -> g.u
outputs:
  - g.y
  - g.z
)");
  expect_error(load_error(path), path, 10, "g.z", "has no output port 'z'");
}

TEST_F(SceneValidation, UnknownBlockInConnection) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
  g: {type: math.gain}
connections:
  - src.y -> g.u
  - src.y -> h.u
outputs: [g.y]
)");
  expect_error(load_error(path), path, 8, "h.u", "unknown block 'h'");
}

TEST_F(SceneValidation, WidthMismatch) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
  g: {type: math.gain, width: 3}
connections:
  - src.y -> g.u
outputs: [g.y]
)");
  expect_error(load_error(path), path, 7, "g.u", "width mismatch");
}

TEST_F(SceneValidation, UnconnectedInput) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
  s: {type: math.sum, signs: +-}
connections:
  - src.y -> s.in1
outputs: [s.y]
)");
  expect_error(load_error(path), path, 5, "s.in2", "input is not connected");
}

TEST_F(SceneValidation, UnconnectedInputOfPrunedBlock) {
  // A block no output needs is still checked: the scene is wrong even where it is not run.
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
  unused: {type: math.gain}
outputs: [src.y]
)");
  expect_error(load_error(path), path, 5, "unused.u", "input is not connected");
}

TEST_F(SceneValidation, InputDrivenTwice) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  a: {type: source.sine}
  b: {type: source.constant}
  g: {type: math.gain}
connections:
  - a.y -> g.u
  - b.y -> g.u
outputs: [g.y]
)");
  expect_error(load_error(path), path, 9, "g.u", "input driven twice (also connected at line 8)");
}

TEST_F(SceneValidation, AlgebraicLoopNamesItsBlocks) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
  loop_sum: {type: math.sum, signs: +-}
  loop_gain: {type: math.gain, k: 0.5}
connections:
  - src.y -> loop_sum.in1
  - loop_gain.y -> loop_sum.in2
  - loop_sum.y -> loop_gain.u
outputs: [loop_sum.y]
)");
  const InputError e = load_error(path);
  // The loop's first connection in the file.
  expect_error(e, path, 9, "connections", "algebraic loop");
  const std::string what = e.what();
  EXPECT_NE(what.find("loop_sum"), std::string::npos) << what;
  EXPECT_NE(what.find("loop_gain"), std::string::npos) << what;
  EXPECT_EQ(what.find("src"), std::string::npos) << "src is not on the loop: " << what;
}

TEST_F(SceneValidation, AlgebraicLoopInPrunedPart) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
  g1: {type: math.gain}
  g2: {type: math.gain}
connections:
  - g2.y -> g1.u
  - g1.y -> g2.u
outputs: [src.y]
)");
  const InputError e = load_error(path);
  expect_error(e, path, 8, "connections", "algebraic loop");
  const std::string what = e.what();
  EXPECT_NE(what.find("g1"), std::string::npos) << what;
  EXPECT_NE(what.find("g2"), std::string::npos) << what;
}

}  // namespace
}  // namespace dydp::engine
