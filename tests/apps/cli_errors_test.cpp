// End-to-end exit statuses of the dydp program: bad input (scenes, --set, options) exits 2 with
// `file:line: field:` on stderr and writes nothing; a solver failure (an unstable step, refused
// points ahead, diverging states or sensitivities) exits 1 naming block and time, and writes no signals.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/apps/cli_fixture.hpp"

namespace dydp::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// ---------------------------------------------------------------- bad input: exit 2

TEST_F(Cli, BadSceneExitsTwoWithFileLineAndWritesNothing) {
  const std::string scene = write("bad.yaml", R"(scene: bad
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
  g: {type: math.gain, width: 2}
connections:
  - src.y -> g.u
outputs: [g.y]
)");
  const fs::path out = dir_ / "out";
  fs::create_directories(out);
  const Result r = dydp("run " + quote(scene) + " --out " + quote(out.string()));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err.rfind(scene + ":7: g.u: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("width mismatch"), std::string::npos) << r.err;
  EXPECT_TRUE(entries(out).empty()) << "left in --out: " << join(entries(out));
}

TEST_F(Cli, BadSceneDoesNotCreateTheOutFolder) {
  const std::string scene = write("bad.yaml", R"(scene: bad
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sinus}
outputs: [src.y]
)");
  const fs::path out = dir_ / "never";
  const Result r = dydp("run " + quote(scene) + " --out " + quote(out.string()));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err.rfind(scene + ":4: src.type: ", 0), 0u) << r.err;
  EXPECT_TRUE(entries(out).empty()) << "left in --out: " << join(entries(out));
}

struct BadScene {
  const char* kind;
  const char* yaml;
  int line;
  const char* field;
};

// The issue's validation errors, each through the program: exit 2, `file:line: field:` on
// stderr, nothing in --out.
const BadScene kBadScenes[] = {
    {"unknown block type", "scene: t\nblocks:\n  a: {type: nope}\noutputs: [a.y]\n", 3, "a.type"},
    {"unknown port",
     "scene: t\nblocks:\n  a: {type: source.sine}\n  g: {type: math.gain}\nconnections:\n"
     "  - a.y -> g.v\noutputs: [g.y]\n",
     6, "g.v"},
    {"width mismatch",
     "scene: t\nblocks:\n  a: {type: source.sine}\n  g: {type: math.gain, width: 2}\nconnections:\n"
     "  - a.y -> g.u\noutputs: [g.y]\n",
     6, "g.u"},
    {"unconnected input", "scene: t\nblocks:\n  a: {type: source.sine}\n  g: {type: math.gain}\noutputs: [a.y]\n",
     4, "g.u"},
    {"input driven twice",
     "scene: t\nblocks:\n  a: {type: source.sine}\n  g: {type: math.gain}\nconnections:\n"
     "  - a.y -> g.u\n  - a.y -> g.u\noutputs: [g.y]\n",
     7, "g.u"},
    {"algebraic loop",
     "scene: t\nblocks:\n  g1: {type: math.gain}\n  g2: {type: math.gain}\nconnections:\n"
     "  - g1.y -> g2.u\n  - g2.y -> g1.u\noutputs: [g1.y]\n",
     6, "connections"},
    {"unknown $parameter", "scene: t\nblocks:\n  a: {type: source.sine, amplitude: $amp}\noutputs: [a.y]\n", 3,
     "a.amplitude"},
    {"value out of bounds", "scene: t\nblocks:\n  a: {type: source.sine, frequency: -3}\noutputs: [a.y]\n", 3,
     "a.frequency"},
    {"malformed number", "scene: t\nblocks:\n  a: {type: source.sine, phase: 0..1}\noutputs: [a.y]\n", 3,
     "a.phase"},
};

TEST_F(Cli, EachValidationErrorExitsTwoWithFileLineField) {
  for (const BadScene& bad : kBadScenes) {
    SCOPED_TRACE(bad.kind);
    const std::string scene = write("bad.yaml", bad.yaml);
    const fs::path out = dir_ / "out";
    const Result r = dydp("run " + quote(scene) + " --out " + quote(out.string()));
    EXPECT_EQ(r.status, 2) << r.err;
    const std::string prefix = scene + ":" + std::to_string(bad.line) + ": " + bad.field + ": ";
    EXPECT_EQ(r.err.rfind(prefix, 0), 0u) << "expected '" << prefix << "' in: " << r.err;
    EXPECT_TRUE(entries(out).empty()) << "left in --out: " << join(entries(out));
  }
}

TEST_F(Cli, SetUnknownParameterExitsTwo) {
  const fs::path out = dir_ / "out";
  const Result r = dydp("run " + quote(msd_scene()) + " --out " + quote(out.string()) +
                        " --set massa=2.0");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("massa"), std::string::npos) << r.err;
  EXPECT_TRUE(entries(out).empty()) << "left in --out: " << join(entries(out));
}

TEST_F(Cli, SetMalformedValueExitsTwo) {
  const fs::path out = dir_ / "out";
  const Result r = dydp("run " + quote(msd_scene()) + " --out " + quote(out.string()) +
                        " --set mass=2,0");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("malformed number '2,0'"), std::string::npos) << r.err;
  EXPECT_TRUE(entries(out).empty()) << "left in --out: " << join(entries(out));
}

