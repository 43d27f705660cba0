// steering: exact tangents in every mode; the laws' values and rates; corners as breakpoints and
// branch choice at a corner by Eval::reached(); CSV mode against its table.
#include <gtest/gtest.h>

#include <numbers>

#include "tests/blocks/scene_helpers.hpp"
#include "tests/blocks/tangent_check.hpp"

namespace dydp::test {
namespace {

std::array<double, 2> rack_at(const engine::Block& b, const std::vector<double>& p, double t, double segment_start) {
  std::array<double, 2> y{};
  double* out[2] = {&y[0], &y[1]};
  engine::Eval e;
  e.t = t;
  e.segment_start = segment_start;
  e.p = p.data();
  b.outputs(e, out);
  return y;
}

BlockCase steering_case(const char* mode) {
  BlockCase c;
  c.type = "steering";
  c.settings = {{"mode", {mode}}};
  c.params = {{"amplitude", 0.02}, {"start", 1.0}, {"ramp_time", 0.5}, {"frequency", 0.7}};
  c.times = {0.5, 1.2, 1.37, 2.3};
  c.samples = 1;
  return c;
}

TEST(Steering, TangentsMatchFiniteDifferences) {
  for (const char* mode : {"step", "ramp_hold", "sine"}) check_tangents(steering_case(mode));
}

TEST(Steering, LawsAndCorners) {
  std::vector<double> p;
  auto ramp = make_block(steering_case("ramp_hold"), &p);
  EXPECT_EQ(rack_at(*ramp, p, 0.9, 0.0)[0], 0.0);
  EXPECT_NEAR(rack_at(*ramp, p, 1.25, 1.0)[0], 0.01, 1e-15);
  EXPECT_NEAR(rack_at(*ramp, p, 1.25, 1.0)[1], 0.04, 1e-15);
  EXPECT_NEAR(rack_at(*ramp, p, 3.0, 1.5)[0], 0.02, 1e-15);
  EXPECT_EQ(rack_at(*ramp, p, 3.0, 1.5)[1], 0.0);
  // At the end corner: still ramping while the segment started before it, holding after.
  EXPECT_NEAR(rack_at(*ramp, p, 1.5, 1.2)[1], 0.04, 1e-15);
  EXPECT_EQ(rack_at(*ramp, p, 1.5, 1.5)[1], 0.0);
  EXPECT_EQ(ramp->breakpoints(p.data(), 0.0, 10.0), (std::vector<double>{1.0, 1.5}));

  auto step = make_block(steering_case("step"), &p);
  EXPECT_EQ(rack_at(*step, p, 1.0, 0.5)[0], 0.0);
  EXPECT_EQ(rack_at(*step, p, 1.0, 1.0)[0], 0.02);

  auto sine = make_block(steering_case("sine"), &p);
  const double t = 1.3, w = 2 * std::numbers::pi * 0.7;
  EXPECT_NEAR(rack_at(*sine, p, t, 1.0)[0], 0.02 * std::sin(w * 0.3), 1e-15);
  EXPECT_NEAR(rack_at(*sine, p, t, 1.0)[1], 0.02 * w * std::cos(w * 0.3), 1e-14);
}

TEST(Steering, CsvFollowsItsTableWithCornersAsBreakpoints) {
  const std::string csv = write_scene("rack.csv", "t,rack\n0.0,0.0\n1.0,0.01\n2.0,0.01\n3.0,-0.02\n");
  BlockCase c;
  c.type = "steering";
  c.settings = {{"mode", {"csv"}}, {"file", {csv}}};
  std::vector<double> p;
  auto b = make_block(c, &p);
  EXPECT_NEAR(rack_at(*b, p, 0.5, 0.0)[0], 0.005, 1e-15);
  EXPECT_NEAR(rack_at(*b, p, 0.5, 0.0)[1], 0.01, 1e-15);
  EXPECT_NEAR(rack_at(*b, p, 2.5, 2.0)[0], -0.005, 1e-15);
  EXPECT_NEAR(rack_at(*b, p, 2.0, 1.0)[1], 0.0, 1e-15) << "the hold, until the corner is reached";
  EXPECT_NEAR(rack_at(*b, p, 2.0, 2.0)[1], -0.03, 1e-15);
  EXPECT_EQ(rack_at(*b, p, 9.0, 3.0)[0], -0.02);
  EXPECT_EQ(b->breakpoints(p.data(), 0.5, 10.0), (std::vector<double>{1.0, 2.0, 3.0}));
}

}  // namespace
}  // namespace dydp::test
