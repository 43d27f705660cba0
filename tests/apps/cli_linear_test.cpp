// End-to-end `dydp equilibrium`, `linearize`, `modes` and `frf` on the shipped sedan scene: the
// files each writes and their shape, the sedan's ride modes where a vehicle engineer expects
// them, and bad input refused by name with exit 2 and nothing written.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "io/csv.hpp"
#include "tests/apps/cli_fixture.hpp"

namespace dydp::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string sedan() { return source_path("scenarios/fourposter_comfort.yaml").string(); }

json read_json(const fs::path& p) { return json::parse(read_text(p)); }

TEST_F(Cli, EquilibriumWritesStatesSignalsAndSensitivities) {
  const Result r = dydp("equilibrium " + quote(sedan()) + " --hold rig.zdot=0 --out " + quote((dir_ / "eq").string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = read_json(dir_ / "eq/equilibrium.json");
  EXPECT_LT(j["residual"].get<double>(), 1e-8);
  EXPECT_EQ(j["held"].size(), 4u);  // rig.zdot[0..3]
  EXPECT_TRUE(j["state"].contains("car.q.z"));
  EXPECT_TRUE(j["signals"].contains("corner_fl.tyre.force"));
  // The front tyres carry a quarter of about 1 500 kg each, give or take the weight distribution.
  const double tyre = j["signals"]["corner_fl.tyre.force"].get<double>();
  EXPECT_GT(tyre, 2500.0);
  EXPECT_LT(tyre, 5500.0);
  // Every declared parameter and direction has its column (2 parameters, 16 directions).
  EXPECT_EQ(j["sensitivity"].size(), 18u);
  EXPECT_NE(j["sensitivity"]["spring_front"]["car.q.z"].get<double>(), 0.0);
  EXPECT_NE(r.out.find("corner_fl.tyre.force"), std::string::npos) << r.out;
}

TEST_F(Cli, ModesAreTheSedansRideModes) {
  const Result r = dydp("modes " + quote(sedan()) + " --hold rig.zdot=0 --out " + quote((dir_ / "m").string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = read_json(dir_ / "m/modes.json");
  int body = 0, hop = 0;
  double last = -1.0;
  for (const json& m : j["modes"]) {
    const double f = m["frequency_hz"].get<double>(), zeta = m["damping_ratio"].get<double>();
    EXPECT_GE(f, last) << "sorted by frequency";
    last = f;
    const std::string first = m["dominant"][0].get<std::string>();
    if (f > 0.9 && f < 2.0 && first.rfind("car.q", 0) == 0) {
      ++body;
      EXPECT_GT(zeta, 0.08) << f << " Hz";  // damped, not unstable
      EXPECT_LT(zeta, 0.5) << f << " Hz";
    }
    if (f > 10.0 && f < 20.0 && first.rfind("car.", 0) == 0) ++hop;
    EXPECT_EQ(m["sensitivity"].size(), 18u);
  }
  EXPECT_EQ(body, 3) << "heave, pitch and roll between 0.9 and 2 Hz";
  EXPECT_EQ(hop, 4) << "a wheel hop per corner between 10 and 20 Hz";
  EXPECT_TRUE(fs::exists(dir_ / "m/modes.csv"));
}

TEST_F(Cli, LinearizeWritesTheFourMatrices) {
  const Result r = dydp("linearize " + quote(sedan()) + " --hold rig.zdot=0 --input rig.z[0] --output car.body_acc_z --out " + quote((dir_ / "l").string()) + " --format mat");
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = read_json(dir_ / "l/linearization.json");
  const size_t n = j["states"].size();
  EXPECT_EQ(n, 52u);
  EXPECT_EQ(j["A"].size(), n);
  EXPECT_EQ(j["B"][0].size(), 1u);
  EXPECT_EQ(j["C"].size(), 1u);
  EXPECT_EQ(j["D"][0].size(), 1u);
  for (const char* f : {"A.csv", "B.csv", "C.csv", "D.csv", "linearization.mat"}) EXPECT_TRUE(fs::exists(dir_ / "l" / f)) << f;
}

TEST_F(Cli, FrfWritesMagnitudePhaseAndDerivatives) {
  const Result r = dydp("frf " + quote(sedan()) + " --hold rig.zdot=0 --input rig.z:rig.zdot --output car.body_acc_z --frequencies 0.5:30:40 --out " + quote((dir_ / "f").string()) + " --report");
  ASSERT_EQ(r.status, 0) << r.err;
  const io::CsvFile csv = io::read_csv((dir_ / "f/frf.csv").string());
  const auto& f = column(csv, "frequency_hz");
  const auto& mag = column(csv, "magnitude(car.body_acc_z/rig.z)");
  ASSERT_EQ(f.size(), 40u);
  EXPECT_NEAR(f.front(), 0.5, 1e-12);
  EXPECT_NEAR(f.back(), 30.0, 1e-9);
  // Heave at 0.5 Hz, well below the ride frequency: the body follows the pads, |a / z| ~ w^2.
  const double w = 2 * M_PI * 0.5;
  EXPECT_NEAR(mag.front() / (w * w), 1.0, 0.25);
  EXPECT_NO_THROW(column(csv, "d(magnitude(car.body_acc_z/rig.z))/d(valve_current)"));
  EXPECT_NO_THROW(column(csv, "phase_deg(car.body_acc_z/rig.z)"));
  EXPECT_TRUE(fs::exists(dir_ / "f/report.md"));
}

// The ISO 2631 weighted transmissibility: the band rms of |H| from the pads to the Wk filter's
// output, with its derivatives, in frf.json; it equals the trapezoid rule over frf.csv's
// magnitudes, and weighting removes part of what the wheel hop transmits.
TEST_F(Cli, FrfWritesTheWeightedTransmissibilityWithItsDerivatives) {
  const Result r = dydp("frf " + quote(sedan()) + " --hold rig.zdot=0 --input rig.z:rig.zdot --output car.body_acc_z --output "
                        "wk.a_weighted --frequencies 0.5:30:40 --out " + quote((dir_ / "w").string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = read_json(dir_ / "w/frf.json");
  const json& weighted = j["objectives"]["rms(|wk.a_weighted/rig.z|)"];
  const json& plain = j["objectives"]["rms(|car.body_acc_z/rig.z|)"];
  ASSERT_TRUE(weighted.is_object()) << j.dump(1);
  EXPECT_EQ(weighted["sensitivity"].size(), 18u);
  // Wk passes 4-10 Hz whole (gain up to 1.05) and halves what lies below 2 Hz and above 25 Hz:
  // on the sedan, whose pads transmit most at the wheel hop, it removes a quarter.
  EXPECT_LT(weighted["value"].get<double>(), 0.9 * plain["value"].get<double>());
  EXPECT_GT(weighted["value"].get<double>(), 0.5 * plain["value"].get<double>());
  EXPECT_NE(weighted["sensitivity"]["spring_front"].get<double>(), 0.0);
  const io::CsvFile csv = io::read_csv((dir_ / "w/frf.csv").string());
  const auto& f = column(csv, "frequency_hz");
  const auto& mag = column(csv, "magnitude(wk.a_weighted/rig.z)");
  double sum = 0.0;
  for (size_t k = 0; k + 1 < f.size(); ++k) sum += 0.5 * (f[k + 1] - f[k]) * (mag[k] * mag[k] + mag[k + 1] * mag[k + 1]);
  EXPECT_NEAR(weighted["value"].get<double>(), std::sqrt(sum / (f.back() - f.front())), 1e-8 * weighted["value"].get<double>());
}

TEST_F(Cli, LinearCommandsRefuseUnknownSignalsAndWriteNothing) {
  for (const std::string& args : {"frf " + quote(sedan()) + " --input rig.nope --output car.body_acc_z --out " + quote((dir_ / "bad").string()),
                                  "frf " + quote(sedan()) + " --input rig.z --output car.nothing --out " + quote((dir_ / "bad").string()),
                                  "linearize " + quote(sedan()) + " --input nowhere.y --out " + quote((dir_ / "bad").string()),
                                  "modes " + quote(sedan()) + " --hold rig.zdot --out " + quote((dir_ / "bad").string()),
                                  "equilibrium " + quote(sedan()) + " --hold rig.zdot=x --out " + quote((dir_ / "bad").string()),
                                  "frf " + quote(sedan()) + " --input rig.z --output car.body_acc_z --frequencies 30:1:5 --out " + quote((dir_ / "bad").string())}) {
    const Result r = dydp(args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "bad")) << args;
    EXPECT_FALSE(r.err.empty()) << args;
  }
  const Result r = dydp("frf " + quote(sedan()) + " --input rig.nope --output car.body_acc_z --out " + quote((dir_ / "bad").string()));
  EXPECT_NE(r.err.find("--input: rig.nope: block rig has no output nope"), std::string::npos) << r.err;
}

TEST_F(Cli, ASceneWithoutEquilibriumIsASolverFailure) {
  // The cornering scene drives on: its state derivatives never vanish.
  const Result r = dydp("equilibrium " + quote(source_path("scenarios/cornering_arb.yaml").string()) + " --out " + quote((dir_ / "none").string()));
  EXPECT_EQ(r.status, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("no equilibrium in reach"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "none"));
}

TEST_F(Cli, SceneHoldsAreTheEquilibriumsAndAHoldOptionReplacesOne) {
  // The sedan with `initial.hold` in the scene (its runs still start from the declared state).
  const std::string time = "time: {start: 0.0, stop: 20.0, output_step: 0.01}";
  const std::string held = write("held.yaml", replaced(scene_copy_text(sedan()), time,
                                                       time + "\ninitial: {state: declared, hold: {rig.zdot: 0.0}}"));
  const Result from_scene = dydp("equilibrium " + quote(held) + " --out " + quote((dir_ / "a").string()));
  ASSERT_EQ(from_scene.status, 0) << from_scene.err;
  const Result from_option = dydp("equilibrium " + quote(sedan()) + " --hold rig.zdot=0 --out " + quote((dir_ / "b").string()));
  ASSERT_EQ(from_option.status, 0) << from_option.err;
  const json a = read_json(dir_ / "a/equilibrium.json"), b = read_json(dir_ / "b/equilibrium.json");
  EXPECT_EQ(a["held"], b["held"]);
  EXPECT_EQ(a["state"], b["state"]);
  // --hold of the same signal replaces the scene's value: the pads held rising at 0.01 m/s.
  const Result replaced = dydp("equilibrium " + quote(held) + " --hold rig.zdot=0.01 --out " + quote((dir_ / "c").string()));
  ASSERT_EQ(replaced.status, 0) << replaced.err;
  const json c = read_json(dir_ / "c/equilibrium.json");
  EXPECT_EQ(c["held"].size(), 4u);
  for (const auto& [name, value] : c["held"].items()) EXPECT_EQ(value.get<double>(), 0.01) << name;
  EXPECT_NE(c["state"], a["state"]);
}

}  // namespace
}  // namespace dydp::test
