// Subsystems (docs/scenes.md, "Subsystems"): instances flattened with prefixed names, their
// parameters bound to scene parameters so that sensitivities cross the boundary (checked on the
// mass-spring-damper against its closed form), pruning and outputs through the boundary, and
// every error named at the file and line where it is written, inside subsystem files too.
//
// Each file is a raw string literal whose first line is line 1, so expected lines can be counted.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <filesystem>
#include <numbers>
#include <string>

#include "engine/analysis/run.hpp"
#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"
#include "tests/engine/msd_closed_form.hpp"
#include "tests/engine/scene_error_test.hpp"

namespace dydp::engine {
namespace {

namespace fs = std::filesystem;

// The oscillator of scenarios/msd_sensitivity.yaml as a subsystem: a sine force on a
// mass-spring-damper; `spare` is needed by nothing and must be pruned.
const char* const kOscillator = R"(subsystem: oscillator
parameters:
  mass: {unit: kg}
  stiffness: {value: 40.0, unit: N/m}
  damping: {value: 1.2, unit: N s/m}
  amplitude: 2.0
outputs:
  position: body.x
blocks:
  force: {type: source.sine, amplitude: $amplitude, frequency: 0.8}
  body: {type: mass_spring_damper, m: $mass, k: $stiffness, c: $damping, x0: 0.05, v0: 0.1}
  spare: {type: source.constant, value: 1.0}
connections:
  - force.y -> body.f
)";

class Subsystems : public test::SceneErrorTest {
 protected:
  Subsystems() : SceneErrorTest("dydp_subsystems_") {}

