// --solver, --rtol, --atol, --step on run, sweep, replay and accuracy: each command with the
// options gives what the same command gives on the scene with those values written into its
// solver section (the loader's path, independent of the options'), and a value the scene
// would refuse is refused naming the option, exit 2, nothing written.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/apps/dydp_process.hpp"

namespace {

namespace fs = std::filesystem;
using dydp::test::entries;
using dydp::test::quote;
using dydp::test::read_text;
using nlohmann::json;

class SolverOptions : public dydp::test::DydpProcessTest {
 protected:
  SolverOptions() : DydpProcessTest("dydp_solver_options_") {}

  static std::string msd_text() { return read_text(dydp::test::source_path("scenarios/msd_sensitivity.yaml")); }
  static std::string msd_path() { return dydp::test::source_path("scenarios/msd_sensitivity.yaml").string(); }

  /// The msd scene with its solver line replaced.
  std::string msd_with(const std::string& solver) const {
    return write("msd_edited.yaml", replaced(msd_text(), "solver: {method: bdf, rtol: 1.0e-8, atol: 1.0e-10}", solver));
  }

  json run_json(const fs::path& out) const { return json::parse(read_text(out / "run.json")); }
};

TEST_F(SolverOptions, RunWithOptionsIsTheRunOfTheEditedScene) {
  struct Case {
    std::string options, solver;
  };
  for (const Case& c : {Case{"--solver rk4 --step 0.002", "solver: {method: rk4, step: 0.002}"},
                        Case{"--rtol 1e-4 --atol 1e-6", "solver: {method: bdf, rtol: 1.0e-4, atol: 1.0e-6}"},
                        Case{"--solver sdirk2 --step 0.005", "solver: {method: sdirk2, step: 0.005}"},
                        Case{"--solver adams --rtol 1e-5", "solver: {method: adams, rtol: 1.0e-5, atol: 1.0e-10}"},
                        Case{"--max-order 2", "solver: {method: bdf, rtol: 1.0e-8, atol: 1.0e-10, max_order: 2}"}}) {
    const fs::path a = dir_ / "a", b = dir_ / "b";
    const auto ra = dydp("run " + quote(msd_path()) + " " + c.options + " --out " + quote(a.string()));
    ASSERT_EQ(ra.status, 0) << c.options << ": " << ra.err;
    const auto rb = dydp("run " + quote(msd_with(c.solver)) + " --out " + quote(b.string()));
    ASSERT_EQ(rb.status, 0) << c.solver << ": " << rb.err;
    const json ja = run_json(a), jb = run_json(b);
    for (const char* key : {"solver", "rtol", "atol", "fixed_step", "max_order", "steps", "rhs_evaluations"})
      EXPECT_EQ(ja[key], jb[key]) << c.options << ": " << key;
    EXPECT_EQ(read_text(a / "signals.csv"), read_text(b / "signals.csv")) << c.options;
    EXPECT_EQ(read_text(a / "objectives.json"), read_text(b / "objectives.json")) << c.options;
    // and it is not the scene's own setting (the options did something)
    EXPECT_NE(ja["steps"], 0);
    EXPECT_TRUE(ja["solver"] != "bdf" || ja["rtol"] != 1e-8 || ja["max_order"] != 5) << c.options;
  }
}

TEST_F(SolverOptions, SweepReplayAndAccuracyTakeThem) {
  // sweep: one point, RK4 at 2 ms, against the run of the edited scene at that point
  const fs::path sweep = dir_ / "sweep", single = dir_ / "single";
  auto r = dydp("sweep " + quote(msd_path()) + " --param stiffness --range 40:40:1 --solver rk4 --step 0.002 --out " +
                quote(sweep.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  r = dydp("run " + quote(msd_with("solver: {method: rk4, step: 0.002}")) + " --out " + quote(single.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const json sj = json::parse(read_text(sweep / "sweep.json"));
  const json oj = json::parse(read_text(single / "objectives.json"));
  EXPECT_EQ(sj["points"][0]["objectives"]["x_rms"]["value"], oj["objectives"]["x_rms"]["value"]);
  EXPECT_EQ(sj["points"][0]["objectives"]["x_rms"]["sensitivity"], oj["objectives"]["x_rms"]["sensitivity"]["stiffness"]);

  // replay: the rig's pads from a recording, integrated by the method named
  const std::string rig = write("rig.yaml",
                                "scene: rig\n"
                                "time: {stop: 0.5, output_step: 0.01}\n"
                                "blocks:\n"
                                "  rig: {type: road.fourposter}\n"
                                "outputs: [rig.z]\n");
  const std::string recording = write("bench.csv", "t,fl,fr,rl,rr\n0,0,0,0,0\n0.5,0.01,0,0,0\n");
  const fs::path replay = dir_ / "replay";
  r = dydp("replay " + quote(rig) + " --input " + quote(recording) + " --solver rk4 --step 0.005 --out " +
           quote(replay.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(run_json(replay)["solver"], "rk4");
  EXPECT_EQ(run_json(replay)["fixed_step"], 0.005);

  // accuracy: the given setting is measured against the reference, and no ladder unless asked
  const fs::path acc = dir_ / "acc";
  r = dydp("accuracy " + quote(msd_path()) + " --rtol 1e-5 --atol 1e-7 --out " + quote(acc.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string csv = read_text(acc / "accuracy.csv");
  EXPECT_NE(csv.find("bdf (given)"), std::string::npos) << csv;
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 2) << csv;  // header and the one row

  // with --max-order the given row names the order
  const fs::path ordered = dir_ / "ordered";
  r = dydp("accuracy " + quote(msd_path()) + " --max-order 2 --out " + quote(ordered.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string csv2 = read_text(ordered / "accuracy.csv");
  EXPECT_NE(csv2.find("bdf order <= 2 (given)"), std::string::npos) << csv2;
  EXPECT_NE(read_text(ordered / "accuracy.md").find("bdf order <= 2 (given)"), std::string::npos);
}

TEST_F(SolverOptions, ValuesTheSceneWouldRefuseAreRefused) {
  struct Case {
    std::string options, prefix;
  };
  for (const Case& c : {Case{"--solver euler", "--solver: unknown method 'euler'"},
                        Case{"--rtol 0", "--rtol: value 0 must be in (0, 1)"},
                        Case{"--rtol 1", "--rtol: value 1 must be in (0, 1)"},
                        Case{"--atol -1e-9", "--atol: value -1e-09 must be in (0, 1)"},
                        Case{"--step 0", "--step: value 0 must be positive"},
                        Case{"--step 1e-12", "--step: gives 1e+13 steps, more than 1e+09"},
                        Case{"--max-order 6", "--max-order: value 6 must be in [1, 5] for bdf"},
                        Case{"--solver rk4 --max-order 2", "--max-order: applies to bdf and adams only"}}) {
    for (const std::string command : {"run", "accuracy"}) {
      const fs::path out = dir_ / "out";
      const auto r = dydp(command + " " + quote(msd_path()) + " " + c.options + " --out " + quote(out.string()));
      EXPECT_EQ(r.status, 2) << command << " " << c.options << ": " << r.err;
      EXPECT_EQ(r.err.rfind(c.prefix, 0), 0u) << "expected '" << c.prefix << "' in: " << r.err;
      EXPECT_TRUE(entries(out).empty()) << command << " " << c.options << " wrote something";
    }
  }
  const auto r = dydp("run " + quote(msd_path()) + " --rtol abc");
  EXPECT_EQ(r.status, 2) << r.err;
}

}  // namespace