TEST_F(Cli, SetValueOutsideRangeNamesTheParameterLine) {
  const fs::path out = dir_ / "out";
  const Result r = dydp("run " + quote(msd_scene()) + " --out " + quote(out.string()) +
                        " --set mass=100");
  EXPECT_EQ(r.status, 2) << r.err;
  // mass is defined on line 8 of the scene.
  EXPECT_EQ(r.err.rfind(msd_scene() + ":8: parameters.mass: ", 0), 0u) << r.err;
  EXPECT_TRUE(entries(out).empty()) << "left in --out: " << join(entries(out));
}

TEST_F(Cli, SetWithoutEqualsExitsTwo) {
  const Result r = dydp("run " + quote(msd_scene()) + " --out " + quote((dir_ / "out").string()) +
                        " --set mass");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("NAME=VALUE"), std::string::npos) << r.err;
}

TEST_F(Cli, UnknownCommandLineOptionExitsTwo) {
  const Result r = dydp("run " + quote(msd_scene()) + " --outt x");
  EXPECT_EQ(r.status, 2) << r.err;
}

// ---------------------------------------------------------------- solver failure: exit 1

TEST_F(Cli, SolverFailureExitsOneNamingBlockAndTime) {
  // rk4 with h = 0.1 s on a lag of tau = 1e-6 s: |1 + z + z^2/2 + z^3/6 + z^4/24| >> 1 for
  // z = -h/tau, so the state grows without bound and overflows within a few dozen steps.
  const std::string scene = write("unstable.yaml", R"(scene: unstable
time: {stop: 20.0, output_step: 0.1}
solver: {method: rk4, step: 0.1}
blocks:
  src: {type: source.constant, value: 1.0}
  fast_lag: {type: math.lag, tau: 1.0e-6}
connections:
  - src.y -> fast_lag.u
outputs: [fast_lag.y]
)");
  const fs::path out = dir_ / "out";
  const Result r = dydp("run " + quote(scene) + " --out " + quote(out.string()));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("block fast_lag"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("t = "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("not finite"), std::string::npos) << r.err;
  EXPECT_TRUE(entries(out).empty()) << "left in --out: " << join(entries(out));
}

// A run whose block refuses every point ahead stops at the smallest step (solver.min_step)
// naming time, block and reason, instead of crawling on at ever smaller steps; with the guard
// off (min_step: 0) the same run was still at t = 2.2673 s after five minutes.
TEST_F(Cli, RefusedPointsAheadStopTheRunAtTheSmallestStep) {
  const fs::path src = fs::path(DYDP_SOURCE_DIR) / "scenarios" / "stress" / "cornering_wheelspin.yaml";
  const Result r = dydp("run " + quote(src.string()) + " --no-sens --out " + quote((dir_ / "spin").string()));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("t = 2.2"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("block corner_fr.damper"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("stroke beyond the chambers' length"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "spin" / "signals.csv"));
}

// RK4 at a millisecond step on the stiffest scene reports the instability instead of writing non-finite numbers.
TEST_F(Cli, StiffHydraulicsFailuresAreReportedNotWritten) {
  const fs::path src = fs::path(DYDP_SOURCE_DIR) / "scenarios" / "stress" / "bulk_modulus_100x.yaml";
  std::string text = scene_text(src);
  const std::string solver = "solver: {method: bdf, rtol: 1.0e-6, atol: 1.0e-8, sens_error_test: false}";
  ASSERT_NE(text.find(solver), std::string::npos);
  std::string rk4 = text;
  rk4.replace(rk4.find(solver), solver.size(), "solver: {method: rk4, step: 0.001}");
  const Result r = dydp("run " + quote(write("rk4.yaml", rk4)) + " --out " + quote((dir_ / "rk4").string()));
  // The instability shows as pressures leaving their domain (or as non-finite numbers).
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("block damper"), std::string::npos) << r.err;
  EXPECT_TRUE(r.err.find("not finite") != std::string::npos || r.err.find("domain") != std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "rk4" / "signals.csv"));
}

// RK4 at 0.1 ms on the quarter car keeps its states bounded but its sensitivities grow without
// bound (the hydraulic modes are unstable in the step's tangent map): the run stops naming them.
TEST_F(Cli, DivergingSensitivitiesStopTheRun) {
  std::string text = scene_text(fs::path(DYDP_SOURCE_DIR) / "scenarios" / "quarter_car_cdc.yaml");
  const std::string solver = "solver: {method: bdf, rtol: 1.0e-6, atol: 1.0e-8}";
  ASSERT_NE(text.find(solver), std::string::npos);
  text.replace(text.find(solver), solver.size(), "solver: {method: rk4, step: 0.0001}");
  const Result r = dydp("run " + quote(write("qc_rk4.yaml", text)) + " --out " + quote((dir_ / "qc_rk4").string()));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("t = "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("sensitivit"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("not finite"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "qc_rk4" / "signals.csv"));
}

}  // namespace
}  // namespace dydp::test
