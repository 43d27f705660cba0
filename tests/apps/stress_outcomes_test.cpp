// The stress suite (scenarios/stress/*.yaml) with one fixed outcome per scene: it completes
// with finite results, or it stops with exit 1 in a stated time window naming a stated block
// and reason. A scene without an entry here fails, so a new stress scene must state its
// outcome. The physical claims of each scene's header comment are asserted on its signals:
// speeds, slip angles, lateral acceleration and yaw rate of the cornering scenes, the pothole's
// depth, length and timing and the wheel's lift-off, and the settings the quarter-car variants
// say they change (against the block's documented defaults).
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <cmath>
#include <map>
#include <numbers>
#include <ostream>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "engine/framework/registry.hpp"
#include "io/csv.hpp"
#include "tests/apps/dydp_process.hpp"

namespace dydp::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr double kG = 9.80665;  // [m/s^2]

struct Stop {
  double from, to;     ///< the time window of the failure [s]
  const char* block;   ///< the block the message names
  const char* reason;  ///< text of the reason
};

struct StressCase {
  const char* scene;
  bool completes;
  Stop stop;  ///< when it does not complete
};

// The outcomes. cornering_wheelspin: the header says the front-right damper's stroke leaves its
// chambers' length at 2.27 s. tiny_chambers: chambers of 0.4 and 0.5 cm^3 leave the piston
// 0.4e-6 / A_ann = 0.82 mm of extension and 0.5e-6 / A_p = 0.62 mm of compression, which the
// corner's first settling uses up within milliseconds (StressClaims below). The others complete.
const StressCase kCases[] = {
    {"bulk_modulus_10x", true, {}},
    {"bulk_modulus_100x", true, {}},
    {"cornering_saturation", true, {}},
    {"cornering_wheelspin", false, {2.2, 2.35, "corner_fr.damper", "stroke beyond the chambers' length"}},
    {"current_hard", true, {}},
    {"current_soft", true, {}},
    {"pothole_lift_off", true, {}},
    {"tiny_chambers", false, {0.0, 0.01, "damper", "stroke beyond the chambers' length"}},
};

void PrintTo(const StressCase& c, std::ostream* os) { *os << c.scene; }

fs::path stress_scene(const std::string& name) { return source_path("scenarios/stress/" + name + ".yaml"); }

double value_at(const io::CsvFile& csv, const std::string& name, double t) {
  const auto& ts = column(csv, "t");
  const size_t k = static_cast<size_t>(std::min_element(ts.begin(), ts.end(), [t](double a, double b) {
                                         return std::fabs(a - t) < std::fabs(b - t);
                                       }) - ts.begin());
  return column(csv, name)[k];
}

/// The damper.cdc default of a parameter (docs/blocks.md's defaults, from the registry).
double damper_default(const std::string& name, double* low = nullptr, double* high = nullptr) {
  const engine::BlockType* type = engine::Registry::global().find("damper.cdc");
  if (!type) throw std::runtime_error("damper.cdc not registered");
  for (const auto& p : type->parameters)
    if (p.name == name) {
      if (low) *low = p.lower;
      if (high) *high = p.upper;
      return p.default_value;
    }
  throw std::runtime_error("damper.cdc has no parameter " + name);
}

/// The number after `key: ` in the scene's damper line.
double damper_setting(const std::string& text, const std::string& key) {
  std::smatch m;
  const std::regex line("  damper: \\{[^\\n]*\\b" + key + ": ([-+0-9.eE]+)");
  if (!std::regex_search(text, m, line)) throw std::runtime_error("no damper " + key);
  return std::stod(m[1].str());
}

class StressOutcomes : public DydpProcessTest, public ::testing::WithParamInterface<StressCase> {
 protected:
  StressOutcomes() : DydpProcessTest("dydp_stress_") {}
};

TEST(StressSuite, EveryStressSceneHasAStatedOutcome) {
  std::set<std::string> stated;
  for (const auto& c : kCases) stated.insert(c.scene);
  int count = 0;
  for (const auto& entry : fs::directory_iterator(source_path("scenarios/stress"))) {
    if (entry.path().extension() != ".yaml") continue;
    EXPECT_TRUE(stated.count(entry.path().stem().string())) << entry.path() << " has no stated outcome";
    ++count;
  }
  EXPECT_EQ(count, static_cast<int>(std::size(kCases)));
}

