// `dydp replay` checked by value: a rig scene whose own road.fourposter would drive other sines
// is replayed from a recording of different sines, sampled at 250 Hz (between the 500 Hz output
// samples the pads are interpolated), with the pad columns in another order than the file's
// (`pad_columns` names them) and the sensitivities on. The replayed pads must match the recorded
// sines' closed form, and the bodies' responses and sensitivities must match an independent run
// of the same scene with the rig replaced by source.sine blocks that produce the recording. The
// replay integrates with the scene's BDF (--solver bdf, replay's own default being Rosenbrock-W
// at 2.5 ms): what is checked here is the recording's path, to the integration's 1e-4 at most.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "io/csv.hpp"
#include "tests/apps/dydp_process.hpp"
#include "tests/grid_error.hpp"

namespace dydp::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

/// The recorded pad motions: a sine each, at frequencies and phases the rig's own settings do
/// not produce (its scene says 1.5 Hz on fl, 2 Hz elsewhere, plus noise).
struct PadSine {
  const char* column;
  double amplitude, frequency, phase;
  double at(double t) const { return amplitude * std::sin(2 * std::numbers::pi * frequency * t + phase); }
};
const PadSine kFrontLeft{"front_left", 0.012, 2.3, 0.4};
const PadSine kFrontRight{"front_right", 0.004, 1.1, 0.0};
const PadSine kRearLeft{"rear_left", 0.006, 0.7, 1.0};
const PadSine kRearRight{"rear_right", 0.008, 3.1, -0.6};

// Two bodies on springs, driven by the pads fl and rr through springs of 40 kN/m; the body
// stiffness and damping are the sensitivity parameters.
const char* const kSceneHead = R"(time: {start: 0.0, stop: 3.0, output_step: 0.002}
solver: {method: bdf, rtol: 1.0e-9, atol: 1.0e-12}
parameters:
  stiffness: {value: 40000.0, unit: N/m, range: [1000.0, 1.0e6]}
  damping: {value: 800.0, unit: N s/m, range: [0.0, 1.0e5]}
sensitivities: [stiffness, damping]
)";
const char* const kBodies = R"(  spring_front: {type: math.gain, k: 40000.0}
  spring_rear: {type: math.gain, k: 40000.0}
  body_front: {type: mass_spring_damper, m: 100.0, k: $stiffness, c: $damping}
  body_rear: {type: mass_spring_damper, m: 80.0, k: $stiffness, c: $damping}
)";
const char* const kBodyConnections = R"(  - pad_fl.y -> spring_front.u
  - pad_rr.y -> spring_rear.u
  - spring_front.y -> body_front.f
  - spring_rear.y -> body_rear.f
outputs: [pad_fl.y, pad_rr.y, body_front.x, body_rear.x]
)";

std::string rig_scene() {
  return std::string("scene: rig\n") + kSceneHead + R"(blocks:
  rig: {type: road.fourposter, amplitude_fl: 0.01, frequency_fl: 1.5, noise_rms: 0.0005, noise_high: 8.0,
        pad_columns: [front_left, front_right, rear_left, rear_right]}
  pad_fl: {type: math.demux, width: 4, indices: [0]}
  pad_rr: {type: math.demux, width: 4, indices: [3]}
)" + kBodies + "connections:\n  - rig.z -> pad_fl.u\n  - rig.z -> pad_rr.u\n" + kBodyConnections;
}

std::string sine(const char* name, const PadSine& s) {
  std::ostringstream out;
  out << std::setprecision(17) << "  " << name << ": {type: source.sine, amplitude: " << s.amplitude
      << ", frequency: " << s.frequency << ", phase: " << s.phase << "}\n";
  return out.str();
}

/// The same bodies driven by the recorded sines themselves; `output_step` sets its grid.
std::string sine_scene(double output_step) {
  std::string head = kSceneHead;
  head.replace(head.find("output_step: 0.002"), 18, "output_step: " + std::to_string(output_step));
  return "scene: rig\n" + head + "blocks:\n" + sine("pad_fl", kFrontLeft) + sine("pad_rr", kRearRight) + kBodies +
         "connections:\n" + kBodyConnections;
}

class ReplayValues : public DydpProcessTest {
 protected:
  ReplayValues() : DydpProcessTest("dydp_replay_values_") {}
};

