// `dydp replay`'s default, error-controlled Rosenbrock-W, by value on recordings of two kinds the
// replay benchmarks hold (bench/replay/make_recordings.py): 3 s of an ISO 8608 class C road at
// 20 m/s sampled at 1 kHz, and a 0.5-25 Hz heave and roll chirp of 2 mm. Against a BDF replay at
// rtol = atol = 1e-9 (a converged reference, a different integrator):
// - every logged signal within 1 % and every sensitivity column within 5 % (the stated target,
//   the metric of docs/accuracy.md: worst over the grid over the column's largest magnitude);
// - the run's own estimate (run.json error_estimate) within a factor 3 of the measured error.
// A replay of the road differs from a replay of a flat recording at the pads and at the body by
// far more than the target (the recording is read), and a fixed step too coarse for the chirp
// (2.5 ms, replay's default until the error control) reports an estimate above the target and
// warns on stderr.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <sstream>

#include "io/csv.hpp"
#include "tests/apps/dydp_process.hpp"

namespace dydp::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr double kSeconds = 3.0;
constexpr double kWheelbase = 2.776;  // shared/reference/sedan.md

class ReplayError : public DydpProcessTest {
 protected:
  ReplayError() : DydpProcessTest("dydp_replay_error_") {}

  std::string write_pads(const std::string& name, double rate, const std::function<double(int, double)>& pad) {
    std::ostringstream csv;
    csv.precision(10);
    csv << "t,fl,fr,rl,rr\n";
    const long samples = std::lround(kSeconds * rate);
    for (long k = 0; k <= samples; ++k) {
      const double t = k / rate;
      csv << t;
      for (int p = 0; p < 4; ++p) csv << ',' << pad(p, t);
      csv << '\n';
    }
    return write(name, csv.str());
  }

  /// ISO 8608 class C (Gd(n0) = 256e-6 m^3 at n0 = 0.1 cycles/m, slope -2) at 20 m/s: sines
  /// at spatial frequencies 0.011 to 10 cycles/m, left and right independent, each rear the
  /// front a wheelbase later.
  std::string class_c_road() {
    std::mt19937 rng(2026);
    std::uniform_real_distribution<double> phase(0.0, 2 * std::numbers::pi);
    struct Sine {
      double n, a, phase[2];
    };
    std::vector<Sine> sines;
    const double dn = 0.005, speed = 20.0;
    for (double n = 0.011; n < 10.0; n += dn)
      sines.push_back({n, std::sqrt(2 * 256e-6 * std::pow(n / 0.1, -2) * dn), {phase(rng), phase(rng)}});
    auto height = [&](int side, double x) {
      double z = 0;
      for (const Sine& s : sines) z += s.a * (std::sin(2 * std::numbers::pi * s.n * x + s.phase[side]) - std::sin(s.phase[side]));
      return z;
    };
    return write_pads("road_c.csv", 1000.0, [&](int p, double t) {
      const double x = speed * t + (p < 2 ? kWheelbase : 0.0);
      return height(p % 2, x);
    });
  }

  std::string chirp() {
    const double f0 = 0.5, f1 = 25.0, rate = std::log(f1 / f0) / kSeconds;
    return write_pads("chirp.csv", 1000.0, [&](int p, double t) {
      const double phi = 2 * std::numbers::pi * f0 * (std::exp(rate * t) - 1) / rate;
      return 0.002 * std::sin(phi - (p % 2 ? std::numbers::pi / 2 : 0.0));
    });
  }

  std::string flat() {
    return write_pads("flat.csv", 1000.0, [](int, double) { return 0.0; });
  }

  std::string short_scene() {
    std::string scene = scene_copy_text(source_path("scenarios/fourposter_comfort.yaml"));
    scene = replaced(scene, "stop: 20.0", "stop: 3.0");
    for (int i = 0; i < 2; ++i) scene.replace(scene.find("window: [2.0, 20.0]"), 19, "window: [0.5, 3.0]");
    return write("scene.yaml", scene);
  }

  fs::path replay(const std::string& scene, const std::string& input, const std::string& options,
                  const std::string& name, ProcessResult* result = nullptr) {
    const fs::path out = dir_ / name;
    const ProcessResult r =
        dydp("replay " + quote(scene) + " --input " + quote(input) + " " + options + " --out " + quote(out.string()));
    EXPECT_EQ(r.status, 0) << r.err;
    if (result) *result = r;
    return out;
  }
};

struct Errors {
  double signals = 0, sensitivities = 0;
};

