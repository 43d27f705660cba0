// The graph checks that accept good scenes: blocks no output needs are pruned and what they feed
// kept, the evaluation order follows feedthrough, loops broken by a state are accepted (a loop
// through a feedthrough output is not), logged signals of wide outputs, and scene parameters
// driving block parameters (set_parameter propagates, checks bounds, and a refusal changes nothing).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"
#include "tests/engine/scene/scene_validation.hpp"

namespace dydp::engine {
namespace {

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