TEST_F(ReplayValues, ReplayFollowsTheRecordingNotTheRig) {
  // The independent run, on the recording's 250 Hz grid: its body_front.x is the "measured"
  // response the recording carries.
  const fs::path sines_250 = dir_ / "sines_250";
  ProcessResult r = dydp("run " + quote(write("sines_250.yaml", sine_scene(0.004))) + " --no-sens --out " +
                         quote(sines_250.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const io::CsvFile measured = io::read_csv((sines_250 / "signals.csv").string());
  const std::vector<double>& t_rec = column(measured, "t");
  ASSERT_EQ(t_rec.size(), 751u);

  // Recording: columns in an order of their own, the measured response among the pads.
  std::ostringstream rec;
  rec << std::setprecision(17) << "t,rear_right,body_front.x,front_left,rear_left,front_right\n";
  for (size_t k = 0; k < t_rec.size(); ++k) {
    const double t = t_rec[k];
    rec << t << ',' << kRearRight.at(t) << ',' << column(measured, "body_front.x")[k] << ',' << kFrontLeft.at(t)
        << ',' << kRearLeft.at(t) << ',' << kFrontRight.at(t) << '\n';
  }
  const std::string recording = write("bench.csv", rec.str());

  const fs::path replay = dir_ / "replay";
  r = dydp("replay " + quote(write("rig.yaml", rig_scene())) + " --input " + quote(recording) +
           " --solver bdf --out " + quote(replay.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const io::CsvFile replayed = io::read_csv((replay / "signals.csv").string());
  const std::vector<double>& t = column(replayed, "t");
  ASSERT_EQ(t.size(), 1501u);

  // The pads between samples against the sines themselves. The recording is interpolated by a
  // not-a-knot cubic spline, within about (w h)^4 x 5 / 384 of a sine: 4.8e-7 of the amplitude
  // at 3.1 Hz sampled at 250 Hz (SciPy's CubicSpline on the same samples: 3.5e-7 inside, 8.9e-7
  // in the first and last interval). The central-difference Hermite cubic it replaced was
  // 1.2e-5 off inside and 4.5e-4 at the ends; a linear interpolation (w h)^2 / 8 = 7.6e-4.
  for (const auto& [signal, pad] : {std::pair{"pad_fl.y", kFrontLeft}, std::pair{"pad_rr.y", kRearRight}}) {
    const std::vector<double>& y = column(replayed, signal);
    double inside = 0, ends = 0;
    for (size_t k = 0; k < t.size(); ++k) {
      const double error = std::fabs(y[k] - pad.at(t[k])) / pad.amplitude;
      double& worst = t[k] <= 0.004 || t[k] >= 2.996 ? ends : inside;
      worst = std::max(worst, error);
    }
    EXPECT_LT(inside, 1e-6) << signal;
    EXPECT_LT(ends, 3e-6) << signal;
  }

  // The responses and their sensitivities against the sines' own run on the replay's grid.
  const fs::path sines = dir_ / "sines";
  r = dydp("run " + quote(write("sines.yaml", sine_scene(0.002))) + " --out " + quote(sines.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const io::CsvFile independent = io::read_csv((sines / "signals.csv").string());
  ASSERT_EQ(column(independent, "t").size(), t.size());
  for (const std::string body : {"body_front.x", "body_rear.x"}) {
    EXPECT_LT(grid_error(column(replayed, body), column(independent, body)), 1e-4) << body;
    for (const std::string p : {"stiffness", "damping"}) {
      const std::string name = "d(" + body + ")/d(" + p + ")";
      EXPECT_LT(grid_error(column(replayed, name), column(independent, name)), 1e-4) << name;
    }
  }

  // replay.json compares the replayed body_front.x with the recording's measured column.
  const json v = json::parse(read_text(replay / "replay.json"))["validation"];
  ASSERT_TRUE(v.contains("body_front.x")) << v.dump();
  EXPECT_EQ(v.size(), 1u) << "pad columns are no logged signals: " << v.dump();
  EXPECT_GT(v["body_front.x"]["correlation"].get<double>(), 0.99999) << v.dump();
  // The measured column is interpolated linearly at the 500 Hz grid: (w h)^2 / 8 of the
  // response's amplitude (about 2 cm) is 3e-6 m.
  EXPECT_LT(v["body_front.x"]["rms_error"].get<double>(), 1e-5) << v.dump();
}

}  // namespace
}  // namespace dydp::test
