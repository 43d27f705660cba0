// End-to-end `dydp run`: the output folder contract of DESIGN.md section 5 (signals.csv,
// objectives.json, run.json, written whole by rename or not at all; their columns, keys and
// values; --set, --no-sens, pruned blocks) and every shipped scene running to finite objectives.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "engine/framework/diagram.hpp"
#include "tests/apps/cli_fixture.hpp"

namespace dydp::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// ---------------------------------------------------------------- the output folder contract

/// The signals of msd_sensitivity.yaml, in its outputs: order, and its sensitivity parameters.
const std::vector<std::string> kMsdSignals = {"body.x", "body.v", "body.a"};
const std::vector<std::string> kMsdParams = {"mass", "stiffness", "damping"};

TEST_F(Cli, RunWritesTheThreeFilesAndNothingElse) {
  const fs::path out = dir_ / "out";
  const Result r = dydp("run " + quote(msd_scene()) + " --out " + quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  std::vector<std::string> names = entries(out);
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"objectives.json", "run.json", "signals.csv"}))
      << "no temporary file may be left behind";
}

TEST_F(Cli, SignalsCsvHeaderAndRows) {
  const fs::path out = dir_ / "out";
  const Result r = dydp("run " + quote(msd_scene()) + " --out " + quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const std::vector<std::string> lines = split(read_text(out / "signals.csv"), '\n');
  ASSERT_FALSE(lines.empty());

  std::vector<std::string> expected = {"t"};
  for (const auto& s : kMsdSignals) expected.push_back(s);
  for (const auto& p : kMsdParams)
    for (const auto& s : kMsdSignals) expected.push_back("d(" + s + ")/d(" + p + ")");
  EXPECT_EQ(split(lines[0], ','), expected);

  // time: {start: 0, stop: 10, output_step: 0.01}: 1001 rows after the header.
  ASSERT_EQ(lines.size(), 1u + 1001u);
  for (size_t k = 1; k < lines.size(); ++k) {
    const auto cells = split(lines[k], ',');
    ASSERT_EQ(cells.size(), expected.size()) << "row " << k;
    for (const auto& c : cells) ASSERT_TRUE(std::isfinite(std::stod(c))) << "row " << k << ": " << c;
    EXPECT_NEAR(std::stod(cells[0]), 0.01 * static_cast<double>(k - 1), 1e-9) << "row " << k;
  }
  // First row: x(0) = x0 = 0.05 and the initial position does not depend on m, k or c.
  const auto first = split(lines[1], ',');
  EXPECT_DOUBLE_EQ(std::stod(first[1]), 0.05);
  EXPECT_DOUBLE_EQ(std::stod(first[4]), 0.0);  // d(body.x)/d(mass)
  EXPECT_DOUBLE_EQ(std::stod(first[7]), 0.0);  // d(body.x)/d(stiffness)
  // Later rows carry non-zero sensitivities.
  const auto last = split(lines.back(), ',');
  EXPECT_NE(std::stod(last[4]), 0.0);
}

TEST_F(Cli, ObjectivesJson) {
  const fs::path out = dir_ / "out";
  const Result r = dydp("run " + quote(msd_scene()) + " --out " + quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  json j;
  ASSERT_NO_THROW(j = json::parse(read_text(out / "objectives.json")));
  ASSERT_TRUE(j.contains("objectives"));
  ASSERT_TRUE(j["objectives"].contains("x_rms")) << j.dump();
  const json& o = j["objectives"]["x_rms"];
  ASSERT_TRUE(o["value"].is_number()) << o.dump();
  EXPECT_GT(o["value"].get<double>(), 0.0);
  ASSERT_TRUE(o["sensitivity"].is_object()) << o.dump();
  EXPECT_EQ(o["sensitivity"].size(), kMsdParams.size()) << o.dump();
  for (const auto& p : kMsdParams) {
    ASSERT_TRUE(o["sensitivity"].contains(p)) << p;
    ASSERT_TRUE(o["sensitivity"][p].is_number()) << p;
    EXPECT_TRUE(std::isfinite(o["sensitivity"][p].get<double>())) << p;
    EXPECT_NE(o["sensitivity"][p].get<double>(), 0.0) << p;
  }
}

TEST_F(Cli, RunJsonKeys) {
  const fs::path out = dir_ / "out";
  const Result r = dydp("run " + quote(msd_scene()) + " --out " + quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  json j;
  ASSERT_NO_THROW(j = json::parse(read_text(out / "run.json")));
  for (const char* key : {"solver", "rtol", "atol", "steps", "rhs_evaluations",
                          "sensitivity_rhs_evaluations", "jacobian_evaluations", "cpu_seconds",
                          "simulated_seconds", "realtime_factor", "pruned_blocks", "warnings"})
    EXPECT_TRUE(j.contains(key)) << "run.json lacks " << key << ": " << j.dump();
  EXPECT_EQ(j.value("solver", ""), "bdf");
  EXPECT_DOUBLE_EQ(j.value("rtol", 0.0), 1e-8);
  EXPECT_DOUBLE_EQ(j.value("atol", 0.0), 1e-10);
  EXPECT_GT(j.value("steps", 0L), 0);
  EXPECT_GT(j.value("rhs_evaluations", 0L), 0);
  EXPECT_GT(j.value("sensitivity_rhs_evaluations", 0L), 0);
  EXPECT_DOUBLE_EQ(j.value("simulated_seconds", 0.0), 10.0);
  EXPECT_GE(j.value("cpu_seconds", -1.0), 0.0);
  EXPECT_TRUE(j["pruned_blocks"].is_array());
  EXPECT_TRUE(j["pruned_blocks"].empty());
  EXPECT_TRUE(j["warnings"].is_array());
  ASSERT_TRUE(j.contains("parameters"));
  EXPECT_DOUBLE_EQ(j["parameters"]["mass"]["value"].get<double>(), 1.5);
  // The states that limited the step: both of the body's and the objective's integral (CVODES
  // integrates it with them), every accepted step counted once (against CVODES' own step
  // count), most often first, and the first named on stdout.
  ASSERT_TRUE(j["limiting_states"].is_array());
  ASSERT_EQ(j["limiting_states"].size(), 3u) << j["limiting_states"].dump();
  long counted = 0;
  double shares = 0.0;
  for (const auto& l : j["limiting_states"]) {
    const std::string state = l["state"].get<std::string>();
    EXPECT_TRUE(state == "body.x" || state == "body.v" || state == "x_rms.integral") << state;
    counted += l["steps"].get<long>();
    shares += l["share"].get<double>();
  }
  EXPECT_EQ(counted, j["steps"].get<long>());
  EXPECT_NEAR(shares, 1.0, 1e-12);
  EXPECT_GE(j["limiting_states"][0]["steps"].get<long>(), j["limiting_states"][1]["steps"].get<long>());
  EXPECT_NE(r.out.find("step limited by: " + j["limiting_states"][0]["state"].get<std::string>()), std::string::npos)
      << r.out;
}

TEST_F(Cli, SetChangesTheObjectiveAndRunJson) {
  const fs::path base = dir_ / "base", heavy = dir_ / "heavy";
  ASSERT_EQ(dydp("run " + quote(msd_scene()) + " --out " + quote(base.string())).status, 0);
  const Result r = dydp("run " + quote(msd_scene()) + " --out " + quote(heavy.string()) +
                        " --set mass=2.0");
  ASSERT_EQ(r.status, 0) << r.err;
  const json a = json::parse(read_text(base / "objectives.json"));
  const json b = json::parse(read_text(heavy / "objectives.json"));
  const double va = a["objectives"]["x_rms"]["value"], vb = b["objectives"]["x_rms"]["value"];
  EXPECT_GT(std::fabs(va - vb), 1e-6 * std::fabs(va)) << va << " vs " << vb;
  const json run = json::parse(read_text(heavy / "run.json"));
  EXPECT_DOUBLE_EQ(run["parameters"]["mass"]["value"].get<double>(), 2.0);
  EXPECT_DOUBLE_EQ(run["parameters"]["stiffness"]["value"].get<double>(), 40.0);
}

TEST_F(Cli, NoSensWritesNoSensitivities) {
  const fs::path out = dir_ / "out";
  const Result r = dydp("run " + quote(msd_scene()) + " --out " + quote(out.string()) + " --no-sens");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::vector<std::string> lines = split(read_text(out / "signals.csv"), '\n');
  ASSERT_FALSE(lines.empty());
  std::vector<std::string> expected = {"t"};
  for (const auto& s : kMsdSignals) expected.push_back(s);
  EXPECT_EQ(split(lines[0], ','), expected);
  EXPECT_EQ(lines.size(), 1u + 1001u);
  const json j = json::parse(read_text(out / "objectives.json"));
  ASSERT_TRUE(j["objectives"].contains("x_rms"));
  EXPECT_TRUE(j["objectives"]["x_rms"]["value"].is_number());
  ASSERT_TRUE(j["objectives"]["x_rms"]["sensitivity"].is_object());
  EXPECT_TRUE(j["objectives"]["x_rms"]["sensitivity"].empty());
  const json run = json::parse(read_text(out / "run.json"));
  EXPECT_EQ(run.value("sensitivity_rhs_evaluations", -1L), 0);
}

TEST_F(Cli, OutputFilesAreReplacedByRenameNotRewrittenInPlace) {
  // A hard link to a previous signals.csv must keep the old bytes: the new file is written
  // under a temporary name and renamed over the old one, never truncated and rewritten.
  const fs::path out = dir_ / "out";
  fs::create_directories(out);
  const fs::path witness = dir_ / "witness.csv";
  write("witness.csv", "old contents\n");
  fs::create_hard_link(witness, out / "signals.csv");
  const Result r = dydp("run " + quote(msd_scene()) + " --out " + quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(read_text(witness), "old contents\n");
  EXPECT_EQ(read_text(out / "signals.csv").rfind("t,body.x,", 0), 0u);
}

TEST_F(Cli, PrunedBlocksInRunJson) {
  const std::string scene = write("pruned.yaml", R"(scene: pruned
time: {stop: 0.5, output_step: 0.1}
solver: {method: rk4, step: 0.01}
blocks:
  src: {type: source.sine}
  spare: {type: math.gain}
connections:
  - src.y -> spare.u
outputs: [src.y]
)");
  const fs::path out = dir_ / "out";
  const Result r = dydp("run " + quote(scene) + " --out " + quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const json run = json::parse(read_text(out / "run.json"));
  EXPECT_EQ(run["pruned_blocks"], json::array({"spare"}));
  EXPECT_EQ(run.value("solver", ""), "rk4");
  const std::vector<std::string> lines = split(read_text(out / "signals.csv"), '\n');
  EXPECT_EQ(lines.size(), 1u + 6u);
  EXPECT_EQ(lines.at(0), "t,src.y");
}

// ---------------------------------------------------------------- every scene

// Every scene in scenarios/ (the README's among them) loads and runs to completion with
// finite objectives.
TEST_F(Cli, EveryScenarioRuns) {
  int count = 0;
  size_t objectives_seen = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(DYDP_SOURCE_DIR) / "scenarios")) {
    if (entry.path().extension() != ".yaml") continue;
    // The full car's 20 s on the rig takes about a minute in an optimised build: the sanitizer
    // build (several times slower) runs its first 2 s, the objective windows moved inside.
    std::string scene = entry.path().string();
    if (DYDP_SANITIZED && entry.path().stem() == "fourposter_comfort") {
      std::string text = dydp::test::scene_copy_text(scene);
      ASSERT_NE(text.find("stop: 20.0"), std::string::npos);
      text.replace(text.find("stop: 20.0"), 10, "stop: 2.0");
      for (size_t at; (at = text.find("window: [2.0, 20.0]")) != std::string::npos;)
        text.replace(at, 19, "window: [1.0, 2.0]");
      scene = write("fourposter_comfort_2s.yaml", text);
    }
    const fs::path out = dir_ / entry.path().stem();
    const Result r = dydp("run " + quote(scene) + " --out " + quote(out.string()));
    ASSERT_EQ(r.status, 0) << entry.path() << "\n" << r.err;
    const json objectives = json::parse(read_text(out / "objectives.json"))["objectives"];
    // Every objective the scene declares, not an empty list the loop below would pass on.
    EXPECT_EQ(objectives.size(), dydp::engine::load_scene(scene).objectives.size()) << entry.path();
    for (const auto& [name, o] : objectives.items())
      EXPECT_TRUE(std::isfinite(o["value"].get<double>())) << entry.path() << " " << name;
    objectives_seen += objectives.size();
    ++count;
  }
  EXPECT_GE(count, 6);
  // cornering_arb 4, quarter_car_cdc 3, fourposter_comfort 2, msd_sensitivity 1
  EXPECT_GE(objectives_seen, 10u);
}

}  // namespace
}  // namespace dydp::test
