// End-to-end `dydp sweep` and `dydp accuracy`: exact derivatives that central differences of whole
// runs approach at second order (across a pothole's edges too), bad sweep arguments exiting 2,
// and the accuracy ladder with its cheapest setting.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/apps/cli_fixture.hpp"

namespace dydp::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// ---------------------------------------------------------------- sweep and accuracy

TEST_F(Cli, SweepReportsExactDerivativesThatCentralDifferencesApproach) {
  const fs::path out = dir_ / "sweep";
  // Steps 0.1 and 0.01: the objective carries the solver's noise (about 6e-8 relative at the
  // scene's rtol 1e-8, measured over 21 runs 5e-4 apart), which a central difference divides by
  // 2h: at h = 0.001 that alone is about 1e-4 of the derivative, at 0.01 about 1e-5, while the
  // truncation error (h^2) is then still 2e-5.
  const Result r = dydp("sweep " + quote(msd_scene()) + " --param damping --range 0.5:2.5:3 --fd 0.1,0.01 --delta 0.1 --out " +
                        quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(read_text(out / "sweep.json"));
  ASSERT_EQ(j["points"].size(), 3u);
  EXPECT_DOUBLE_EQ(j["points"][1]["p"].get<double>(), 1.5);
  for (const auto& pt : j["points"]) {
    const auto& o = pt["objectives"]["x_rms"];
    const double exact = o["sensitivity"].get<double>();
    const double fd_coarse = o["fd"][0]["value"].get<double>(), fd_fine = o["fd"][1]["value"].get<double>();
    // More damping, less motion; the finer difference is closer to the exact derivative.
    EXPECT_LT(exact, 0.0);
    EXPECT_LT(std::fabs(fd_fine - exact), std::fabs(fd_coarse - exact));
    EXPECT_LT(std::fabs(fd_fine - exact), 1e-4 * std::fabs(exact));
    // second order: a ten times smaller step, an error about a hundred times smaller
    EXPECT_GT(std::fabs(fd_coarse - exact), 20.0 * std::fabs(fd_fine - exact));
    EXPECT_NEAR(o["normalised"].get<double>(), pt["p"].get<double>() / o["value"].get<double>() * exact, 1e-12);
  }
  const auto rows = split(read_text(out / "sweep.csv"), '\n');
  EXPECT_EQ(rows.size(), 4u);  // header + 3 points
}

// Every point of a sweep estimates its own error as a run does (a shadow run beside it): the
// estimate of each point equals that of `dydp run` on the same scene at that point with the
// same sensitivity, and a point whose estimate is above the target says so on stderr.
TEST_F(Cli, SweepPointsEstimateTheirOwnErrorAsARunDoes) {
  const fs::path out = dir_ / "sweep";
  const Result r = dydp("sweep " + quote(msd_scene()) + " --param damping --range 0.5:2.5:3 --out " + quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("estimated error (each run's own"), std::string::npos) << r.out;
  const json j = json::parse(read_text(out / "sweep.json"));
  ASSERT_EQ(j["points"].size(), 3u);
  // The same scene with the swept parameter as its one sensitivity, run at the middle point.
  const fs::path scene = dir_ / "msd_damping.yaml";
  {
    std::ofstream f(scene);
    f << replaced(read_text(msd_scene()), "sensitivities: [mass, stiffness, damping]", "sensitivities: [damping]");
  }
  const Result one = dydp("run " + quote(scene.string()) + " --set damping=1.5 --out " + quote((dir_ / "run").string()));
  ASSERT_EQ(one.status, 0) << one.err;
  const json run = json::parse(read_text(dir_ / "run/run.json"));
  const json& expected = run["error_estimate"];
  const json& got = j["points"][1]["error_estimate"];
  ASSERT_TRUE(got.is_object()) << j["points"][1].dump();
  EXPECT_GT(got["signals"].get<double>(), 0.0);
  EXPECT_NEAR(got["signals"].get<double>(), expected["signals"].get<double>(), 1e-12);
  EXPECT_NEAR(got["sensitivities"].get<double>(), expected["sensitivities"].get<double>(), 1e-12);
  EXPECT_EQ(got["how"], expected["how"]);
  EXPECT_TRUE(j["points"][0]["warnings"].empty());
  const auto header = split(split(read_text(out / "sweep.csv"), '\n')[0], ',');
  EXPECT_EQ(header.back(), "error_estimate_sensitivities");

  // RK4 at 0.25 s (outputs every 0.25 s) on a 0.8 Hz drive and a 0.8 Hz mass, 5 steps a period:
  // far above the 1 % target, and said.
  const fs::path coarse_scene = dir_ / "msd_coarse.yaml";
  {
    std::ofstream f(coarse_scene);
    f << replaced(read_text(msd_scene()), "output_step: 0.01", "output_step: 0.25");
  }
  const Result coarse = dydp("sweep " + quote(coarse_scene.string()) +
                             " --param damping --range 0.5:2.5:2 --solver rk4 --step 0.25 --out " +
                             quote((dir_ / "coarse").string()));
  ASSERT_EQ(coarse.status, 0) << coarse.err;
  EXPECT_NE(coarse.err.find("warning: at damping = 0.5: estimated error"), std::string::npos) << coarse.err;
  const json c = json::parse(read_text(dir_ / "coarse/sweep.json"));
  EXPECT_GT(c["points"][0]["error_estimate"]["signals"].get<double>(), 0.01);
  // --no-estimate: no shadow runs, and none claimed.
  const Result none = dydp("sweep " + quote(msd_scene()) + " --param damping --range 0.5:2.5:2 --no-estimate --out " +
                           quote((dir_ / "none").string()));
  ASSERT_EQ(none.status, 0) << none.err;
  EXPECT_TRUE(json::parse(read_text(dir_ / "none/sweep.json"))["points"][0]["error_estimate"].is_null());
}

TEST_F(Cli, SweepOfAnUnknownParameterExitsTwo) {
  const Result r = dydp("sweep " + quote(msd_scene()) + " --param nope --range 0:1:3 --out " + quote((dir_ / "o").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("nope"), std::string::npos) << r.err;
  const Result bad_range = dydp("sweep " + quote(msd_scene()) + " --param damping --range 1:0 --out " + quote((dir_ / "o").string()));
  EXPECT_EQ(bad_range.status, 2);
  EXPECT_NE(bad_range.err.find("LO:HI:N"), std::string::npos) << bad_range.err;
  EXPECT_FALSE(fs::exists(dir_ / "o" / "sweep.csv"));
}

TEST_F(Cli, AccuracyWritesTheLadderAndNamesTheCheapestSetting) {
  const fs::path out = dir_ / "acc";
  const Result r = dydp("accuracy " + quote(msd_scene()) + " --target 1e-5 --out " + quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = split(read_text(out / "accuracy.csv"), '\n');
  EXPECT_EQ(rows.size(), 1u + 7 + 7 + 6 + 6);
  EXPECT_NE(r.out.find("Cheapest setting for errors below 1e-05"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(out / "accuracy.md"));
}

// Across the pothole's edges (breakpoints, wheel lift-off) the exact sensitivity of the comfort
// figure to the valve current agrees with central differences of whole runs.
TEST_F(Cli, PotholeSensitivityAgreesWithCentralDifferences) {
  std::string text = scene_text(fs::path(DYDP_SOURCE_DIR) / "scenarios" / "stress" / "pothole_lift_off.yaml");
  const std::string solver = "solver: {method: bdf, rtol: 1.0e-6, atol: 1.0e-8}";
  ASSERT_NE(text.find(solver), std::string::npos);
  text.replace(text.find(solver), solver.size(), "solver: {method: bdf, rtol: 1.0e-9, atol: 1.0e-11}");
  const std::string scene = write("pothole.yaml", text);
  const fs::path out = dir_ / "sweep";
  const Result r = dydp("sweep " + quote(scene) + " --param valve_current --range 0.8:0.8:1 --fd 0.01,0.001,0.0001 --out " +
                        quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(read_text(out / "sweep.json"));
  // comfort_rms, comfort_wk, damper_power: a list the loop below cannot pass on empty
  ASSERT_EQ(j["points"][0]["objectives"].size(), 3u) << j.dump();
  for (const auto& [name, o] : j["points"][0]["objectives"].items()) {
    ASSERT_EQ(o["fd"].size(), 3u) << name;
    const double exact = o["sensitivity"].get<double>();
    double best = INFINITY;
    for (const auto& fd : o["fd"]) best = std::min(best, std::fabs(fd["value"].get<double>() - exact));
    EXPECT_LT(best, 1e-4 * std::fabs(exact)) << name << " exact " << exact << "\n" << o.dump();
  }
}

}  // namespace
}  // namespace dydp::test
