// `dydp replay` of the main scene at a fixed step on a recording with content up to its Nyquist
// frequency: the 4-poster's 1 Hz, +-10 mm out of phase, plus 0.5 mm rms of white noise sampled
// at 200 Hz, replayed with SDIRK2 at 5 ms (one step per sample) and the sensitivity on. The CDC
// dampers' valves then change faster than a 5 ms step's Newton iteration can follow at some
// steps; those are taken in halves (run.json: substeps), and the replay completes (it stopped at
// t = 0.595 s before the halving existed, the binary of 1596ed1) with finite objectives and
// sensitivities.
// The same with the Rosenbrock-W scheme (rosw) on white noise sampled at 500 Hz: at one step per
// sample (2 ms) the linearised steps cannot follow the dampers' orifice laws and the run stops,
// after halving the failing step six times, saying what to change; at 0.25 ms it completes.
#include <gtest/gtest.h>

#include <cmath>
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
};

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
  for (const auto& [name, o] : objectives.items()) {
    EXPECT_TRUE(std::isfinite(o["value"].get<double>())) << name;
    EXPECT_GT(o["value"].get<double>(), 0.0) << name;
    for (const auto& [direction, s] : o["sensitivity"].items()) EXPECT_TRUE(std::isfinite(s.get<double>())) << name;
  }
}

TEST_F(ReplayNoise, RosenbrockAtOneStepPerSampleStopsSayingWhatToChange) {
  const std::string input = noisy_recording(0.002);  // 500 Hz
  const std::string path = short_scene();
  const fs::path out = dir_ / "out";
  const ProcessResult r = dydp("replay " + quote(path) + " --input " + quote(input) +
                               " --solver rosw --step 0.002 --out " + quote(out.string()));
  ASSERT_EQ(r.status, 1) << "the replay no longer stops: measure it and change this test\n" << r.out;
  EXPECT_NE(r.err.find("block corner_"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(the scene's step 0.002 s halved 6 times)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("use method sdirk2 or bdf, or a smaller step"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "run.json"));
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
  for (const auto& [name, o] : objectives.items()) {
    EXPECT_GT(o["value"].get<double>(), 0.0) << name;
    for (const auto& [direction, s] : o["sensitivity"].items()) EXPECT_TRUE(std::isfinite(s.get<double>())) << name;
  }
}

}  // namespace
}  // namespace dydp::test
