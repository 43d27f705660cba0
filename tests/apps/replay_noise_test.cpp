// `dydp replay` of the main scene at a fixed step on a recording with content up to its Nyquist
// frequency: the 4-poster's 1 Hz, +-10 mm out of phase, plus 0.5 mm rms of white noise sampled
// at 200 Hz, replayed with SDIRK2 at 5 ms (one step per sample) and the sensitivity on. The CDC
// dampers' valves then change faster than a 5 ms step's Newton iteration can follow at some
// steps; those are taken in halves (run.json: substeps), and the replay completes (it stopped at
// t = 0.595 s before the halving existed, the binary of 1596ed1) with finite objectives and
// sensitivities.
// The same with replay's own integrator, Rosenbrock-W (rosw) at 2.5 ms, and at one step per
// sample (2 ms), on white noise sampled at 500 Hz: both complete without a halved step (before the
// dampers' rows were solved exactly in each stage, rosw stopped at 2 ms after halving six times
// and needed 0.25 ms), and their objectives and sensitivities are checked against a reference
// that is not a replay: `dydp run` with BDF at rtol 1e-9 of the scene with the recording named in
// its rig's input_file (so a replay that ignored its recording would not match it either).
// Every objectives.json is checked to hold the scene's two objectives and their sensitivity, so
// that no loop over them passes on an empty list.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <sstream>

#include "tests/apps/dydp_process.hpp"

namespace dydp::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

class ReplayNoise : public DydpProcessTest {
 protected:
  ReplayNoise() : DydpProcessTest("dydp_replay_noise_") {}

  /// 2 s of the 4-poster's 1 Hz, +-10 mm out of phase, plus 0.5 mm rms of white noise, one
  /// sample every `interval` seconds: the recording's path.
  std::string noisy_recording(double interval) {
    std::mt19937 rng(1);
    std::normal_distribution<double> noise(0.0, 0.0005);
    std::ostringstream csv;
    csv << "t,fl,fr,rl,rr\n";
    const long samples = std::lround(2.0 / interval);
    for (long k = 0; k <= samples; ++k) {
      const double t = interval * k, z = 0.01 * std::sin(2 * std::numbers::pi * t);
      csv << t << ',' << z + noise(rng) << ',' << -z + noise(rng) << ',' << z + noise(rng) << ',' << -z + noise(rng)
          << '\n';
    }
    return write("noisy.csv", csv.str());
  }
  /// The main scene shortened to the recording's 2 s.
  std::string short_scene() {
    std::string scene = scene_copy_text(source_path("scenarios/fourposter_comfort.yaml"));
    scene = replaced(scene, "stop: 20.0", "stop: 2.0");
    for (int i = 0; i < 2; ++i) scene.replace(scene.find("window: [2.0, 20.0]"), 19, "window: [0.5, 2.0]");
    return write("scene.yaml", scene);
  }
  /// The main scene shortened to 2 s, its rig reading `recording` (input_file, as replay sets it).
  std::string scene_reading(const std::string& recording) {
    const std::string scene = read_text(short_scene());
    return write("reference.yaml", replaced(scene, "noise_high: 10.0}", "noise_high: 10.0, input_file: " + recording + "}"));
  }
};

/// objectives.json's objectives: name -> (value, d/d(valve_current)); fails the test unless
/// there are the scene's two (comfort, comfort_wk), each with its finite sensitivity.
std::map<std::string, std::pair<double, double>> objectives_of(const fs::path& out) {
  std::map<std::string, std::pair<double, double>> m;
  const json o = json::parse(read_text(out / "objectives.json"))["objectives"];
  EXPECT_EQ(o.size(), 2u) << out << ": " << o.dump();
  for (const auto& [name, v] : o.items()) {
    EXPECT_TRUE(v["sensitivity"].contains("valve_current")) << out << ": " << name;
    m[name] = {v["value"].get<double>(), v["sensitivity"].value("valve_current", NAN)};
    EXPECT_TRUE(std::isfinite(m[name].first) && std::isfinite(m[name].second)) << out << ": " << name;
  }
  return m;
}

