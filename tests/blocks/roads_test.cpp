// Roads: exact parameter tangents; zdot is the time derivative of z; the rear wheels follow the
// front ones by the wheelbase; seeded noise reproducible with the requested rms; ISO 8608 class
// variance against the PSD integral; obstacle shapes, heights and breakpoints.
#include <gtest/gtest.h>

#include <cmath>

#include "tests/blocks/tangent_check.hpp"

namespace dydp::test {
namespace {

using Settings = std::map<std::string, std::vector<std::string>>;

struct Sample {
  std::array<double, 4> z, zdot;
};
Sample road_at(const engine::Block& b, const std::vector<double>& p, double t) {
  Sample s{};
  double* y[2] = {s.z.data(), s.zdot.data()};
  engine::Eval e;
  e.t = e.segment_start = t;
  e.p = p.data();
  b.outputs(e, y);
  return s;
}

BlockCase road_case(const std::string& type, Settings settings = {}) {
  BlockCase c;
  c.type = type;
  c.settings = std::move(settings);
  c.times = {0.0, 0.41, 1.37, 2.9};
  c.samples = 1;
  return c;
}

const Settings kProfile = {{"bumps", {"3.0", "0.5", "0.04"}},
                           {"potholes", {"7.0", "0.6", "0.03"}},
                           {"steps", {"12.0", "0.02"}}};

TEST(Roads, TangentsMatchFiniteDifferences) {
  check_tangents(road_case("road.fourposter"));
  check_tangents(road_case("road.iso8608", {{"components", {"40"}}}));
  BlockCase c = road_case("road.profile", kProfile);
  c.times = {0.33, 0.73, 1.0, 1.23, 1.7};  // on the bump, pothole, step, for front and rear
  c.params = {{"speed", 10.0}, {"wheelbase", 2.5}};
  check_tangents(c);
}

TEST(Roads, RateIsTheTimeDerivativeOfHeight) {
  for (const auto& c : {road_case("road.fourposter"), road_case("road.iso8608"), road_case("road.profile", kProfile)}) {
    std::vector<double> p;
    auto b = make_block(c, &p);
    for (double t : {0.05, 0.33, 0.71, 1.23, 2.5}) {
      const double h = 1e-6;
      const Sample s = road_at(*b, p, t), a = road_at(*b, p, t + h), m = road_at(*b, p, t - h);
      for (int i = 0; i < 4; ++i)
        EXPECT_NEAR(s.zdot[i], (a.z[i] - m.z[i]) / (2 * h), 1e-6 * (1 + std::fabs(s.zdot[i]))) << c.type << " " << t << " " << i;
    }
  }
}

TEST(Roads, RearWheelsFollowTheFrontOnesByTheWheelbase) {
  for (const auto& c : {road_case("road.iso8608"), road_case("road.profile", kProfile)}) {
    std::vector<double> p;
    auto b = make_block(c, &p);
    const double delay = p[1] / p[0];  // wheelbase / speed
    for (double t : {0.4, 1.1, 1.6}) {
      const Sample rear = road_at(*b, p, t + delay), front = road_at(*b, p, t);
      EXPECT_NEAR(rear.z[2], front.z[0], 1e-12) << c.type;
      EXPECT_NEAR(rear.z[3], front.z[1], 1e-12) << c.type;
    }
  }
}

/// Mean of z^2 over [0, T] sampled every dt.
std::array<double, 4> mean_square(const engine::Block& b, const std::vector<double>& p, double T, double dt) {
  std::array<double, 4> acc{};
  int n = 0;
  for (double t = 0; t < T; t += dt, ++n) {
    const Sample s = road_at(b, p, t);
    for (int i = 0; i < 4; ++i) acc[i] += s.z[i] * s.z[i];
  }
  for (double& a : acc) a /= n;
  return acc;
}

TEST(Roads, FourPosterNoiseHasTheRequestedRmsAndIsSeeded) {
  BlockCase c = road_case("road.fourposter");
  c.params = {{"amplitude_fl", 0.0}, {"amplitude_fr", 0.0}, {"amplitude_rl", 0.0}, {"amplitude_rr", 0.0}, {"noise_rms", 0.002}};
  std::vector<double> p;
  auto b = make_block(c, &p);
  // Components spaced 0.39 Hz apart: their products average out over a multiple of 1/0.39 s.
  const auto ms = mean_square(*b, p, 1.0 / 0.39 * 40, 0.005);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(std::sqrt(ms[i]), 0.002, 0.002 * 0.01) << i;
  auto again = make_block(c, &p);
  EXPECT_EQ(road_at(*b, p, 1.234).z, road_at(*again, p, 1.234).z);
  c.settings = {{"seed", {"2"}}};
  auto other = make_block(c, &p);
  EXPECT_NE(road_at(*b, p, 1.234).z[0], road_at(*other, p, 1.234).z[0]);
  EXPECT_NE(road_at(*b, p, 1.234).z[0], road_at(*b, p, 1.234).z[1]) << "pads have their own phases";
}

// The noise's sines come from one rotation per component (exp(i w_k t) by products, not a
// sincos each): the rate must still be the height's derivative, early and late in a long run,
// with the sine and noise together (central differences, h = 1e-5 s: error ~ h^2 zddd / 6).
TEST(Roads, FourPosterRateIsTheDerivativeOfTheHeightAtAnyTime) {
  BlockCase c = road_case("road.fourposter");
  c.params = {{"noise_rms", 0.002}, {"noise_high", 25.0}};
  std::vector<double> p;
  auto b = make_block(c, &p);
  const double h = 1e-5;
  for (double t : {0.3, 17.9, 600.2, 3600.7}) {
    const Sample s = road_at(*b, p, t), plus = road_at(*b, p, t + h), minus = road_at(*b, p, t - h);
    for (int i = 0; i < 4; ++i) {
      const double rate = (plus.z[i] - minus.z[i]) / (2 * h);
      EXPECT_NEAR(s.zdot[i], rate, 1e-6 * std::max(0.01, std::abs(s.zdot[i]))) << "t " << t << " pad " << i;
    }
  }
}

TEST(Roads, Iso8608VarianceFollowsTheClassPsd) {
  // Variance of the synthesis = sum Gd(n_k) dn; for n_k on the midpoint grid this approximates
  // the integral of Gd(n0) (n / n0)^-2 over the band, Gd(n0) n0^2 (1 / n_min - 1 / n_max).
  const double n_min = 0.05, n_max = 2.0, n0 = 0.1;
  for (const char* cls : {"A", "E"}) {
    BlockCase c = road_case("road.iso8608", {{"class", {cls}}, {"n_min", {"0.05"}}, {"n_max", {"2.0"}}, {"components", {"400"}}});
    c.params = {{"speed", 10.0}};
    std::vector<double> p;
    auto b = make_block(c, &p);
    const double gd0 = 16e-6 * std::pow(4.0, cls[0] - 'A');
    const double expected = gd0 * n0 * n0 * (1 / n_min - 1 / n_max);
    // Period of the synthesis in distance: 1 / dn = 400 / 1.95 m, at 10 m/s.
    const auto ms = mean_square(*b, p, 400 / 1.95 / 10.0, 0.005);
    for (int i : {0, 1}) EXPECT_NEAR(ms[i], expected, 0.02 * expected) << cls << " track " << i;
  }
}

TEST(Roads, ProfileObstaclesHaveTheirHeightsAndEdgesAreBreakpoints) {
  BlockCase c = road_case("road.profile", kProfile);
  c.params = {{"speed", 10.0}, {"wheelbase", 2.5}};
  std::vector<double> p;
  auto b = make_block(c, &p);
  EXPECT_NEAR(road_at(*b, p, 0.325).z[0], 0.04, 1e-12) << "bump top";
  EXPECT_NEAR(road_at(*b, p, 0.73).z[1], -0.03, 1e-12) << "pothole floor";
  EXPECT_NEAR(road_at(*b, p, 1.3).z[0], 0.02, 1e-12) << "after the step";
  EXPECT_NEAR(road_at(*b, p, 0.2).z[0], 0.0, 1e-15);
  EXPECT_NEAR(road_at(*b, p, 0.4).z[0], 0.0, 1e-15) << "behind the bump";
  const auto bp = b->breakpoints(p.data(), 0.0, 10.0);
  for (double t : {0.3, 0.35, 0.7, 0.705, 0.755, 0.76, 1.2, 1.205, 0.55, 1.45})
    EXPECT_TRUE(std::any_of(bp.begin(), bp.end(), [&](double x) { return std::fabs(x - t) < 1e-12; })) << t;
  c.settings["tracks"] = {"left"};
  auto left = make_block(c, &p);
  EXPECT_NEAR(road_at(*left, p, 0.325).z[1], 0.0, 1e-15);
}

}  // namespace
}  // namespace dydp::test
