// `dydp replay` of the main scene at a fixed step on a recording with content up to its Nyquist
// frequency: the 4-poster's 1 Hz, +-10 mm out of phase, plus 0.5 mm rms of white noise sampled
// at 200 Hz, replayed with SDIRK2 at 5 ms (one step per sample) and the sensitivity on. The CDC
// dampers' valves then change faster than a 5 ms step's Newton iteration can follow at some
// steps; those are taken in halves (run.json: substeps), and the replay completes (it stopped at
// t = 0.595 s before the halving existed, the binary of 1596ed1) with finite objectives and
// sensitivities.
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
};

TEST_F(ReplayNoise, FixedStepReplayOfANoisyRecordingCompletesWithHalvedSteps) {
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.0005);
  std::ostringstream csv;
  csv << "t,fl,fr,rl,rr\n";
  for (int k = 0; k <= 400; ++k) {  // 2 s at 200 Hz
    const double t = 0.005 * k, z = 0.01 * std::sin(2 * std::numbers::pi * t);
    csv << t << ',' << z + noise(rng) << ',' << -z + noise(rng) << ',' << z + noise(rng) << ',' << -z + noise(rng)
        << '\n';
  }
  const std::string input = write("noisy.csv", csv.str());
  std::string scene = scene_copy_text(source_path("scenarios/fourposter_comfort.yaml"));
  scene = replaced(scene, "stop: 20.0", "stop: 2.0");
  for (int i = 0; i < 2; ++i) scene.replace(scene.find("window: [2.0, 20.0]"), 19, "window: [0.5, 2.0]");
  const std::string path = write("scene.yaml", scene);
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

}  // namespace
}  // namespace dydp::test
