// Scene validation beyond single values (issue 17): keys given twice, relations between the
// fields of the time and solver sections, each block's consistency rules (engine/framework/block_check.hpp)
// and the warnings for legal but probably unintended input. Every refusal is an InputError
// naming file, line and field; loading writes nothing, so a refused scene leaves nothing behind.
//
// Each scene is a raw string literal whose first line is line 1 of the file.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "engine/analysis/run.hpp"
#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"
#include "engine/scene/consistency_checks.hpp"
#include "io/csv.hpp"
#include "tests/temp_folder_test.hpp"

namespace dydp::engine {
namespace {

namespace fs = std::filesystem;

class SceneRelations : public test::TempFolderTest {
 protected:
  SceneRelations() : TempFolderTest("dydp_scene_relations_") {}

  /// Loads the scene, expects an InputError with this file, line, field and phrase, and checks
  /// that the folder holds nothing but what the test wrote.
  void expect_refused(const std::string& path, int line, const std::string& field,
                      const std::string& phrase) const {
    const auto before = count_entries();
    try {
      load_scene(path);
      ADD_FAILURE() << path << " loaded without an InputError";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(e.file(), path) << what;
      EXPECT_EQ(e.line(), line) << what;
      EXPECT_EQ(e.field(), field) << what;
      EXPECT_NE(what.find(phrase), std::string::npos) << "'" << phrase << "' not in: " << what;
      const std::string prefix =
          (line > 0 ? path + ":" + std::to_string(line) : path) + ": " + (field.empty() ? "" : field + ": ");
      EXPECT_EQ(what.rfind(prefix, 0), 0u) << "expected prefix '" << prefix << "' in: " << what;
    }
    EXPECT_EQ(count_entries(), before) << "loading wrote into " << dir_;
  }

  size_t count_entries() const {
    size_t n = 0;
    for (const auto& e : fs::recursive_directory_iterator(dir_)) n += e.exists() ? 1 : 0;
    return n;
  }

  /// A valid one-block scene with `time` and `solver` lines substituted (lines 2 and 3).
  std::string scene(const std::string& time, const std::string& solver) const {
    return write("s.yaml", "scene: t\n" + time + "\n" + solver + R"(
blocks:
  src: {type: source.sine, frequency: 1.0}
outputs: [src.y]
)");
  }
};

// ---------------------------------------------------------------- keys given twice

TEST_F(SceneRelations, TopLevelKeyGivenTwiceNamesBothLines) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
time: {stop: 2.0, output_step: 0.1}
outputs: [src.y]
)");
  expect_refused(path, 5, "time", "key given twice (first at line 2)");
}

TEST_F(SceneRelations, KeyGivenTwiceInsideABlock) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
  g:
    type: math.gain
    k: 2.0
    k: 3.0
connections:
  - src.y -> g.u
outputs: [g.y]
)");
  expect_refused(path, 8, "g.k", "key given twice (first at line 7)");
}

TEST_F(SceneRelations, KeyGivenTwiceInAFlowMapping) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1, stop: 5.0}
blocks:
  src: {type: source.sine}
outputs: [src.y]
)");
  expect_refused(path, 2, "time.stop", "key given twice (first at line 2)");
}

TEST_F(SceneRelations, SceneParameterGivenTwice) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
parameters:
  gain_k: {value: 2.0}
  gain_k: {value: 3.0}
blocks:
  src: {type: source.sine, amplitude: $gain_k}
outputs: [src.y]
)");
  expect_refused(path, 5, "parameters.gain_k", "key given twice (first at line 4)");
}

TEST_F(SceneRelations, KeyGivenTwiceInAParameterBody) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
parameters:
  gain_k:
    value: 2.0
    value: 3.0
blocks:
  src: {type: source.sine, amplitude: $gain_k}
outputs: [src.y]
)");
  expect_refused(path, 6, "parameters.gain_k.value", "key given twice (first at line 5)");
}

