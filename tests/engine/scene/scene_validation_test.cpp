// Scene validation: every kind of bad input is an InputError naming the file, the line and the
// field where it was written; and the graph checks that accept good scenes (pruning, ordering,
// loops broken by a state, scene parameters driving block parameters).
//
// Each scene is a raw string literal whose first line is line 1 of the file, so the expected
// line numbers can be counted in the literal.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"
#include "tests/engine/scene_error_test.hpp"

namespace dydp::engine {
namespace {

namespace fs = std::filesystem;

class SceneValidation : public test::SceneErrorTest {
 protected:
  SceneValidation() : SceneErrorTest("dydp_scene_validation_") {}

  static int index_of(const Diagram& d, const std::string& name) {
    for (size_t i = 0; i < d.nodes.size(); ++i)
      if (d.nodes[i].name == name) return static_cast<int>(i);
    return -1;
  }

  /// Position in the evaluation order of node i's step for its outputs that read states only
  /// (reads_inputs false) or its first step for outputs that read inputs, or -1.
  static int position(const Diagram& d, int i, bool reads_inputs) {
    for (size_t k = 0; k < d.output_steps.size(); ++k)
      if (d.output_steps[k].node == i && d.output_steps[k].reads.empty() != reads_inputs)
        return static_cast<int>(k);
    return -1;
  }
};

// ---------------------------------------------------------------- errors of the graph

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

// ---------------------------------------------------------------- errors of values

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

TEST_F(SceneValidation, UnknownTopLevelKey) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
solvr: {method: bdf}
blocks:
  src: {type: source.sine}
outputs: [src.y]
)");
  const InputError e = load_error(path);
  EXPECT_EQ(e.file(), path);
  EXPECT_EQ(e.line(), 3) << e.what();
  // The field names the unknown key (prefixed by its context).
  const std::string& field = e.field();
  EXPECT_TRUE(field.size() >= 5 && field.compare(field.size() - 5, 5, "solvr") == 0) << field;
  EXPECT_NE(std::string(e.what()).find("unknown key"), std::string::npos) << e.what();
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

TEST_F(SceneValidation, YamlSyntaxError) {
  // Line 5 opens a flow sequence that is never closed.
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
outputs: [src.y
)");
  const InputError e = load_error(path);
  EXPECT_EQ(e.file(), path);
  // yaml-cpp reports the point where it gave up: on or after the unclosed bracket.
  EXPECT_GE(e.line(), 5) << e.what();
  EXPECT_LE(e.line(), 6) << e.what();
  EXPECT_NE(std::string(e.what()).find("YAML syntax"), std::string::npos) << e.what();
}

TEST_F(SceneValidation, YamlSyntaxErrorInTheMiddle) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}: 3
outputs: [src.y]
)");
  const InputError e = load_error(path);
  EXPECT_EQ(e.file(), path);
  EXPECT_EQ(e.line(), 4) << e.what();
  EXPECT_NE(std::string(e.what()).find("YAML syntax"), std::string::npos) << e.what();
}

TEST_F(SceneValidation, MissingSceneFile) {
  const std::string path = (dir_ / "absent.yaml").string();
  const InputError e = load_error(path);
  EXPECT_EQ(e.file(), path);
  EXPECT_NE(std::string(e.what()).find("cannot open"), std::string::npos) << e.what();
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

TEST_F(SceneValidation, MalformedCsvTableNamesTheCsvFileAndRow) {
  const std::string csv = write("road.csv", "t,z\n0.0,0.0\n0.5,0.01\n1.0,abc\n");
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  road: {type: source.table, file: road.csv, column: z}
outputs: [road.y]
)");
  const InputError e = load_error(path);
  EXPECT_EQ(fs::path(e.file()).lexically_normal(), fs::path(csv).lexically_normal()) << e.what();
  EXPECT_EQ(e.line(), 4) << e.what();  // header is row 1
  EXPECT_EQ(e.field(), "z") << e.what();
  EXPECT_NE(std::string(e.what()).find("malformed number"), std::string::npos) << e.what();
}

TEST_F(SceneValidation, CsvTableTimesMustIncrease) {
  const std::string csv = write("road.csv", "t,z\n0.0,0.0\n0.5,0.01\n0.5,0.02\n");
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  road: {type: source.table, file: road.csv, column: z}
outputs: [road.y]
)");
  const InputError e = load_error(path);
  EXPECT_EQ(fs::path(e.file()).lexically_normal(), fs::path(csv).lexically_normal()) << e.what();
  EXPECT_EQ(e.line(), 4) << e.what();
  EXPECT_EQ(e.field(), "t") << e.what();
  EXPECT_NE(std::string(e.what()).find("times must increase"), std::string::npos) << e.what();
}

TEST_F(SceneValidation, CsvTableUnknownColumnNamesTheSceneLine) {
  write("road.csv", "t,z\n0.0,0.0\n1.0,0.01\n");
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  road:
    type: source.table
    file: road.csv
    column: height
outputs: [road.y]
)");
  expect_error(load_error(path), path, 7, "road.column", "no column 'height'");
}