  /// A scene around one instance `osc` of the oscillator in sub/oscillator.yaml.
  std::string scene_with(const std::string& instance, const std::string& oscillator = kOscillator,
                         const std::string& outputs = "[osc.position, osc.body.v, x_rms]") const {
    put("sub/oscillator.yaml", oscillator);
    return put("s.yaml", R"(scene: t
time: {start: 0.0, stop: 10.0, output_step: 0.01}
solver: {method: bdf, rtol: 1.0e-10, atol: 1.0e-12}
parameters:
  mass: {value: 1.5, unit: kg}
  stiffness: {value: 40.0, unit: N/m}
sensitivities: [mass, stiffness]
subsystems:
  oscillator: {file: sub/oscillator.yaml}
blocks:
  )" + instance + R"(
  x_rms: {type: objective.rms, window: [2.0, 10.0]}
connections:
  - osc.position -> x_rms.in
outputs: )" + outputs + "\n");
  }
};

test::MsdParams<double> msd() { return {1.5, 40.0, 1.2, 2.0, 2 * std::numbers::pi * 0.8, 0.05, 0.1}; }

// ---------------------------------------------------------------- flattening and values

TEST_F(Subsystems, InstanceIsFlattenedWithPrefixedNamesAndPruned) {
  const Diagram d = load_scene(scene_with("osc: {type: subsystem.oscillator, mass: $mass, stiffness: $stiffness}"));
  std::vector<std::string> names;
  for (const Node& n : d.nodes) names.push_back(n.name);
  EXPECT_EQ(names, (std::vector<std::string>{"osc.force", "osc.body", "x_rms"}));
  EXPECT_EQ(d.pruned, (std::vector<std::string>{"osc.spare"}));
  ASSERT_EQ(d.logged.size(), 2u);
  EXPECT_EQ(d.logged[0].name, "osc.position");  // an output port keeps the name it was asked by
  EXPECT_EQ(d.logged[1].name, "osc.body.v");
  // The body's parameters: m and k driven by the scene parameters, c the subsystem's default.
  const Node& body = d.nodes[1];
  EXPECT_EQ(body.p_scene[0], d.find_parameter("mass"));
  EXPECT_EQ(body.p_scene[1], d.find_parameter("stiffness"));
  EXPECT_EQ(body.p_scene[2], -1);
  EXPECT_DOUBLE_EQ(body.p[2], 1.2);
  EXPECT_EQ(body.file, (dir_ / "sub/oscillator.yaml").string());
}

// Sensitivities through the boundary: x(t), dx/dm and dx/dk of the instance's body against the
// closed form differentiated by complex step.
TEST_F(Subsystems, SensitivitiesCrossTheBoundaryAsTheClosedFormSays) {
  const Diagram d = load_scene(scene_with("osc: {type: subsystem.oscillator, mass: $mass, stiffness: $stiffness}"));
  const RunResult r = run(d);
  const int ix = r.signal_index("osc.position");
  ASSERT_GE(ix, 0);
  double err_x = 0, err_m = 0, err_k = 0, scale_x = 0, scale_m = 0, scale_k = 0;
  for (size_t k = 0; k < r.t.size(); ++k) {
    const double t = r.t[k];
    const auto x = [t](const test::MsdParams<std::complex<double>>& z) { return test::msd_position(z, t); };
    const double x_ref = test::msd_position(msd(), t);
    const double dm = test::complex_step(x, msd(), 0), dk = test::complex_step(x, msd(), 1);
    const int i = static_cast<int>(k);
    err_x = std::max(err_x, std::fabs(r.value(i, ix) - x_ref)), scale_x = std::max(scale_x, std::fabs(x_ref));
    err_m = std::max(err_m, std::fabs(r.tangent(i, 0, ix) - dm)), scale_m = std::max(scale_m, std::fabs(dm));
    err_k = std::max(err_k, std::fabs(r.tangent(i, 1, ix) - dk)), scale_k = std::max(scale_k, std::fabs(dk));
  }
  EXPECT_LT(err_x / scale_x, 1e-6);
  EXPECT_LT(err_m / scale_m, 1e-5);
  EXPECT_LT(err_k / scale_k, 1e-5);
  ASSERT_EQ(r.objectives.size(), 1u);
  EXPECT_NE(r.objectives[0].sensitivity[0], 0.0);
}

// An inline subsystem holding an instance of the file's subsystem, its parameter passed on with
// `$`: names nest (`pair.osc.body`) and the scene parameter still reaches the body.
TEST_F(Subsystems, NestedInstancesPassParametersOn) {
  put("sub/oscillator.yaml", kOscillator);
  const Diagram d = load_scene(put("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
parameters:
  mass: {value: 2.5, unit: kg}
sensitivities: [mass]
subsystems:
  oscillator: {file: sub/oscillator.yaml}
  pair:
    parameters: {m: {unit: kg}}
    outputs: {x: osc.position}
    blocks:
      osc: {type: subsystem.oscillator, mass: $m}
blocks:
  pair: {type: subsystem.pair, m: $mass}
outputs: [pair.x, pair.osc.body.v, pair.osc]
)"));
  const auto body = std::find_if(d.nodes.begin(), d.nodes.end(), [](const Node& n) { return n.name == "pair.osc.body"; });
  ASSERT_NE(body, d.nodes.end());
  EXPECT_EQ(body->p_scene[0], d.find_parameter("mass"));
  EXPECT_DOUBLE_EQ(body->p[0], 2.5);
  std::vector<std::string> logged;
  for (const auto& s : d.logged) logged.push_back(s.name);
  EXPECT_EQ(logged, (std::vector<std::string>{"pair.x", "pair.osc.body.v", "pair.osc.position"}));
  // The instance's parameter line: where `$mass` was written (the scene, line 14).
  EXPECT_EQ(body->p_line[0], 14);
  EXPECT_EQ(body->parameter_file(0, d.file), d.file);
}

// A setting inside a subsystem takes the instance's value (`indices: [$pad]`), and a subsystem
// input port may drive several internal inputs.
TEST_F(Subsystems, SettingsTakeTheInstanceValueAndInputsFanOut) {
  const Diagram d = load_scene(put("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
subsystems:
  pick:
    parameters: {element: {}}
    inputs: {u: [a.u, b.u]}
    outputs: {a: a.y, b: b.y}
    blocks:
      a: {type: math.demux, width: 3, indices: [$element]}
      b: {type: math.demux, width: 3, indices: [0]}
blocks:
  v: {type: source.constant, value: 0.0}
  m: {type: math.mux, inputs: 3}
  s2: {type: source.constant, value: 7.0}
  p: {type: subsystem.pick, element: 2}
connections:
  - v.y -> m.in1
  - v.y -> m.in2
  - s2.y -> m.in3
  - m.y -> p.u
outputs: [p.a, p.b]
)"));
  const RunResult r = run(d);
  EXPECT_NEAR(r.value(0, r.signal_index("p.a")), 7.0, 1e-12);  // element 2 of [0, 0, 7]
  EXPECT_NEAR(r.value(0, r.signal_index("p.b")), 0.0, 1e-12);
}

// ---------------------------------------------------------------- errors where they are written

TEST_F(Subsystems, UnknownBlockTypeInsideTheSubsystemFile) {
  std::string osc = kOscillator;
  osc.replace(osc.find("type: source.constant"), 21, "type: source.konstant");
  const auto e = load_error(scene_with("osc: {type: subsystem.oscillator, mass: $mass}", osc));
  expect_error(e, (dir_ / "sub/oscillator.yaml").string(), 12, "osc.spare.type", "unknown block type 'source.konstant'");
}

TEST_F(Subsystems, KeyGivenTwiceInsideTheSubsystemFile) {
  std::string osc = kOscillator;
  osc.replace(osc.find("frequency: 0.8}"), 15, "frequency: 0.8, frequency: 0.9}");
  const auto e = load_error(scene_with("osc: {type: subsystem.oscillator, mass: $mass}", osc));
  expect_error(e, (dir_ / "sub/oscillator.yaml").string(), 10, "force.frequency", "key given twice");
}

// Inline, a block written twice in a definition reads like one written twice in the scene.
TEST_F(Subsystems, BlockGivenTwiceInAnInlineDefinition) {
  const auto e = load_error(put("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
subsystems:
  pair:
    outputs: {y: g.y}
    blocks:
      g: {type: source.constant, value: 1.0}
      g: {type: source.constant, value: 2.0}
blocks:
  p: {type: subsystem.pair}
outputs: [p.y]
)"));
  expect_error(e, (dir_ / "s.yaml").string(), 8, "g", "block defined twice (first at line 7)");
}

TEST_F(Subsystems, OutputPortNamingAMissingPortInsideTheSubsystem) {
  std::string osc = kOscillator;
  osc.replace(osc.find("position: body.x"), 16, "position: body.q");
  const auto e = load_error(scene_with("osc: {type: subsystem.oscillator, mass: $mass}", osc));
  expect_error(e, (dir_ / "sub/oscillator.yaml").string(), 8, "osc.body.q", "has no output port 'q'");
}

TEST_F(Subsystems, ConnectionInsideTheSubsystemToAnUnknownPort) {
  std::string osc = kOscillator;
  osc.replace(osc.find("force.y -> body.f"), 17, "force.y -> body.g");
  const auto e = load_error(scene_with("osc: {type: subsystem.oscillator, mass: $mass}", osc));
  expect_error(e, (dir_ / "sub/oscillator.yaml").string(), 14, "osc.body.g", "has no input port 'g'");
}

// An end without its port name inside the subsystem file, in a connection or in an output
// port's mapping, is refused where it is written (the scene fuzzer found the connection case
// in a scene: docs/fuzzing.md).
TEST_F(Subsystems, PortWithoutItsNameInsideTheSubsystem) {
  std::string wire = kOscillator;
  wire.replace(wire.find("force.y -> body.f"), 17, "force.y -> body.");
  expect_error(load_error(scene_with("osc: {type: subsystem.oscillator, mass: $mass}", wire)),
               (dir_ / "sub/oscillator.yaml").string(), 14, "connections", "both ends need block.port, got 'force.y -> body.'");
  std::string shown = kOscillator;
  shown.replace(shown.find("position: body.x"), 16, "position: body.");
  expect_error(load_error(scene_with("osc: {type: subsystem.oscillator, mass: $mass}", shown)),
               (dir_ / "sub/oscillator.yaml").string(), 8, "outputs.position", "expected an internal 'block.port', got 'body.'");
}

TEST_F(Subsystems, UnknownSubsystemParameterInsideTheFile) {
  std::string osc = kOscillator;
  osc.replace(osc.find("c: $damping"), 11, "c: $dampin");
  const auto e = load_error(scene_with("osc: {type: subsystem.oscillator, mass: $mass}", osc));
  expect_error(e, (dir_ / "sub/oscillator.yaml").string(), 11, "osc.body.c", "unknown parameter '$dampin'");
}

// A bad value given at the instance is the scene's line; a bad default, the subsystem's.
TEST_F(Subsystems, ValueOutOfBoundsIsNamedWhereItIsWritten) {
  expect_error(load_error(scene_with("osc: {type: subsystem.oscillator, mass: -1.0}")),
               (dir_ / "s.yaml").string(), 11, "osc.body.m", "outside");
  std::string osc = kOscillator;
  osc.replace(osc.find("damping: {value: 1.2"), 20, "damping: {value: -3.0");
  expect_error(load_error(scene_with("osc: {type: subsystem.oscillator, mass: $mass}", osc)),
               (dir_ / "sub/oscillator.yaml").string(), 5, "osc.body.c", "outside");
  expect_error(load_error(scene_with("osc: {type: subsystem.oscillator, mass: 1.0e-320}")),
               (dir_ / "s.yaml").string(), 11, "osc.mass", "underflows");
}

TEST_F(Subsystems, InstanceErrorsAreTheScenesLines) {
  expect_error(load_error(scene_with("osc: {type: subsystem.oscillator}")), (dir_ / "s.yaml").string(), 11,
               "osc.mass", "required parameter of subsystem oscillator is missing");
  expect_error(load_error(scene_with("osc: {type: subsystem.oscillator, mass: $mass, mas: 1.0}")),
               (dir_ / "s.yaml").string(), 11, "osc.mas", "unknown parameter of subsystem.oscillator");
  expect_error(load_error(scene_with("osc: {type: subsystem.oscilator, mass: $mass}")),
               (dir_ / "s.yaml").string(), 11, "osc.type", "unknown subsystem 'oscilator' (defined: oscillator)");
  expect_error(load_error(scene_with("osc: {type: subsystem.oscillator, mass: $mas}")),
               (dir_ / "s.yaml").string(), 11, "osc.mass", "unknown scene parameter '$mas'");
  expect_error(load_error(scene_with("osc: {type: subsystem.oscillator, mass: $mass}", kOscillator,
                                     "[osc.velocity]")),
               (dir_ / "s.yaml").string(), 15, "osc.velocity", "has no output port or block 'velocity'");
}

TEST_F(Subsystems, ConnectionToAMissingInstancePort) {
  put("sub/oscillator.yaml", kOscillator);
  put("s2.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
subsystems:
  oscillator: {file: sub/oscillator.yaml}
blocks:
  osc: {type: subsystem.oscillator, mass: 1.0}
  x_rms: {type: objective.rms, window: [0.5, 1.0]}
connections:
  - osc.x -> x_rms.in
outputs: [x_rms]
)");
  expect_error(load_error((dir_ / "s2.yaml").string()), (dir_ / "s2.yaml").string(), 9, "osc.x",
               "subsystem instance 'osc' (subsystem.oscillator) has no output port 'x' (outputs: position)");
}

TEST_F(Subsystems, UnconnectedInstanceInputIsTheInstancesLine) {
  const auto e = load_error(put("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
subsystems:
  gain2:
    inputs: {u: g.u}
    outputs: {y: g.y}
    blocks:
      g: {type: math.gain, k: 2.0}
blocks:
  twice: {type: subsystem.gain2}
outputs: [twice.y]
)"));
  expect_error(e, (dir_ / "s.yaml").string(), 10, "twice.u", "input is not connected");
}

TEST_F(Subsystems, MissingSubsystemFileIsTheIncludingLine) {
  const auto e = load_error(put("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
subsystems:
  corner: {file: corners/missing.yaml}
blocks:
  c: {type: subsystem.corner}
outputs: [c]
)"));
  expect_error(e, (dir_ / "s.yaml").string(), 4, "subsystems.corner.file", "cannot open the subsystem file");
}

TEST_F(Subsystems, SubsystemContainingItselfIsRefused) {
  const auto e = load_error(put("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
subsystems:
  loop:
    outputs: {y: inner.y}
    blocks:
      inner: {type: subsystem.loop}
blocks:
  l: {type: subsystem.loop}
outputs: [l.y]
)"));
  expect_error(e, (dir_ / "s.yaml").string(), 7, "l.inner.type", "contains itself (loop -> loop)");
}

// A consistency rule broken by values from two places: named at the value the rule names, in
// the scene, where the instance gave it.
TEST_F(Subsystems, BlockRuleBrokenByAnInstanceValue) {
  put("sub/damper.yaml", R"(subsystem: strut
parameters:
  rod: {value: 0.02, unit: m}
inputs: {x: d.stroke, v: d.stroke_rate}
outputs: {f: d.force}
blocks:
  d: {type: damper.cdc, rod_diameter: $rod}
)");
  const auto e = load_error(put("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
subsystems:
  strut: {file: sub/damper.yaml}
blocks:
  zero: {type: source.constant, value: 0.0}
  s: {type: subsystem.strut,
      rod: 0.5}
connections:
  - zero.y -> s.x
  - zero.y -> s.v
outputs: [s.f]
)"));
  expect_error(e, (dir_ / "s.yaml").string(), 8, "s.d.rod_diameter", "");
}

TEST_F(Subsystems, AlgebraicLoopInsideTheSubsystemFile) {
  put("sub/loop.yaml", R"(subsystem: loop
outputs: {y: a.y}
blocks:
  a: {type: math.gain, k: 2.0}
  b: {type: math.gain, k: 0.5}
connections:
  - a.y -> b.u
  - b.y -> a.u
)");
  const auto e = load_error(put("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
subsystems:
  loop: {file: sub/loop.yaml}
blocks:
  l: {type: subsystem.loop}
outputs: [l.y]
)"));
  expect_error(e, (dir_ / "sub/loop.yaml").string(), 7, "connections", "algebraic loop");
}

// Changing a scene parameter checks the bounds of the block parameters it drives inside an
// instance, and names the instance's value.
TEST_F(Subsystems, SetParameterChecksInsideInstances) {
  Diagram d = load_scene(scene_with("osc: {type: subsystem.oscillator, mass: $mass, stiffness: $stiffness}"));
  try {
    d.set_parameter(d.find_parameter("mass"), -2.0, false);
    ADD_FAILURE() << "a negative mass was accepted";
  } catch (const InputError& e) {
    expect_error(e, (dir_ / "s.yaml").string(), 11, "osc.body.m", "(from $mass) outside its bounds");
  }
}

}  // namespace
}  // namespace dydp::engine