// The scene as shipped, with its sensitivities: the stated outcome, and finite results.
TEST_P(StressOutcomes, OutcomeIsTheStatedOne) {
  const StressCase& c = GetParam();
  const fs::path out = dir_ / "out";
  const ProcessResult r = dydp("run " + quote(stress_scene(c.scene).string()) + " --out " + quote(out.string()));
  if (c.completes) {
    ASSERT_EQ(r.status, 0) << r.err;
    const io::CsvFile csv = io::read_csv((out / "signals.csv").string());
    for (size_t i = 0; i < csv.names.size(); ++i)
      for (double v : csv.columns[i]) ASSERT_TRUE(std::isfinite(v)) << csv.names[i];
    const json objectives = json::parse(read_text(out / "objectives.json"))["objectives"];
    EXPECT_FALSE(objectives.empty());
    for (const auto& [name, o] : objectives.items()) {
      EXPECT_TRUE(std::isfinite(o["value"].get<double>())) << name;
      EXPECT_FALSE(o["sensitivity"].empty()) << name;
      for (const auto& [p, g] : o["sensitivity"].items()) EXPECT_TRUE(std::isfinite(g.get<double>())) << name << " " << p;
    }
    return;
  }
  EXPECT_EQ(r.status, 1) << r.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.err, m, std::regex("t = ([0-9.eE+-]+)"))) << r.err;
  const double t = std::stod(m[1].str());
  EXPECT_GE(t, c.stop.from) << r.err;
  EXPECT_LE(t, c.stop.to) << r.err;
  EXPECT_NE(r.err.find(std::string("block ") + c.stop.block), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(c.stop.reason), std::string::npos) << r.err;
  EXPECT_TRUE(!fs::exists(out) || fs::is_empty(out)) << "nothing may be left in --out";
}

INSTANTIATE_TEST_SUITE_P(Scenes, StressOutcomes, ::testing::ValuesIn(kCases),
                         [](const auto& info) { return std::string(info.param.scene); });

class StressClaims : public DydpProcessTest {
 protected:
  StressClaims() : DydpProcessTest("dydp_stress_claims_") {}

  /// Runs a copy of a stress scene (edited by `edit`) without sensitivities; its signals.
  io::CsvFile run_copy(const std::string& name, const std::function<std::string(std::string)>& edit) {
    const std::string scene = write(name + ".yaml", edit(scene_copy_text(stress_scene(name))));
    const fs::path out = dir_ / name;
    const ProcessResult r = dydp("run " + quote(scene) + " --no-sens --out " + quote(out.string()));
    EXPECT_EQ(r.status, 0) << r.err;
    if (r.status != 0) throw std::runtime_error(name + " did not run: " + r.err);
    return io::read_csv((out / "signals.csv").string());
  }
};

// cornering_saturation's header: "it coasts from 25 to 17 m/s, front slip angles above 0.2 rad
// peaking at 0.41 rad, lateral acceleration 0.93 g". The slip angles are read over the hold
// (after the 1 s ramp that ends at 1.5 s), the lateral acceleration over the scene's objective
// window [4, 5] s.
TEST_F(StressClaims, CorneringSaturationCoastsAndSaturatesAsItsHeaderSays) {
  const io::CsvFile csv = run_copy("cornering_saturation", [](std::string s) { return s; });
  const auto& t = column(csv, "t");
  EXPECT_NEAR(value_at(csv, "car.body_vx", 0.0), 25.0, 1e-3);
  EXPECT_NEAR(value_at(csv, "car.body_vx", t.back()), 17.0, 1.0);
  double slip_min = INFINITY, slip_max = 0, acc = 0;
  int n = 0;
  for (size_t k = 0; k < t.size(); ++k) {
    const double slip = std::fabs(column(csv, "corner_fl.mf.slip_angle")[k]);
    if (t[k] >= 1.5) slip_min = std::min(slip_min, slip), slip_max = std::max(slip_max, slip);
    if (t[k] >= 4.0) acc += column(csv, "car.body_acc_y")[k], ++n;
  }
  EXPECT_GT(slip_min, 0.2);
  EXPECT_NEAR(slip_max, 0.41, 0.03);
  EXPECT_NEAR(std::fabs(acc / n) / kG, 0.93, 0.05);
}

// cornering_wheelspin's header: "at 2 s the car spins (yaw rate 1.4 rad/s, rear slip angle
// 0.49 rad, 10 m/s sideways)": its first 2.1 s (objective windows moved inside the run).
TEST_F(StressClaims, CorneringWheelspinSpinsAtTwoSecondsAsItsHeaderSays) {
  const io::CsvFile csv = run_copy("cornering_wheelspin", [](std::string s) {
    s = DydpProcessTest::replaced(s, "stop: 5.0", "stop: 2.1");
    while (s.find("window: [4.0, 5.0]") != std::string::npos)
      s.replace(s.find("window: [4.0, 5.0]"), 18, "window: [1.5, 2.1]");
    return s;
  });
  EXPECT_NEAR(std::fabs(value_at(csv, "car.yaw_rate", 2.0)), 1.4, 0.14);
  EXPECT_NEAR(std::fabs(value_at(csv, "corner_rl.mf.slip_angle", 2.0)), 0.49, 0.05);
  EXPECT_NEAR(std::fabs(value_at(csv, "car.body_vy", 2.0)), 10.0, 1.0);
}

