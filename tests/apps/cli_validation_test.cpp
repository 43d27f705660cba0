// Issue 17 through the program: a scene or a command-line value that makes no sense exits 2
// with `file:line: field: message` on stderr and writes nothing; legal but probably unintended
// input is printed as a warning and recorded in run.json `warnings`.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/apps/dydp_process.hpp"
#include "tests/temp_folder_test.hpp"

namespace {

namespace fs = std::filesystem;
using dydp::test::entries;
using dydp::test::quote;
using nlohmann::json;

class CliValidation : public dydp::test::TempFolderTest {
 protected:
  CliValidation() : TempFolderTest("dydp_cli_validation_") {}

  dydp::test::ProcessResult dydp(const std::string& args) const {
    return dydp::test::run_process(DYDP_EXE, args, dir_);
  }
  /// Runs `dydp ARGS --out OUT` and expects exit 2, stderr starting with `prefix`, OUT empty.
  void expect_refused(const std::string& args, const std::string& prefix) const {
    const fs::path out = dir_ / "out";
    const auto r = dydp(args + " --out " + quote(out.string()));
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(r.err.rfind(prefix, 0), 0u) << "expected '" << prefix << "' in: " << r.err;
    EXPECT_TRUE(entries(out).empty()) << "something was written to " << out;
  }

  static std::string msd_scene() {
    return (fs::path(DYDP_SOURCE_DIR) / "scenarios" / "msd_sensitivity.yaml").string();
  }
};

TEST_F(CliValidation, DuplicateKeyExitsTwoNamingBothLines) {
  const std::string scene = write("dup.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine, frequency: 1.0, frequency: 2.0}
outputs: [src.y]
)");
  expect_refused("run " + quote(scene), scene + ":4: src.frequency: key given twice (first at line 4)");
}

TEST_F(CliValidation, RelationBetweenFieldsExitsTwo) {
  const std::string scene = write("rel.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
solver: {method: rk4, step: 0.0}
blocks:
  src: {type: source.sine}
outputs: [src.y]
)");
  expect_refused("run " + quote(scene), scene + ":3: solver.step: must be positive");
}

TEST_F(CliValidation, BadInitialSectionExitsTwo) {
  const std::string typo = write("typo.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
initial: equilibrum
blocks:
  src: {type: source.sine}
outputs: [src.y]
)");
  expect_refused("run " + quote(typo), typo + ":3: initial: unknown value 'equilibrum' (equilibrium, declared)");
  const std::string hold = write("hold.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
initial:
  state: equilibrium
  hold: {src.x: 0.0}
blocks:
  src: {type: source.sine}
outputs: [src.y]
)");
  expect_refused("run " + quote(hold), hold + ":5: initial.hold.src.x: block src has no output x (its outputs: y)");
  // A constant force on a mass without spring: no equilibrium, refused before anything is run.
  const std::string falling = write("falling.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
initial: equilibrium
blocks:
  m: {type: mass_spring_damper, k: 0.0}
  f: {type: source.constant, value: 1.0}
connections: [f.y -> m.f]
outputs: [m.x]
)");
  expect_refused("run " + quote(falling), falling + ":3: initial: equilibrium: t = 0 s: block m: no equilibrium in reach");
}

TEST_F(CliValidation, SceneThatIsAFolderExitsTwoNamingIt) {
  const fs::path folder = dir_ / "scenes";
  fs::create_directories(folder);
  expect_refused("run " + quote(folder.string()), folder.string() + ": is a folder, not a scene file");
}

TEST_F(CliValidation, SweepOfOnePointOverARangeExitsTwo) {
  expect_refused("sweep " + quote(msd_scene()) + " --param damping --range 1:3:1",
                 "--range: 1:3:1: N = 1 with LO < HI");
}

TEST_F(CliValidation, SweepWithANegativeDeltaExitsTwo) {
  expect_refused("sweep " + quote(msd_scene()) + " --param damping --range 1:3:3 --delta -5",
                 "--delta: -5: must be positive");
}

TEST_F(CliValidation, AccuracyTargetOfZeroOrBelowExitsTwo) {
  expect_refused("accuracy " + quote(msd_scene()) + " --target 0", "--target: 0: outside (0, 1)");
  expect_refused("accuracy " + quote(msd_scene()) + " --target -1e-3", "--target: -0.001: outside (0, 1)");
  expect_refused("accuracy " + quote(msd_scene()) + " --target 1", "--target: 1: outside (0, 1)");
}

TEST_F(CliValidation, DamperRodWiderThanPistonExitsTwo) {
  const std::string scene = write("damper.yaml", R"(scene: t
time: {stop: 0.1, output_step: 0.01}
blocks:
  stroke: {type: source.constant}
  rate: {type: source.constant}
  d: {type: damper.cdc, piston_diameter: 0.030, rod_diameter: 0.035}
connections:
  - stroke.y -> d.stroke
  - rate.y -> d.stroke_rate
outputs: [d.force]
)");
  expect_refused("run " + quote(scene), scene + ":6: d.rod_diameter: rod 0.035 m is not narrower");
}

TEST_F(CliValidation, BlocksPrintsTheirRules) {
  const auto r = dydp("blocks");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("    check   rod_diameter < piston_diameter\n"), std::string::npos);
  EXPECT_NE(r.out.find("    check   noise_low <= noise_high\n"), std::string::npos);
  EXPECT_NE(r.out.find("    check   window overlaps [time.start, time.stop]\n"), std::string::npos);
}

TEST_F(CliValidation, ReplayOfARecordingThatEndsEarlyWarnsAndRecordsIt) {
  const std::string scene = write("rig.yaml", R"(scene: rig
time: {stop: 1.0, output_step: 0.01}
blocks:
  rig: {type: road.fourposter}
outputs: [rig.z]
)");
  const std::string recording = write("bench.csv", "t,fl,fr,rl,rr\n0,0,0,0,0\n0.5,0.01,0,0,0\n");
  const fs::path out = dir_ / "out";
  const auto r = dydp("replay " + quote(scene) + " --input " + quote(recording) + " --no-sens --out " +
                      quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string warning = scene + ":4: rig.input_file: the recording ends at 0.5 s";
  EXPECT_NE(r.err.find("warning: " + warning), std::string::npos) << r.err;
  const json run = json::parse(dydp::test::read_text(out / "run.json"));
  ASSERT_EQ(run["warnings"].size(), 1u) << run.dump();
  EXPECT_EQ(run["warnings"][0].get<std::string>().rfind(warning, 0), 0u) << run.dump();
}

}  // namespace