TEST_F(SceneRelations, AnAliasIsNotAKeyGivenTwice) {
  // `*sine` is the anchored mapping again: walked once, and two blocks are made from it.
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  a: &sine {type: source.sine, frequency: 1.0}
  b: *sine
outputs: [a.y, b.y]
)");
  EXPECT_EQ(load_scene(path).nodes.size(), 2u);
}

// ---------------------------------------------------------------- the run's time span

TEST_F(SceneRelations, OutputStepLongerThanTheRun) {
  const std::string path = scene("time: {stop: 1.0,\n  output_step: 2.0}", "solver: {method: bdf}");
  expect_refused(path, 3, "time.output_step", "longer than the run");
}

TEST_F(SceneRelations, OutputGridThatWouldOverflow) {
  const std::string path = scene("time: {stop: 1.0, output_step: 1.0e-12}", "solver: {method: bdf}");
  expect_refused(path, 2, "time.output_step", "more than 1e+07");
}

TEST_F(SceneRelations, AbsurdStopTime) {
  const std::string path = scene("time: {stop: 1.0e308, output_step: 1.0e307}", "solver: {method: bdf}");
  expect_refused(path, 2, "time.stop", "outside [-1e+06, 1e+06] s");
}

TEST_F(SceneRelations, AbsurdStartTime) {
  const std::string path = scene("time: {start: -1.0e300, stop: 1.0, output_step: 0.1}", "solver: {method: bdf}");
  expect_refused(path, 2, "time.start", "outside [-1e+06, 1e+06] s");
}

// ---------------------------------------------------------------- solver settings

TEST_F(SceneRelations, RelativeToleranceOfOne) {
  const std::string path = scene("time: {stop: 1.0, output_step: 0.1}", "solver: {method: bdf, rtol: 1.0}");
  expect_refused(path, 3, "solver.rtol", "must be below 1");
}

TEST_F(SceneRelations, AbsoluteToleranceAboveOne) {
  const std::string path = scene("time: {stop: 1.0, output_step: 0.1}", "solver: {method: bdf, atol: 5.0}");
  expect_refused(path, 3, "solver.atol", "must be below 1");
}

TEST_F(SceneRelations, FixedStepOfZeroIsNotReplaced) {
  const std::string path = scene("time: {stop: 1.0, output_step: 0.1}", "solver: {method: rk4, step: 0}");
  expect_refused(path, 3, "solver.step", "must be positive");
}

TEST_F(SceneRelations, DenormalFixedStep) {
  const std::string path = scene("time: {stop: 1.0, output_step: 0.1}", "solver: {method: rk4, step: 4.0e-320}");
  expect_refused(path, 3, "solver.step", "denormal");
}

TEST_F(SceneRelations, FixedStepGivingTooManySteps) {
  const std::string path = scene("time: {stop: 1.0, output_step: 0.1}", "solver: {method: rk4, step: 1.0e-300}");
  expect_refused(path, 3, "solver.step", "more than 1e+09");
}

TEST_F(SceneRelations, NegativeStepLimit) {
  const std::string path = scene("time: {stop: 1.0, output_step: 0.1}", "solver: {method: bdf, max_steps: -5}");
  expect_refused(path, 3, "solver.max_steps", "whole number in [1, 1e+09]");
}

TEST_F(SceneRelations, StepLimitTooLargeForAnInteger) {
  const std::string path = scene("time: {stop: 1.0, output_step: 0.1}", "solver: {method: bdf, max_steps: 1.0e308}");
  expect_refused(path, 3, "solver.max_steps", "whole number");
}

TEST_F(SceneRelations, MinimumStepNotBelowTheOutputStep) {
  const std::string path = scene("time: {stop: 1.0, output_step: 0.1}", "solver: {method: bdf, min_step: 0.5}");
  expect_refused(path, 3, "solver.min_step", "must be below time.output_step");
}

// ---------------------------------------------------------------- files