// ---------------------------------------------------------------- scenes that load

TEST_F(SceneValidation, PrunesBlocksNoOutputNeeds) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
  g: {type: math.gain, k: 2.0}
  spare_src: {type: source.constant}
  spare_gain: {type: math.gain}
connections:
  - src.y -> g.u
  - spare_src.y -> spare_gain.u
outputs: [g.y]
)");
  const Diagram d = load_scene(path);
  std::vector<std::string> pruned = d.pruned;
  std::sort(pruned.begin(), pruned.end());
  EXPECT_EQ(pruned, (std::vector<std::string>{"spare_gain", "spare_src"}));
  ASSERT_EQ(d.nodes.size(), 2u);
  EXPECT_EQ(index_of(d, "spare_src"), -1);
  EXPECT_EQ(index_of(d, "spare_gain"), -1);
  EXPECT_GE(index_of(d, "src"), 0);
  EXPECT_GE(index_of(d, "g"), 0);
  ASSERT_EQ(d.logged.size(), 1u);
  EXPECT_EQ(d.logged[0].name, "g.y");
}

TEST_F(SceneValidation, UpstreamOfARequestedOutputIsKept) {
  // g2 is only needed through g1: following connections backwards must keep it.
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  g1: {type: math.gain}
  g2: {type: math.gain}
  src: {type: source.sine}
connections:
  - g2.y -> g1.u
  - src.y -> g2.u
outputs: [g1.y]
)");
  const Diagram d = load_scene(path);
  EXPECT_TRUE(d.pruned.empty());
  EXPECT_EQ(d.nodes.size(), 3u);
}

TEST_F(SceneValidation, EvaluationOrderFollowsFeedthrough) {
  // Listed downstream-first: the feedthrough pass must still put each source before what it
  // feeds.
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  out_gain: {type: math.gain, k: 3.0}
  mid_gain: {type: math.gain, k: 2.0}
  src: {type: source.sine}
connections:
  - mid_gain.y -> out_gain.u
  - src.y -> mid_gain.u
outputs: [out_gain.y]
)");
  const Diagram d = load_scene(path);
  const int src = index_of(d, "src"), mid = index_of(d, "mid_gain"), out = index_of(d, "out_gain");
  ASSERT_GE(src, 0);
  ASSERT_GE(mid, 0);
  ASSERT_GE(out, 0);
  // The source reads no input: its step waits for nothing.
  ASSERT_EQ(d.output_steps.size(), 3u);
  EXPECT_GE(position(d, src, false), 0);
  EXPECT_LT(position(d, src, false), position(d, mid, true));
  EXPECT_LT(position(d, mid, true), position(d, out, true));
  // Each input reads the signal slot its source writes.
  EXPECT_EQ(d.nodes[mid].input_source[0], d.nodes[src].output_offset[0]);
  EXPECT_EQ(d.nodes[out].input_source[0], d.nodes[mid].output_offset[0]);
}

TEST_F(SceneValidation, LoopBrokenByAStateIsAccepted) {
  // x' = u - x through a sum and an integrator: the integrator's output reads its state only.
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
  err: {type: math.sum, signs: +-}
  integ: {type: math.integrator}
connections:
  - src.y -> err.in1
  - integ.y -> err.in2
  - err.y -> integ.u
outputs: [integ.y, err.y]
)");
  Diagram d;
  ASSERT_NO_THROW(d = load_scene(path));
  EXPECT_EQ(d.nodes.size(), 3u);
  EXPECT_EQ(d.num_states, 1);
  const int src = index_of(d, "src"), err = index_of(d, "err"), integ = index_of(d, "integ");
  // The integrator's output is computed first, from its state; the sum after its sources.
  EXPECT_GE(position(d, integ, false), 0);
  EXPECT_EQ(position(d, integ, true), -1);
  EXPECT_LT(position(d, integ, false), position(d, err, true));
  EXPECT_LT(position(d, src, false), position(d, err, true));
  EXPECT_GE(position(d, src, false), 0);
}

TEST_F(SceneValidation, LoopThroughStateOnlyOutputOfMixedBlockIsAccepted) {
  // body.x reads the state only: x -> gain -> f closes a loop that a state breaks.
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  body: {type: mass_spring_damper}
  feedback: {type: math.gain, k: -2.0}
connections:
  - body.x -> feedback.u
  - feedback.y -> body.f
outputs: [body.x, body.a]
)");
  Diagram d;
  ASSERT_NO_THROW(d = load_scene(path));
  const int body = index_of(d, "body"), feedback = index_of(d, "feedback");
  // body has two steps: x and v first, a after the gain that drives f.
  EXPECT_GE(position(d, body, false), 0);
  EXPECT_LT(position(d, body, false), position(d, feedback, true));
  EXPECT_LT(position(d, feedback, true), position(d, body, true));
  EXPECT_GE(position(d, feedback, true), 0);
}

