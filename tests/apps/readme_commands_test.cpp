// The commands of README.md "Using dydp", each run as written there: the main job
// (scenarios/fourposter_comfort.yaml) with --report, `sweep --report`, `accuracy --methods`,
// the handling scene's `screen` (with fewer samples).
// (`replay` with its sensitivities is tests/apps/replay_values_test.cpp.) A report is checked
// for what it promises: report.md is not empty and every plot it shows exists and is not empty.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "tests/apps/dydp_process.hpp"

namespace dydp::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

class ReadmeCommands : public DydpProcessTest {
 protected:
  ReadmeCommands() : DydpProcessTest("dydp_readme_") {}

  /// report.md in `dir` is not empty and each `![...](plots/NAME.png)` it shows is a non-empty
  /// file; returns the plots shown.
  static std::vector<std::string> check_report(const fs::path& dir) {
    const fs::path md = dir / "report.md";
    EXPECT_TRUE(fs::exists(md)) << md;
    const std::string text = read_text(md);
    EXPECT_GT(text.size(), 100u) << text;
    std::vector<std::string> plots;
    const std::regex image(R"(!\[[^\]]*\]\((plots/[^)]+\.png)\))");
    for (std::sregex_iterator it(text.begin(), text.end(), image), end; it != end; ++it) {
      const fs::path png = dir / (*it)[1].str();
      plots.push_back((*it)[1].str());
      EXPECT_TRUE(fs::exists(png)) << png << " shown in report.md but missing";
      if (fs::exists(png)) {
        EXPECT_GT(fs::file_size(png), 1000u) << png;
      }
    }
    if (text.find("gnuplot was not found") == std::string::npos) {
      EXPECT_FALSE(plots.empty()) << "gnuplot is there but report.md shows no plot:\n" << text;
    }
    return plots;
  }
};

// `dydp run scenarios/fourposter_comfort.yaml --report`: the main job. The sanitizer build runs
// the same scene over its first 3 s (objective windows moved inside) instead of 20 s.
TEST_F(ReadmeCommands, MainJobWithReport) {
  std::string scene = source_path("scenarios/fourposter_comfort.yaml").string();
  double stop = 20.0;
  if (DYDP_SANITIZED) {
    std::string text = scene_copy_text(scene);
    text = replaced(text, "stop: 20.0", "stop: 3.0");
    while (text.find("window: [2.0, 20.0]") != std::string::npos)
      text.replace(text.find("window: [2.0, 20.0]"), 19, "window: [1.0, 3.0]");
    scene = write("fourposter_comfort_3s.yaml", text);
    stop = 3.0;
  }
  const fs::path out = dir_ / "out";
  const ProcessResult r = dydp("run " + quote(scene) + " --report --out " + quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f : {"signals.csv", "objectives.json", "run.json"})
    EXPECT_GT(fs::file_size(out / f), 0u) << f;
  EXPECT_DOUBLE_EQ(json::parse(read_text(out / "run.json"))["simulated_seconds"].get<double>(), stop);
  const json objectives = json::parse(read_text(out / "objectives.json"))["objectives"];
  ASSERT_FALSE(objectives.empty());
  for (const auto& [name, o] : objectives.items()) {
    EXPECT_TRUE(std::isfinite(o["value"].get<double>())) << name;
    ASSERT_TRUE(o["sensitivity"].contains("valve_current")) << name;
    EXPECT_TRUE(std::isfinite(o["sensitivity"]["valve_current"].get<double>())) << name;
  }
  check_report(out);
}