TEST_F(SceneRelations, SceneThatIsAFolder) {
  const fs::path folder = dir_ / "scene.yaml";
  fs::create_directories(folder);
  expect_refused(folder.string(), 0, "", "is a folder, not a scene file");
}

TEST_F(SceneRelations, CsvFileThatIsAFolder) {
  const fs::path folder = dir_ / "bench.csv";
  fs::create_directories(folder);
  try {
    io::read_csv(folder.string());
    ADD_FAILURE() << "a folder read as a CSV file";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), folder.string());
    EXPECT_EQ(std::string(e.what()), folder.string() + ": is a folder, not a CSV file");
  }
}

// ---------------------------------------------------------------- block consistency rules

TEST_F(SceneRelations, ObjectiveWindowOutsideTheRun) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
  obj:
    type: objective.rms
    window: [5.0, 6.0]
connections:
  - src.y -> obj.in
outputs: [obj]
)");
  expect_refused(path, 7, "obj.window", "outside the run");
}

TEST_F(SceneRelations, SlipAngleWindowBeforeTheRun) {
  const std::string path = write("s.yaml", R"(scene: t
time: {start: 2.0, stop: 3.0, output_step: 0.1}
blocks:
  beta: {type: objective.slip_angle, window: [0.0, 1.0]}
outputs: [beta]
)");
  expect_refused(path, 4, "beta.window", "outside the run");
}

TEST_F(SceneRelations, NoiseBandLowAboveHigh) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  rig:
    type: road.fourposter
    noise_low: 30.0
    noise_high: 20.0
outputs: [rig.z]
)");
  expect_refused(path, 6, "rig.noise_low", "noise band [30, 20] Hz");
}

TEST_F(SceneRelations, DamperRodWiderThanItsPiston) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.01}
blocks:
  stroke: {type: source.constant}
  rate: {type: source.constant}
  d:
    type: damper.cdc
    piston_diameter: 0.030
    rod_diameter: 0.040
connections:
  - stroke.y -> d.stroke
  - rate.y -> d.stroke_rate
outputs: [d.force]
)");
  expect_refused(path, 9, "d.rod_diameter", "not narrower than the piston");
}

TEST_F(SceneRelations, DamperRodOfTheDefaultWidthAgainstANarrowPiston) {
  // The rod keeps its default (0.020 m): the rule is reported at the block's line.
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.01}
blocks:
  stroke: {type: source.constant}
  rate: {type: source.constant}
  d: {type: damper.cdc, piston_diameter: 0.015}
connections:
  - stroke.y -> d.stroke
  - rate.y -> d.stroke_rate
outputs: [d.force]
)");
  expect_refused(path, 6, "d.rod_diameter", "not narrower than the piston");
}

TEST_F(SceneRelations, SceneParameterCannotLaterBreakARule) {
  // A sweep sets the scene parameter: a value that makes the rod wider than the piston is
  // refused like the same value written in the scene, and nothing is changed.
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.01}
parameters:
  rod: {value: 0.020, range: [0.010, 0.050]}
blocks:
  stroke: {type: source.constant}
  rate: {type: source.constant}
  d:
    type: damper.cdc
    rod_diameter: $rod
connections:
  - stroke.y -> d.stroke
  - rate.y -> d.stroke_rate
outputs: [d.force]
)");
  Diagram d = load_scene(path);
  try {
    d.set_parameter(d.find_parameter("rod"), 0.040);
    ADD_FAILURE() << "no InputError for a rod wider than the piston";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.line(), 10) << e.what();
    EXPECT_EQ(e.field(), "d.rod_diameter") << e.what();
  }
  EXPECT_EQ(d.parameters[d.find_parameter("rod")].value, 0.020);
  EXPECT_EQ(d.nodes[2].p[5], 0.020);
}