TEST_F(SceneValidation, LoopThroughFeedthroughOutputOfMixedBlockIsAlgebraic) {
  // body.a = (f - c v - k x) / m reads f directly: a -> gain -> f is an algebraic loop.
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  body: {type: mass_spring_damper}
  feedback: {type: math.gain, k: -2.0}
connections:
  - feedback.y -> body.f
  - body.a -> feedback.u
outputs: [body.x]
)");
  const InputError e = load_error(path);
  expect_error(e, path, 7, "connections", "algebraic loop");
  const std::string what = e.what();
  EXPECT_NE(what.find("body"), std::string::npos) << what;
  EXPECT_NE(what.find("feedback"), std::string::npos) << what;
}

TEST_F(SceneValidation, LoggedSignalsOfWideAndWholeBlockOutputs) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.constant, value: 1.0}
  body: {type: mass_spring_damper}
  rms: {type: objective.rms}
connections:
  - src.y -> body.f
  - body.x -> rms.in
outputs: [body, rms]
)");
  const Diagram d = load_scene(path);
  std::vector<std::string> names;
  for (const auto& s : d.logged) names.push_back(s.name);
  EXPECT_EQ(names, (std::vector<std::string>{"body.x", "body.v", "body.a"}));
  ASSERT_EQ(d.objectives.size(), 1u);
  EXPECT_EQ(d.nodes[d.objectives[0]].name, "rms");
}

TEST_F(SceneValidation, SetParameterPropagatesAndChecksBounds) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
parameters:
  f: {value: 2.0, range: [-5.0, 5.0]}
sensitivities: [f]
blocks:
  a:
    type: source.sine
    frequency: $f
  b: {type: source.sine, frequency: $f, amplitude: 3.0}
  s: {type: math.sum}
connections:
  - a.y -> s.in1
  - b.y -> s.in2
outputs: [s.y]
)");
  Diagram d = load_scene(path);
  const int f = d.find_parameter("f");
  ASSERT_GE(f, 0);
  ASSERT_EQ(d.sensitivities, std::vector<int>{f});
  const int a = index_of(d, "a"), b = index_of(d, "b");
  ASSERT_GE(a, 0);
  ASSERT_GE(b, 0);
  constexpr int kFrequency = 1;  // source.sine: amplitude, frequency, phase, offset

  d.set_parameter(f, 3.5);
  EXPECT_DOUBLE_EQ(d.parameters[f].value, 3.5);
  EXPECT_DOUBLE_EQ(d.nodes[a].p[kFrequency], 3.5);
  EXPECT_DOUBLE_EQ(d.nodes[b].p[kFrequency], 3.5);
  EXPECT_DOUBLE_EQ(d.nodes[b].p[0], 3.0);  // amplitude untouched
  EXPECT_EQ(d.parameter_seed(d.nodes[a], kFrequency, 0), 1.0);
  EXPECT_EQ(d.parameter_seed(d.nodes[a], 0, 0), 0.0);

  // Outside the scene parameter's range.
  try {
    d.set_parameter(f, 6.0);
    ADD_FAILURE() << "no InputError for a value outside the range";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.line(), 4);
    EXPECT_EQ(e.field(), "parameters.f");
  }
  EXPECT_DOUBLE_EQ(d.parameters[f].value, 3.5);

  // Within the range but outside source.sine's frequency bounds [0, inf): names the block line.
  try {
    d.set_parameter(f, -1.0);
    ADD_FAILURE() << "no InputError for a value outside the block's bounds";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.line(), 9) << e.what();
    EXPECT_EQ(e.field(), "a.frequency");
    EXPECT_NE(std::string(e.what()).find("outside its bounds"), std::string::npos) << e.what();
  }
  EXPECT_DOUBLE_EQ(d.parameters[f].value, 3.5) << "a refused value must not be kept";
}

TEST_F(SceneValidation, RefusedSetParameterLeavesEveryBlockUnchanged) {
  // `f` drives an unbounded gain (evaluated first) and a sine frequency bounded below by 0:
  // a value the sine refuses must not be left behind in the gain.
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
parameters:
  f: {value: 2.0}
blocks:
  src: {type: source.constant, value: 1.0}
  g: {type: math.gain, k: $f}
  osc: {type: source.sine, frequency: $f}
  s: {type: math.sum}
connections:
  - g.y -> s.in1
  - osc.y -> s.in2
  - src.y -> g.u
outputs: [s.y]
)");
  Diagram d = load_scene(path);
  const int f = d.find_parameter("f");
  const int g = index_of(d, "g"), osc = index_of(d, "osc");
  ASSERT_GE(g, 0);
  ASSERT_GE(osc, 0);
  ASSERT_LT(g, osc) << "the test needs the unbounded user of f first";
  EXPECT_THROW(d.set_parameter(f, -1.0), InputError);
  EXPECT_DOUBLE_EQ(d.parameters[f].value, 2.0);
  EXPECT_DOUBLE_EQ(d.nodes[g].p[0], 2.0);
  EXPECT_DOUBLE_EQ(d.nodes[osc].p[1], 2.0);
}

}  // namespace
}  // namespace dydp::engine
