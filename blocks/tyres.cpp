// tyre.vertical: the radial force of a tyre as a point follower on the road: linear stiffness
// and damping with smooth lift-off, so the force never pulls the wheel onto the road.
#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/framework/registry.hpp"

namespace dydp::blocks {
namespace {

using engine::Block;
using engine::DirView;
using engine::Eval;
using engine::Seeds;

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Smooth positive part by softplus, ramp(z; w) = w ln(1 + exp(z / w)), and its partials; its
/// z-slope, the logistic sigma(z / w), is the smooth contact indicator (0 to 1 over a few w,
/// with exponentially small tails, so no force acts in the air).
struct Ramp {
  double value, slope, slope_z, value_w, slope_w;
};
Ramp smooth_ramp(double z, double w) {
  const double a = z / w;
  const double softplus = std::max(a, 0.0) + std::log1p(std::exp(-std::fabs(a)));
  const double sigma = a >= 0 ? 1.0 / (1.0 + std::exp(-a)) : std::exp(a) / (1.0 + std::exp(a));
  const double bell = sigma * (1 - sigma);
  return {w * softplus, sigma, bell / w, softplus - a * sigma, -bell * a / w};
}

class TyreVertical : public Block {
 public:
  enum { kRadius, kStiffness, kDamping, kContactWidth, kForceWidth };
  enum { kRoadZ, kRoadZdot, kWheelZ, kWheelZdot };
  TyreVertical() {
    declare_input("road_z", 1, "m");
    declare_input("road_zdot", 1, "m/s");
    declare_input("wheel_z", 1, "m");
    declare_input("wheel_zdot", 1, "m/s");
    declare_output("force", 1, "N");
    declare_output("deflection", 1, "m");
  }

  /// deflection = road_z + R0 - wheel_z; F_raw = k ramp(delta; w_c) + c ddelta/dt sigma(delta / w_c);
  /// F = ramp(F_raw; w_F) sigma(delta / w_c) > 0 (the second factor removes ramp's floor in the air).
  void outputs(const Eval& e, double* const* y) const override {
    const double* p = e.p;
    const double delta = e.u[kRoadZ][0] + p[kRadius] - e.u[kWheelZ][0];
    const double delta_rate = e.u[kRoadZdot][0] - e.u[kWheelZdot][0];
    const Ramp contact = smooth_ramp(delta, p[kContactWidth]);
    const double raw = p[kStiffness] * contact.value + p[kDamping] * delta_rate * contact.slope;
    y[0][0] = smooth_ramp(raw, p[kForceWidth]).value * contact.slope;
    y[1][0] = delta;
  }
  void outputs_tangent(const Eval& e, const Seeds& s, const DirView* dy) const override {
    const double* p = e.p;
    const double delta = e.u[kRoadZ][0] + p[kRadius] - e.u[kWheelZ][0];
    const double delta_rate = e.u[kRoadZdot][0] - e.u[kWheelZdot][0];
    const Ramp contact = smooth_ramp(delta, p[kContactWidth]);
    const double raw = p[kStiffness] * contact.value + p[kDamping] * delta_rate * contact.slope;
    const Ramp force = smooth_ramp(raw, p[kForceWidth]);
    for (int d = 0; d < s.directions; ++d) {
      const double d_delta = s.u[kRoadZ](0, d) + s.p(kRadius, d) - s.u[kWheelZ](0, d);
      const double d_rate = s.u[kRoadZdot](0, d) - s.u[kWheelZdot](0, d);
      const double dw = s.p(kContactWidth, d);
      const double d_value = contact.slope * d_delta + contact.value_w * dw;
      const double d_slope = contact.slope_z * d_delta + contact.slope_w * dw;
      const double d_raw = s.p(kStiffness, d) * contact.value + p[kStiffness] * d_value +
                           s.p(kDamping, d) * delta_rate * contact.slope +
                           p[kDamping] * (d_rate * contact.slope + delta_rate * d_slope);
      dy[0](0, d) = (force.slope * d_raw + force.value_w * s.p(kForceWidth, d)) * contact.slope +
                    force.value * d_slope;
      dy[1](0, d) = d_delta;
    }
  }
};

const engine::BlockRegistration tyre_vertical({
    "tyre.vertical", "tyres",
    "Radial tyre force: stiffness and damping on the deflection road_z + R0 - wheel_z, smooth lift-off, never pulling.",
    {{"unloaded_radius", "m", 0.32, false, 0.0, kInf, "unloaded radius R0"},
     {"stiffness", "N/m", 250e3, false, 0.0, kInf, "radial stiffness"},
     {"damping", "N s/m", 200.0, false, 0.0, kInf, "radial damping"},
     {"contact_width", "m", 1e-4, false, 1e-9, kInf, "deflection over which contact sets in"},
     {"force_width", "N", 1.0, false, 1e-9, kInf, "force over which the no-pull limit is rounded"}},
    {},
    [](const engine::BlockSettings&) -> std::unique_ptr<Block> { return std::make_unique<TyreVertical>(); }});

}  // namespace
}  // namespace dydp::blocks