TEST_F(SceneRelations, BlocksDeclareTheirRules) {
  const BlockType* damper = Registry::global().find("damper.cdc");
  ASSERT_NE(damper, nullptr);
  const std::vector<std::string> rules = check_rules(*damper);
  ASSERT_EQ(rules.size(), 1u);
  EXPECT_EQ(rules[0], "rod_diameter < piston_diameter");
  const BlockType* rms = Registry::global().find("objective.rms");
  ASSERT_NE(rms, nullptr);
  EXPECT_EQ(check_rules(*rms).size(), 3u);
}

// ---------------------------------------------------------------- bounds as the rule states them

TEST_F(SceneRelations, BoundsPrintAsTheRuleStatesThem) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine, frequency: -1.0e-12}
outputs: [src.y]
)");
  expect_refused(path, 4, "src.frequency", "value -1e-12 outside [0, inf] Hz");
}

// ---------------------------------------------------------------- warnings

TEST_F(SceneRelations, WindowInsideTheInitialTransientIsAWarningInRunJson) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
  obj: {type: objective.rms,
        window: [0.05, 1.0]}
connections:
  - src.y -> obj.in
outputs: [obj]
)");
  const Diagram d = load_scene(path);
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_EQ(d.warnings[0].rfind(path + ":6: obj.window: ", 0), 0u) << d.warnings[0];
  EXPECT_NE(d.warnings[0].find("initial transient"), std::string::npos) << d.warnings[0];
  const RunResult r = run(d);
  ASSERT_EQ(r.stats.warnings.size(), 1u);
  EXPECT_EQ(r.stats.warnings[0], d.warnings[0]);
}

TEST_F(SceneRelations, SettledWindowGivesNoWarning) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
  obj: {type: objective.rms, window: [0.1, 1.0]}
connections:
  - src.y -> obj.in
outputs: [obj]
)");
  EXPECT_TRUE(load_scene(path).warnings.empty());
}

TEST_F(SceneRelations, RecordingThatEndsEarlyIsAWarning) {
  write("road.csv", "t,z\n0.0,0.0\n0.5,0.01\n");
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  road:
    type: source.table
    file: road.csv
    column: z
outputs: [road.y]
)");
  const Diagram d = load_scene(path);
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_EQ(d.warnings[0].rfind(path + ":6: road.file: ", 0), 0u) << d.warnings[0];
  EXPECT_NE(d.warnings[0].find("ends at 0.5 s, before time.stop = 1 s"), std::string::npos) << d.warnings[0];
}

TEST_F(SceneRelations, ReplayRecordingThatEndsEarlyIsAWarning) {
  const std::string csv = write("bench.csv", "t,fl,fr,rl,rr\n0,0,0,0,0\n0.4,0,0,0,0\n");
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  rig: {type: road.fourposter}
outputs: [rig.z]
)");
  const Diagram d = load_scene(path, {}, {{"input_file", csv}});
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_EQ(d.warnings[0].rfind(path + ":4: rig.input_file: ", 0), 0u) << d.warnings[0];
  EXPECT_NE(d.warnings[0].find("ends at 0.4 s"), std::string::npos) << d.warnings[0];
}

TEST_F(SceneRelations, ShippedScenesLoadWithoutWarnings) {
  // The rules must not fire on the scenes users start from (the stress scenes among them);
  // cli_run_test's EveryScenarioRuns runs them.
  int count = 0;
  for (const auto& e : fs::recursive_directory_iterator(fs::path(DYDP_SOURCE_DIR) / "scenarios")) {
    // scenarios/subsystems/ holds the subsystems the scenes include, not scenes.
    if (e.path().extension() != ".yaml" || e.path().parent_path().filename() == "subsystems") continue;
    SCOPED_TRACE(e.path().string());
    const Diagram d = load_scene(e.path().string());
    EXPECT_TRUE(d.warnings.empty()) << d.warnings.front();
    ++count;
  }
  EXPECT_GE(count, 15);
}

}  // namespace
}  // namespace dydp::engine
