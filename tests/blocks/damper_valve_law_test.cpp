// damper.cdc's electro-valve map pinned across the whole current range, through the block:
// docs/blocks.md states A_v = A_hard (A_soft / A_hard)^xi, xi = (i - 0.3) / 1.3, with the
// defaults A_hard = 0.5 mm^2 and A_soft = 8 mm^2, so every 1.3 / 8 A the section grows by
// 16^(1/8) = sqrt(2): 0.5, 0.707, 1, 1.414, 2, 2.828, 4, 5.657, 8 mm^2 by hand. The section is
// read back from the block's pipe equation, rho L / A_pipe dq/dt = p_reb - p_res - dp_valve(q)
// - dp_port(q), with dp(q) = q sqrt(q^2 + K^2 pt) / K^2 and K = Cd A sqrt(2 / rho) (the same
// page), inverted for the valve's K at a chosen state. Also through the block: the quasi-steady
// rebound force at 0.5 m/s falls strictly with the current over a fine grid of the range.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "tests/blocks/scene_helpers.hpp"
#include "tests/blocks/tangent_check.hpp"

namespace dydp::test {
namespace {

// The documented defaults (docs/blocks.md, "Defaults and the resulting damping").
constexpr double kDensity = 870.0, kDischarge = 0.7, kTransition = 1e5;  // [kg/m^3], [-], [Pa]
constexpr double kPortSection = 3e-6, kPipeLength = 0.1, kPipeSection = 20e-6;  // [m^2], [m], [m^2]

double coefficient(double section) { return kDischarge * section * std::sqrt(2 / kDensity); }
double loss(double q, double k) { return q * std::sqrt(q * q + k * k * kTransition) / (k * k); }

/// K from dp = q sqrt(q^2 + K^2 pt) / K^2 at given q, dp: with u = K^2,
/// dp^2 u^2 - q^2 pt u - q^4 = 0, the positive root.
double coefficient_from_loss(double q, double dp) {
  const double a = dp * dp, b = -q * q * kTransition, c = -q * q * q * q;
  return std::sqrt((-b + std::sqrt(b * b - 4 * a * c)) / (2 * a));
}

/// The electro-valve section the block uses at `current`, read from its dq/dt.
double section_from_block(double current) {
  BlockCase c;
  c.type = "damper.cdc";
  c.params = {{"current", current}};
  detail::Point pt;
  const auto block = make_block(c, &pt.p);
  const double p_res = 5e5, p_reb = 3.5e6, q = 2e-5;  // [Pa], [Pa], [m^3/s]
  pt.x = {p_reb, 1e6, p_res, q};
  pt.u = {{0.0}, {0.0}};
  const detail::Values v = detail::evaluate(*block, pt);
  const double inertance = kDensity * kPipeLength / kPipeSection;
  const double valve_dp = p_reb - p_res - loss(q, coefficient(kPortSection)) - inertance * v.xdot.at(3);
  return coefficient_from_loss(q, valve_dp) / (kDischarge * std::sqrt(2 / kDensity));
}

TEST(DamperValveLaw, SectionIsGeometricBetweenTheEndsOfTheCurrentRange) {
  // Hand values: A(0.3 + k 1.3 / 8) = 0.5 mm^2 x sqrt(2)^k.
  const double by_hand[9] = {0.5e-6, 0.70710678e-6, 1.0e-6, 1.41421356e-6, 2.0e-6,
                             2.82842712e-6, 4.0e-6, 5.65685425e-6, 8.0e-6};
  for (int k = 0; k <= 8; ++k) {
    const double current = 0.3 + 1.3 * k / 8;
    EXPECT_NEAR(section_from_block(current), by_hand[k], 1e-6 * by_hand[k]) << current << " A";
  }
}

TEST(DamperValveLaw, SlopeAtBothEndsIsTheGeometricOne) {
  // dA/di = A ln(A_soft / A_hard) / 1.3 = A ln(16) / 1.3: 1.0664 mm^2/A at 0.3 A, 17.06 at 1.6 A.
  const double h = 1e-4;  // [A] one-sided, inside the range
  const double slope_hard = (section_from_block(0.3 + h) - section_from_block(0.3)) / h;
  const double slope_soft = (section_from_block(1.6) - section_from_block(1.6 - h)) / h;
  EXPECT_NEAR(slope_hard, 0.5e-6 * std::log(16.0) / 1.3, 2e-3 * 0.5e-6 * std::log(16.0) / 1.3);
  EXPECT_NEAR(slope_soft, 8e-6 * std::log(16.0) / 1.3, 2e-3 * 8e-6 * std::log(16.0) / 1.3);
}

std::string rebound_scene(double current) {
  return R"(scene: damper_rebound
time: {start: 0.0, stop: 0.05, output_step: 0.001}
solver: {method: bdf, rtol: 1.0e-9, atol: 1.0e-9}
blocks:
  rate: {type: source.constant, value: 0.5}
  stroke: {type: source.ramp, start: 0.0, slope: 0.5}
  damper: {type: damper.cdc, current: )" + std::to_string(current) + R"(}
connections:
  - stroke.y -> damper.stroke
  - rate.y -> damper.stroke_rate
outputs: [damper.force]
)";
}

TEST(DamperValveLaw, SimulatedReboundForceFallsStrictlyWithCurrent) {
  double previous = INFINITY;
  for (int k = 0; k <= 13; ++k) {
    const double current = 0.3 + 0.1 * k;
    const auto r = run_scene(write_scene("rebound.yaml", rebound_scene(current)), {}, false);
    const double force = signal(r, "damper.force").back();
    EXPECT_LT(force, previous) << "not softer at " << current << " A";
    EXPECT_GT(force, 0.0) << current << " A";
    previous = force;
  }
}

}  // namespace
}  // namespace dydp::test
