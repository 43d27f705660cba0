// End-to-end `dydp replay`: a recorded run replayed from its recording reproduces the recorded
// response (and not that of another recording), paced to the wall clock with --realtime; a scene
// without a recorded input exits 2.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "tests/apps/cli_fixture.hpp"

namespace dydp::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// ---------------------------------------------------------------- replay

// A synthetic 4-poster run is recorded (pads and a response), then replayed through the same
// scene from the recording: the replayed response matches the recorded one.
TEST_F(Cli, ReplayOfARecordedRunReproducesItsResponse) {
  const std::string scene = write("rig.yaml", R"(scene: rig
time: {start: 0.0, stop: 4.0, output_step: 0.002}
solver: {method: bdf, rtol: 1.0e-8, atol: 1.0e-10}
blocks:
  rig: {type: road.fourposter, amplitude_fl: 0.01, frequency_fl: 1.5, noise_rms: 0.0005, noise_high: 8.0}
  pad: {type: math.demux, width: 4, indices: [0]}
  spring: {type: math.gain, k: 40000.0}
  body: {type: mass_spring_damper, m: 100.0, k: 40000.0, c: 800.0}
connections:
  - rig.z -> pad.u
  - pad.y -> spring.u
  - spring.y -> body.f
outputs: [rig.z, body.x]
)");
  const fs::path synthetic = dir_ / "synthetic";
  ASSERT_EQ(dydp("run " + quote(scene) + " --no-sens --out " + quote(synthetic.string())).status, 0);
  // Recording: t, the four pads (named as the bench names them), and the measured response.
  const auto rows = split(read_text(synthetic / "signals.csv"), '\n');
  std::ostringstream rec;
  rec << "t,fl,fr,rl,rr,body.x\n";
  for (size_t k = 1; k < rows.size(); k += 2) rec << rows[k] << "\n";  // every other sample: 500 Hz
  const std::string recording = write("bench.csv", rec.str());

  const fs::path out = dir_ / "replay";
  const Result r = dydp("replay " + quote(scene) + " --input " + quote(recording) + " --no-sens --out " + quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(read_text(out / "replay.json"));
  const auto& v = j["validation"]["body.x"];
  EXPECT_GT(v["correlation"].get<double>(), 0.9999) << j.dump();
  EXPECT_LT(v["rms_error"].get<double>(), 1e-4) << j.dump();  // body.x swings about 1 cm
  EXPECT_TRUE(fs::exists(out / "signals.csv"));
  EXPECT_FALSE(fs::exists(out / "signals.csv.partial"));
  EXPECT_TRUE(fs::exists(out / "run.json"));

  // Paced to the wall clock, 4 s of simulation take at least about 4 s.
  const auto start = std::chrono::steady_clock::now();
  const Result paced = dydp("replay " + quote(scene) + " --input " + quote(recording) +
                            " --no-sens --realtime --out " + quote((dir_ / "paced").string()));
  ASSERT_EQ(paced.status, 0) << paced.err;
  EXPECT_GE(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 3.9);
  EXPECT_TRUE(json::parse(read_text(dir_ / "paced" / "replay.json")).contains("missed_deadlines"));
}

TEST_F(Cli, ReplayOfASceneWithoutRecordedInputExitsTwo) {
  const std::string recording = write("bench.csv", "t,fl,fr,rl,rr\n0,0,0,0,0\n1,0,0,0,0\n");
  const Result r = dydp("replay " + quote(msd_scene()) + " --input " + quote(recording) + " --out " + quote((dir_ / "o").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("input_file"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace dydp::test