/// The worst over the grid of |run - ref| over the reference column's largest magnitude, over
/// the signals and over the sensitivity columns; columns whose reference is zero left out.
Errors measured(const fs::path& ref_dir, const fs::path& run_dir) {
  const io::CsvFile ref = io::read_csv((ref_dir / "signals.csv").string());
  const io::CsvFile run = io::read_csv((run_dir / "signals.csv").string());
  Errors e;
  for (size_t c = 1; c < ref.names.size(); ++c) {
    const int k = run.find(ref.names[c]);
    EXPECT_GE(k, 0) << ref.names[c];
    if (k < 0) continue;
    double scale = 0, worst = 0;
    for (size_t i = 0; i < ref.columns[c].size(); ++i) {
      scale = std::max(scale, std::fabs(ref.columns[c][i]));
      worst = std::max(worst, std::fabs(ref.columns[c][i] - run.columns[k][i]));
    }
    if (scale <= 1e-12) continue;
    double& slot = ref.names[c].rfind("d(", 0) == 0 ? e.sensitivities : e.signals;
    slot = std::max(slot, worst / scale);
  }
  return e;
}

TEST_F(ReplayError, DefaultReplayMeetsItsTargetAndEstimatesItsErrorOnARoadAndAChirp) {
  const std::string scene = short_scene();
  for (const auto& [kind, input] : {std::pair{"road", class_c_road()}, std::pair{"chirp", chirp()}}) {
    const fs::path ref = replay(scene, input, "--solver bdf --rtol 1e-9 --atol 1e-9 --no-estimate", std::string("ref_") + kind);
    const fs::path out = replay(scene, input, "", std::string("default_") + kind);
    const json run = json::parse(read_text(out / "run.json"));
    EXPECT_EQ(run["solver"].get<std::string>(), "rosw");
    EXPECT_EQ(run["fixed_step"].get<double>(), 0.0) << "the default is error-controlled";
    const Errors e = measured(ref, out);
    EXPECT_LT(e.signals, 0.01) << kind;
    EXPECT_LT(e.sensitivities, 0.05) << kind;
    const json& est = run["error_estimate"];
    ASSERT_TRUE(est.is_object()) << run.dump(2);
    const double es = est["signals"].get<double>(), ed = est["sensitivities"].get<double>();
    EXPECT_GT(es, e.signals / 3) << kind;
    EXPECT_LT(es, e.signals * 3) << kind;
    EXPECT_GT(ed, e.sensitivities / 3) << kind;
    EXPECT_LT(ed, e.sensitivities * 3) << kind;
    // Tighter tolerances give a smaller error: --rtol and --atol set the default's accuracy.
    const fs::path tight = replay(scene, input, "--rtol 2e-4 --atol 2e-4", std::string("tight_") + kind);
    const Errors et = measured(ref, tight);
    EXPECT_LT(et.signals, e.signals) << kind;
  }
}

TEST_F(ReplayError, ARecordingChangesTheReplayAtThePadsAndTheBody) {
  const std::string scene = short_scene();
  const fs::path road = replay(scene, class_c_road(), "--no-estimate", "road");
  const fs::path still = replay(scene, flat(), "--no-estimate", "flat");
  const io::CsvFile a = io::read_csv((road / "signals.csv").string());
  const io::CsvFile b = io::read_csv((still / "signals.csv").string());
  for (const char* name : {"corner_fl.tyre.force", "car.body_acc_z"}) {  // at the pad, at the body
    const int ia = a.find(name), ib = b.find(name);
    ASSERT_GE(ia, 0) << name;
    ASSERT_GE(ib, 0) << name;
    double scale = 0, diff = 0;
    for (size_t i = 0; i < a.columns[ia].size(); ++i) {
      scale = std::max(scale, std::fabs(a.columns[ia][i]));
      diff = std::max(diff, std::fabs(a.columns[ia][i] - b.columns[ib][i]));
    }
    ASSERT_GT(scale, 0) << name;
    // Five times replay's 1 % target for the signals: the recording, not the error, tells them apart.
    EXPECT_GT(diff / scale, 0.05) << name << ": the replay did not follow the recording";
  }
}

TEST_F(ReplayError, ACoarseFixedStepReportsAnEstimateAboveTheTargetAndWarns) {
  const std::string scene = short_scene();
  ProcessResult r;
  const fs::path out = replay(scene, chirp(), "--step 0.0025", "coarse", &r);
  const json run = json::parse(read_text(out / "run.json"));
  EXPECT_DOUBLE_EQ(run["fixed_step"].get<double>(), 0.0025);
  const json& est = run["error_estimate"];
  ASSERT_TRUE(est.is_object());
  EXPECT_GT(est["sensitivities"].get<double>(), 0.05);
  EXPECT_NE(r.err.find("above the"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace dydp::test
