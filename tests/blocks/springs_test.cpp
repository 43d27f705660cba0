// spring.linear, spring.progressive, anti_roll_bar: exact tangents; rates against the laws;
// smooth stops; the bar's forces as the gradient of its torsion energy.
#include <gtest/gtest.h>

#include <cmath>

#include "tests/blocks/tangent_check.hpp"

namespace dydp::test {
namespace {

double spring_force(const engine::Block& b, const std::vector<double>& p, double delta) {
  const double* u[1] = {&delta};
  double f = 0;
  double* y[1] = {&f};
  engine::Eval e;
  e.u = u;
  e.p = p.data();
  b.outputs(e, y);
  return f;
}
double rate(const engine::Block& b, const std::vector<double>& p, double delta) {
  const double h = 1e-6;
  return (spring_force(b, p, delta + h) - spring_force(b, p, delta - h)) / (2 * h);
}

TEST(Springs, TangentsMatchFiniteDifferences) {
  for (const char* type : {"spring.linear", "spring.progressive"}) {
    BlockCase c;
    c.type = type;
    c.params = {{"preload", 3000.0}};
    c.inputs = {{{0.0, 0.1}}};  // reaches both stops
    c.samples = 30;
    check_tangents(c);
  }
}

TEST(Springs, LinearLawPreloadAndStops) {
  BlockCase c;
  c.type = "spring.linear";
  c.params = {{"preload", 3000.0}, {"stiffness", 30e3}};
  std::vector<double> p;
  auto b = make_block(c, &p);
  EXPECT_NEAR(spring_force(*b, p, 0.0), 3000.0, 1e-6);
  EXPECT_NEAR(spring_force(*b, p, 0.02), 3000.0 + 600.0, 1e-3);
  EXPECT_NEAR(rate(*b, p, 0.02), 30e3, 1e-3);
  // Well inside a stop, the rate is the spring's plus the stop's; the stops are smooth.
  EXPECT_NEAR(rate(*b, p, 0.09), 30e3 + 500e3, 50.0);
  EXPECT_NEAR(rate(*b, p, -0.10), 30e3 + 500e3, 50.0);
  EXPECT_NEAR(rate(*b, p, 0.07), 30e3 + 250e3, 1.0) << "half engaged at the clearance";
  EXPECT_LT(spring_force(*b, p, -0.1), 3000.0 - 30e3 * 0.1 - 500e3 * 0.019) << "the rebound stop pulls";
}

TEST(Springs, ProgressiveRateRisesFromInitialToFinal) {
  BlockCase c;
  c.type = "spring.progressive";
  std::vector<double> p;
  auto b = make_block(c, &p);
  EXPECT_NEAR(spring_force(*b, p, 0.0), 0.0, 1e-9);
  EXPECT_NEAR(rate(*b, p, -0.03), 25e3, 25e3 * 0.02);
  EXPECT_NEAR(rate(*b, p, 0.03), 35e3, 0.1) << "the middle of the rise";
  EXPECT_NEAR(rate(*b, p, 0.055), 45e3, 45e3 * 0.02);
  double previous = 0;
  for (double delta = -0.05; delta < 0.1; delta += 0.005) {
    const double k = rate(*b, p, delta);
    EXPECT_GE(k, previous - 1e-6) << delta;
    previous = k;
  }
}

TEST(AntiRollBar, TangentsMatchFiniteDifferences) {
  BlockCase c;
  c.type = "anti_roll_bar";
  c.inputs = {{{0.0, 0.12}}, {{0.0, 0.12}}};
  c.samples = 20;
  check_tangents(c);
}

TEST(AntiRollBar, ForcesAreTheGradientOfTheTorsionEnergy) {
  BlockCase c;
  c.type = "anti_roll_bar";
  std::vector<double> p;
  auto b = make_block(c, &p);
  const double k = p[0], a = p[1];
  const auto forces = [&](double zl, double zr) {
    const double* u[2] = {&zl, &zr};
    double fl = 0, fr = 0, twist = 0;
    double* y[3] = {&fl, &fr, &twist};
    engine::Eval e;
    e.u = u;
    e.p = p.data();
    b->outputs(e, y);
    return std::array<double, 3>{fl, fr, twist};
  };
  const auto energy = [&](double zl, double zr) {
    const double phi = std::asin(zl / a) - std::asin(zr / a);
    return 0.5 * k * phi * phi;
  };
  const double zl = 0.04, zr = -0.03, h = 1e-6;
  const auto f = forces(zl, zr);
  EXPECT_NEAR(f[0], (energy(zl + h, zr) - energy(zl - h, zr)) / (2 * h), 1e-6 * std::fabs(f[0]));
  EXPECT_NEAR(f[1], (energy(zl, zr + h) - energy(zl, zr - h)) / (2 * h), 1e-6 * std::fabs(f[1]));
  // Small travels: F = k (z_l - z_r) / a^2, equal and opposite; no force in pure heave.
  const auto small = forces(1e-4, -1e-4);
  EXPECT_NEAR(small[0], k * 2e-4 / (a * a), 1e-6 * k * 2e-4 / (a * a));
  EXPECT_NEAR(small[1], -small[0], 1e-9);
  EXPECT_NEAR(forces(0.05, 0.05)[0], 0.0, 1e-12);
}

}  // namespace
}  // namespace dydp::test