// pothole_lift_off's header: "a 50 mm deep, 0.6 m long pothole at 25 m/s: impact, wheel
// lift-off". The pothole starts 20 m down the road: the wheel is over it from 0.8 s for
// 0.6 / 25 = 24 ms, at full depth between the 50 mm edges (0.802 to 0.822 s); the tyre leaves
// the road (its force falls below 1 % of the static load) while over it.
TEST_F(StressClaims, PotholeIsFiftyMillimetresDeepAndTheWheelLiftsOff) {
  const io::CsvFile csv = run_copy("pothole_lift_off", [](std::string s) {
    return DydpProcessTest::replaced(s, "outputs: [body_az.y,", "outputs: [road_z.y, body_az.y,");
  });
  const auto& t = column(csv, "t");
  const auto& road = column(csv, "road_z.y");
  const auto& tyre = column(csv, "tyre.force");
  const double static_load = tyre.front();
  EXPECT_GT(static_load, 1000.0);
  double deepest = 0, least_force = INFINITY, least_before = INFINITY;
  for (size_t k = 0; k < t.size(); ++k) {
    if (t[k] < 0.8 - 1e-9 || t[k] > 0.824 + 1e-9) {
      EXPECT_NEAR(road[k], 0.0, 1e-12) << "t = " << t[k];
    }
    if (t[k] >= 0.802 + 1e-9 && t[k] <= 0.822 - 1e-9) {
      EXPECT_NEAR(road[k], -0.05, 1e-12) << "t = " << t[k];
    }
    deepest = std::min(deepest, road[k]);
    if (t[k] < 0.8) least_before = std::min(least_before, tyre[k]);
    if (t[k] >= 0.8 && t[k] <= 0.9) least_force = std::min(least_force, tyre[k]);
  }
  EXPECT_NEAR(deepest, -0.05, 1e-12);
  EXPECT_GT(least_before, 0.5 * static_load) << "the wheel leaves the road before the pothole";
  EXPECT_LT(least_force, 0.01 * static_load) << "no lift-off over the pothole";
}

// tiny_chambers stops at the compression chamber's end: over its first 4.3 ms the stroke runs
// towards -V_comp0 / A_p = -0.5e-6 / (pi / 4 0.032^2) = -0.622 mm, by hand, and not beyond.
TEST_F(StressClaims, TinyChambersRunOutOfStrokeAtTheCompressionEnd) {
  const io::CsvFile csv = run_copy("tiny_chambers", [](std::string s) {
    s = DydpProcessTest::replaced(s, "stop: 3.0, output_step: 0.005", "stop: 0.0043, output_step: 0.0001");
    while (s.find("window: [1.0, 3.0]") != std::string::npos)
      s.replace(s.find("window: [1.0, 3.0]"), 18, "window: [0.0, 0.0043]");
    return s;
  });
  const double compression_end = -0.5e-6 / (std::numbers::pi / 4 * 0.032 * 0.032);
  const auto& stroke = column(csv, "stroke.y");
  const double least = *std::min_element(stroke.begin(), stroke.end());
  EXPECT_GT(least, compression_end);
  EXPECT_LT(least, 0.75 * compression_end) << "the stroke is not near the chamber's end";
}

// The quarter-car variants change what their headers say, against damper.cdc's defaults
// (docs/blocks.md): bulk modulus x10 (15 GPa) and x100 (150 GPa), chambers / 100 (0.4 and
// 0.5 cm^3), and the valve current at the hard (0.3 A) and soft (1.6 A) ends of its range.
TEST(StressSuite, QuarterCarVariantsChangeWhatTheirHeadersSay) {
  const double bulk = damper_default("bulk_modulus");
  EXPECT_DOUBLE_EQ(damper_setting(read_text(stress_scene("bulk_modulus_10x")), "bulk_modulus"), 10 * bulk);
  EXPECT_DOUBLE_EQ(damper_setting(read_text(stress_scene("bulk_modulus_100x")), "bulk_modulus"), 100 * bulk);
  EXPECT_DOUBLE_EQ(10 * bulk, 15e9);
  const std::string tiny = read_text(stress_scene("tiny_chambers"));
  EXPECT_DOUBLE_EQ(damper_setting(tiny, "rebound_volume"), damper_default("rebound_volume") / 100);
  EXPECT_DOUBLE_EQ(damper_setting(tiny, "compression_volume"), damper_default("compression_volume") / 100);
  EXPECT_DOUBLE_EQ(damper_setting(tiny, "rebound_volume"), 0.4e-6);
  double low = 0, high = 0;
  damper_default("current", &low, &high);
  EXPECT_EQ(low, 0.3);
  EXPECT_EQ(high, 1.6);
  for (const auto& [scene, current] : std::map<std::string, double>{{"current_hard", low}, {"current_soft", high}}) {
    std::smatch m;
    const std::string text = read_text(stress_scene(scene));
    ASSERT_TRUE(std::regex_search(text, m, std::regex("valve_current: \\{value: ([0-9.]+)"))) << scene;
    EXPECT_DOUBLE_EQ(std::stod(m[1].str()), current) << scene;
  }
}

}  // namespace
}  // namespace dydp::test