TEST_F(ReplayNoise, FixedStepReplayOfANoisyRecordingCompletesWithHalvedSteps) {
  const std::string input = noisy_recording(0.005);  // 200 Hz
  const std::string path = short_scene();
  const fs::path out = dir_ / "out";
  const ProcessResult r = dydp("replay " + quote(path) + " --input " + quote(input) +
                               " --solver sdirk2 --step 0.005 --out " + quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const json run = json::parse(read_text(out / "run.json"));
  EXPECT_GT(run["substeps"].get<long>(), 0) << "no step needed halving: the test no longer reaches the case";
  const json objectives = json::parse(read_text(out / "objectives.json"))["objectives"];
  ASSERT_EQ(objectives.size(), 2u) << objectives.dump();
  for (const auto& [name, o] : objectives.items()) {
    EXPECT_TRUE(std::isfinite(o["value"].get<double>())) << name;
    EXPECT_GT(o["value"].get<double>(), 0.0) << name;
    ASSERT_FALSE(o["sensitivity"].empty()) << name;
    for (const auto& [direction, s] : o["sensitivity"].items()) EXPECT_TRUE(std::isfinite(s.get<double>())) << name;
  }
}

TEST_F(ReplayNoise, ReplayIsRosenbrockWAndFollowsBdfAtOneStepPerSampleAndAt2p5Ms) {
  const std::string input = noisy_recording(0.002);  // 500 Hz
  const std::string path = short_scene();
  const fs::path reference = dir_ / "bdf";
  ProcessResult r = dydp("run " + quote(scene_reading(input)) + " --rtol 1e-9 --atol 1e-9 --out " +
                         quote(reference.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const auto ref = objectives_of(reference);
  ASSERT_EQ(ref.size(), 2u);
  // Measured (2026-12-06): at 2.5 ms the objectives within 1.5 % and 0.5 %, their sensitivities
  // within 3.0 % and 0.6 %; at 2 ms 0.7 % and 0.04 %, 1.7 % and 0.8 %. White noise up to the
  // Nyquist frequency is the hardest input a fixed step meets (the shaker file's errors are 10
  // times smaller, docs/accuracy.md); the bounds leave about twice the measured.
  struct Case {
    const char* options;  // empty: replay's default
    double step_s, value_bound, sensitivity_bound;
  };
  // A fixed step is taken when --step names one (replay's default is error-controlled,
  // replay_error_test.cpp); with or without --solver rosw.
  const Case cases[] = {{"--step 0.0025", 0.0025, 0.035, 0.065}, {"--solver rosw --step 0.0025", 0.0025, 0.035, 0.065},
                        {"--step 0.002", 0.002, 0.015, 0.04}};
  for (int i = 0; i < 3; ++i) {
    const Case& c = cases[i];
    const fs::path out = dir_ / ("rosw" + std::to_string(i));
    r = dydp("replay " + quote(path) + " --input " + quote(input) + " " + c.options + " --out " + quote(out.string()));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("(rosw, step "), std::string::npos) << r.out;
    const json run = json::parse(read_text(out / "run.json"));
    EXPECT_EQ(run["solver"].get<std::string>(), "rosw");
    EXPECT_DOUBLE_EQ(run["fixed_step"].get<double>(), c.step_s);
    EXPECT_EQ(run["substeps"].get<long>(), 0) << c.options;
    EXPECT_GT(run["nonlinear_iterations"].get<long>(), 0) << "the dampers' rows were not iterated";
    const auto replayed = objectives_of(out);
    ASSERT_EQ(replayed.size(), ref.size()) << c.options;
    for (const auto& [name, v] : replayed) {
      ASSERT_TRUE(ref.count(name)) << name;
      const auto& [value, sensitivity] = ref.at(name);
      EXPECT_LT(std::fabs(v.first - value), c.value_bound * std::fabs(value)) << name << " at " << c.step_s;
      EXPECT_LT(std::fabs(v.second - sensitivity), c.sensitivity_bound * std::fabs(sensitivity))
          << name << " at " << c.step_s;
    }
  }
}

TEST_F(ReplayNoise, RosenbrockAtAQuarterMillisecondCompletes) {
  const std::string input = noisy_recording(0.002);  // 500 Hz
  const std::string path = short_scene();
  const fs::path out = dir_ / "out";
  const ProcessResult r = dydp("replay " + quote(path) + " --input " + quote(input) +
                               " --solver rosw --step 0.00025 --out " + quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const json run = json::parse(read_text(out / "run.json"));
  EXPECT_EQ(run["solver"].get<std::string>(), "rosw");
  EXPECT_EQ(run["steps"].get<long>(), 8000 + run["substeps"].get<long>());  // a halving adds one step
  EXPECT_GT(run["local_jacobian_refreshes"].get<long>(), 0);
  const json objectives = json::parse(read_text(out / "objectives.json"))["objectives"];
  ASSERT_EQ(objectives.size(), 2u) << objectives.dump();
  for (const auto& [name, o] : objectives.items()) {
    EXPECT_GT(o["value"].get<double>(), 0.0) << name;
    ASSERT_FALSE(o["sensitivity"].empty()) << name;
    for (const auto& [direction, s] : o["sensitivity"].items()) EXPECT_TRUE(std::isfinite(s.get<double>())) << name;
  }
}

}  // namespace
}  // namespace dydp::test