// `dydp sweep SCENE --param NAME --range LO:HI:N --fd H1,H2 --delta STEP --report`.
TEST_F(ReadmeCommands, SweepWithReport) {
  const fs::path out = dir_ / "sweep";
  const ProcessResult r = dydp("sweep " + quote(source_path("scenarios/msd_sensitivity.yaml").string()) +
                               " --param damping --range 0.5:2.5:3 --fd 0.1,0.01 --delta 0.1 --report --out " +
                               quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_GT(fs::file_size(out / "sweep.csv"), 0u);
  EXPECT_GT(fs::file_size(out / "sweep.json"), 0u);
  const std::vector<std::string> plots = check_report(out);
  if (!plots.empty()) {
    const std::set<std::string> shown(plots.begin(), plots.end());
    for (const char* p : {"plots/sweep_x_rms.png", "plots/fd_error_x_rms.png"})
      EXPECT_TRUE(shown.count(p)) << p << " not in report.md";
  }
}

// `dydp accuracy SCENE --methods bdf,rk4`: only the listed methods' ladders are run.
TEST_F(ReadmeCommands, AccuracyWithMethods) {
  const fs::path out = dir_ / "acc";
  const ProcessResult r = dydp("accuracy " + quote(source_path("scenarios/msd_sensitivity.yaml").string()) +
                               " --methods bdf,rk4 --target 1e-4 --out " + quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  std::istringstream csv(read_text(out / "accuracy.csv"));
  std::string line;
  std::getline(csv, line);
  int bdf = 0, rk4 = 0, other = 0;
  while (std::getline(csv, line)) {
    if (line.empty()) continue;
    const std::string method = line.substr(0, line.find(','));
    (method == "bdf" ? bdf : method == "rk4" ? rk4 : other)++;
  }
  // The README's ladders: BDF over rtol 1e-3..1e-9 (7 settings), RK4 over 6 fixed steps.
  EXPECT_EQ(bdf, 7);
  EXPECT_EQ(rk4, 6);
  EXPECT_EQ(other, 0);
  EXPECT_GT(fs::file_size(out / "accuracy.md"), 0u);
  EXPECT_NE(r.out.find("Cheapest setting for errors below 0.0001"), std::string::npos) << r.out;
}

// The README's screening command on the handling scene, as README.md writes it (read from the
// file), with 2 samples instead of 16: every listed parameter is ranked for every objective,
// the front and rear bars lead the yaw rate (steady-state handling is roll stiffness
// distribution), and the report shows its tornado charts.
TEST_F(ReadmeCommands, ScreenOfTheHandlingScene) {
  const std::string readme = read_text(source_path("README.md"));
  const std::string prefix = "dydp screen scenarios/cornering_arb.yaml";
  const std::size_t at = readme.find(prefix);
  ASSERT_NE(at, std::string::npos) << "README.md has no " << prefix;
  std::string command = readme.substr(at + 5, readme.find('\n', at) - at - 5);
  command = replaced(command, "scenarios/cornering_arb.yaml", quote(source_path("scenarios/cornering_arb.yaml").string()));
  command = replaced(command, "--samples 16", "--samples 2");
  const fs::path out = dir_ / "screen";
  command = replaced(command, "--out out/screen_cornering", "--out " + quote(out.string()));
  const std::string listed = command.substr(command.find("--params ") + 9);
  const std::size_t parameters = static_cast<std::size_t>(std::count(listed.begin(), listed.end(), ',')) + 1;
  EXPECT_GE(parameters, 16u);

  const ProcessResult r = dydp(command);
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(read_text(out / "screen.json"));
  for (const char* objective : {"beta", "yaw_rate", "lateral_acc", "roll"}) {
    SCOPED_TRACE(objective);
    ASSERT_TRUE(j["objectives"].contains(objective)) << j.dump();
    const json& ranking = j["objectives"][objective]["parameters"];
    ASSERT_EQ(ranking.size(), parameters);
  }
  const json& yaw = j["objectives"]["yaw_rate"]["parameters"];
  std::set<std::string> top;
  for (const auto& [name, p] : yaw.items())
    if (p["rank"].get<int>() <= 2) top.insert(name);
  EXPECT_EQ(top, (std::set<std::string>{"arb_front", "arb_rear"})) << yaw.dump();
  check_report(out);
}

}  // namespace
}  // namespace dydp::test
