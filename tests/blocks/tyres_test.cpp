// tyre.vertical: exact tangents, static stiffness, and lift-off (the force never pulls).
#include <gtest/gtest.h>

#include "tests/blocks/tangent_check.hpp"

namespace dydp::test {
namespace {

/// Force of tyre.vertical at deflection delta and deflection rate (road minus wheel).
double tyre_force(engine::Block& b, const std::vector<double>& p, double delta, double rate) {
  const double road[2] = {0.0, rate}, wheel[2] = {0.32 - delta, 0.0};
  const double u0 = road[0], u1 = road[1], u2 = wheel[0], u3 = wheel[1];
  const double* u[4] = {&u0, &u1, &u2, &u3};
  double f = 0, defl = 0;
  double* y[2] = {&f, &defl};
  engine::Eval e;
  e.u = u;
  e.p = p.data();
  b.outputs(e, y);
  EXPECT_NEAR(defl, delta, 1e-12);
  return f;
}

TEST(TyreVertical, TangentsMatchFiniteDifferences) {
  BlockCase c;
  c.type = "tyre.vertical";
  c.inputs = {{{0.01, 0.02}}, {{0.0, 0.5}}, {{0.31, 0.02}}, {{0.0, 0.5}}};
  c.samples = 20;
  check_tangents(c);
  // Around contact onset, where the smoothing acts.
  c.inputs = {{{0.0, 2e-4}}, {{0.0, 0.05}}, {{0.32, 2e-4}}, {{0.0, 0.05}}};
  check_tangents(c);
}

TEST(TyreVertical, StaticStiffnessAndDamping) {
  BlockCase c;
  c.type = "tyre.vertical";
  std::vector<double> p;
  auto b = make_block(c, &p);
  EXPECT_NEAR(tyre_force(*b, p, 0.016, 0.0), 250e3 * 0.016, 1.0);
  EXPECT_NEAR(tyre_force(*b, p, 0.016, 0.3) - tyre_force(*b, p, 0.016, 0.0), 200.0 * 0.3, 0.1);
}

TEST(TyreVertical, NeverPullsAndLiftsOff) {
  BlockCase c;
  c.type = "tyre.vertical";
  std::vector<double> p;
  auto b = make_block(c, &p);
  for (double delta : {-0.05, -0.01, -1e-3, 0.0, 1e-3, 0.01})
    for (double rate : {-5.0, -1.0, 0.0, 1.0, 5.0}) {
      const double f = tyre_force(*b, p, delta, rate);
      EXPECT_GE(f, 0.0) << delta << " " << rate;
      if (delta <= -1e-3) {
        EXPECT_LT(f, 0.1) << "in the air, approaching or not: " << delta << " " << rate;
      }
    }
  // Separating fast while still deflected: the damping would pull; the force is nearly zero.
  EXPECT_LT(tyre_force(*b, p, 0.002, -20.0), 0.1);
}

}  // namespace
}  // namespace dydp::test
