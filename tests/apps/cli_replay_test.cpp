// End-to-end `dydp replay`: a recorded run replayed from its recording reproduces the recorded
// response (and not that of another recording), paced to the wall clock with --realtime; a scene
// without a recorded input exits 2.
#include <gtest/gtest.h>

#include <algorithm>
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
// scene from the recording: the replayed response matches the recorded one. The same response
// under flat pads is replayed too, and must not match: a replay that ran the scene's own rig
// instead of the recording would pass the first check but not this one.
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

  // The recording with the pads held at zero and the response left as it was: the replayed pad
  // and body must follow the flat pads, about 1 cm away from the recorded ones (far beyond the
  // bounds above), not the scene's own 1.5 Hz rig.
  std::ostringstream flat_rec;
  flat_rec << "t,fl,fr,rl,rr,body.x\n";
  for (size_t k = 1; k < rows.size(); k += 2) {
    const auto cells = split(rows[k], ',');
    ASSERT_EQ(cells.size(), 6u) << rows[k];
    flat_rec << cells[0] << ",0,0,0,0," << cells[5] << "\n";
  }
  const fs::path flat_out = dir_ / "flat";
  const Result flat = dydp("replay " + quote(scene) + " --input " + quote(write("flat.csv", flat_rec.str())) +
                           " --no-sens --out " + quote(flat_out.string()));
  ASSERT_EQ(flat.status, 0) << flat.err;
  const json flat_j = json::parse(read_text(flat_out / "replay.json"));
  // Measured: the flat replay's rms error 8.7e-3 and correlation 0 (1.3e-6 and 1 - 6e-9 above).
  EXPECT_GT(flat_j["validation"]["body.x"]["rms_error"].get<double>(), 50 * 1e-4) << flat_j.dump();
  EXPECT_LT(flat_j["validation"]["body.x"]["correlation"].get<double>(), 0.5) << flat_j.dump();
  const io::CsvFile recorded = io::read_csv((synthetic / "signals.csv").string());
  const io::CsvFile replayed = io::read_csv((out / "signals.csv").string());
  const io::CsvFile flat_replayed = io::read_csv((flat_out / "signals.csv").string());
  ASSERT_EQ(replayed.columns.at(0).size(), recorded.columns.at(0).size());
  ASSERT_EQ(flat_replayed.columns.at(0).size(), recorded.columns.at(0).size());
  for (const char* signal : {"rig.z[0]", "body.x"}) {
    const std::vector<double>& want = column(recorded, signal);
    double replay_error = 0.0, flat_error = 0.0;
    for (size_t k = 0; k < want.size(); ++k) {
      replay_error = std::max(replay_error, std::fabs(column(replayed, signal)[k] - want[k]));
      flat_error = std::max(flat_error, std::fabs(column(flat_replayed, signal)[k] - want[k]));
    }
    // Measured: the replay within 5e-9 (pad) and 8e-7 (body) of the recorded run, the flat
    // replay 1.1e-2 and 1.4e-2 away.
    EXPECT_LT(replay_error, 1e-5) << signal;
    EXPECT_GT(flat_error, 500 * 1e-5) << signal << ": the flat recording was not replayed";
  }

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
