// End-to-end `dydp kc` on the shipped sedan scene: the files it writes, the sedan's kinematics
// where a vehicle engineer expects them (camber gain negative, motion ratios between 0.4 and 1,
// roll centres above the ground, a rack that steers the front wheels only), the derivatives
// with respect to the scene's geometry directions, and bad input refused with exit 2 and
// nothing written.
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

const json& find_curve(const json& doc, const std::string& sweep, const std::string& quantity, const std::string& corner) {
  for (const json& s : doc["sweeps"])
    if (s["name"] == sweep)
      for (const json& c : s["curves"])
        if (c["quantity"] == quantity && c["corner"] == corner) return c;
  throw std::runtime_error("no curve " + sweep + "/" + quantity + "/" + corner);
}

double at_design(const json& curve) {
  const auto& v = curve["values"];
  return v[v.size() / 2].get<double>();
}

TEST_F(Cli, KcWritesTheSedansKinematicsWithTheirDerivatives) {
  const Result r = dydp("kc " + quote(sedan()) + " --report --format mat --out " + quote((dir_ / "kc").string()));
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f : {"kc.json", "kc_bump.csv", "kc_roll.csv", "kc_steer.csv", "kc.mat", "report.md"})
    EXPECT_TRUE(fs::exists(dir_ / "kc" / f)) << f;
  const json doc = json::parse(read_text(dir_ / "kc/kc.json"));
  ASSERT_EQ(doc["sweeps"].size(), 3u);
  // The scene's four geometry directions are the derivatives' columns (the damper, spring and
  // tyre directions do not reach the car's model parameters).
  ASSERT_EQ(doc["parameters"].size(), 4u);
  for (const std::string c : {"fl", "fr", "rl", "rr"}) {
    const double gain = at_design(find_curve(doc, "bump", "camber_gain", c));
    EXPECT_LT(gain, -5.0) << c;  // deg/m: the top leans in as the wheel rises
    EXPECT_GT(gain, -60.0) << c;
    for (const std::string q : {"spring_ratio", "damper_ratio"}) {
      const double mr = at_design(find_curve(doc, "bump", q, c));
      EXPECT_GT(mr, 0.4) << c << " " << q;
      EXPECT_LT(mr, 1.0) << c << " " << q;
    }
    const double rch = at_design(find_curve(doc, "bump", "roll_centre_height", c));
    EXPECT_GT(rch, 0.0) << c;
    EXPECT_LT(rch, 0.3) << c;
  }
  // The front strut's mount moves the front motion ratio, not the rear's; the curve says how it
  // was differentiated.
  const json& front = find_curve(doc, "bump", "spring_ratio", "fl");
  const json& rear = find_curve(doc, "bump", "spring_ratio", "rl");
  EXPECT_EQ(front["derivative"], "central differences of the exact rate");
  EXPECT_GT(std::abs(front["sensitivity"]["strut_mount_front"][16].get<double>()), 0.5);
  EXPECT_LT(std::abs(rear["sensitivity"]["strut_mount_front"][16].get<double>()), 1e-6);
  EXPECT_EQ(find_curve(doc, "bump", "spring_compression", "fl")["derivative"], "exact");
  // Steering: the front wheels only.
  int steered = 0;
  for (const json& c : doc["sweeps"][2]["curves"]) steered += c["quantity"] == "toe";
  EXPECT_EQ(steered, 2);
  // The CSV has the travel, every curve, and every curve's derivative per direction.
  const auto table = io::read_csv((dir_ / "kc/kc_bump.csv").string());
  EXPECT_EQ(table.columns.size(), 1 + doc["sweeps"][0]["curves"].size() * 5);
  EXPECT_EQ(table.columns[0].size(), 33u);
  EXPECT_NE(r.out.find("roll centre"), std::string::npos) << r.out;
}

TEST_F(Cli, KcRefusesBadInputAndWritesNothing) {
  for (const std::string& args :
       {"kc " + quote(sedan()) + " --travel 0 --out " + quote((dir_ / "bad").string()),
        "kc " + quote(sedan()) + " --points 4 --out " + quote((dir_ / "bad").string()),
        "kc " + quote(sedan()) + " --block rig --out " + quote((dir_ / "bad").string()),
        "kc " + quote(source_path("scenarios/quarter_car_cdc.yaml").string()) + " --out " + quote((dir_ / "bad").string())}) {
    const Result r = dydp(args);
    EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "bad")) << args;
  }
  // The quarter car has no wheel sensors: the message names the block and what it needs.
  const Result r = dydp("kc " + quote(source_path("scenarios/quarter_car_cdc.yaml").string()) + " --out " +
                        quote((dir_ / "bad").string()));
  EXPECT_NE(r.err.find("quarter_car_cdc.yaml:18"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("axle_pos_C"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace dydp::test
