// Suspension springs: spring.linear and spring.progressive, with preload and smooth bump and
// rebound stops. Input: deflection [m], positive in compression; output: force [N], positive in
// compression (pushing the mounts apart).
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

/// Smooth positive part by softplus, pos(z; w) = w ln(1 + exp(z / w)), with d/dz (the logistic
/// sigma(z / w)) and d/dw; exponentially small away from contact, so a stop does not act early.
struct Pos {
  double value, dz, dw;
};
Pos smooth_pos(double z, double w) {
  const double a = z / w;
  const double softplus = std::max(a, 0.0) + std::log1p(std::exp(-std::fabs(a)));
  const double sigma = a >= 0 ? 1.0 / (1.0 + std::exp(-a)) : std::exp(a) / (1.0 + std::exp(a));
  return {w * softplus, sigma, softplus - a * sigma};
}

/// The common part: preload and stops. Parameters 0..5 of every spring, in this order.
enum StopParam { kPreload, kBumpClearance, kBumpStiffness, kReboundClearance, kReboundStiffness, kStopWidth, kNumStop };

/// F_stops = k_b pos(delta - c_b; w) - k_r pos(-delta - c_r; w): the bump stop pushes beyond the
/// bump clearance, the rebound stop pulls beyond the rebound clearance (in extension).
double stops(const double* p, double delta) {
  return p[kBumpStiffness] * smooth_pos(delta - p[kBumpClearance], p[kStopWidth]).value -
         p[kReboundStiffness] * smooth_pos(-delta - p[kReboundClearance], p[kStopWidth]).value;
}
/// The two stops' smooth contact at a deflection, the same for every direction of a tangent.
struct Stops {
  Pos bump, rebound;
};
Stops stops_at(const double* p, double delta) {
  return {smooth_pos(delta - p[kBumpClearance], p[kStopWidth]), smooth_pos(-delta - p[kReboundClearance], p[kStopWidth])};
}
double stops_tangent(const double* p, const Stops& at, const Seeds& s, double d_delta, int d) {
  const Pos& b = at.bump;
  const Pos& r = at.rebound;
  const double dw = s.p(kStopWidth, d);
  return s.p(kBumpStiffness, d) * b.value +
         p[kBumpStiffness] * (b.dz * (d_delta - s.p(kBumpClearance, d)) + b.dw * dw) -
         s.p(kReboundStiffness, d) * r.value -
         p[kReboundStiffness] * (r.dz * (-d_delta - s.p(kReboundClearance, d)) + r.dw * dw);
}

class Spring : public Block {
 public:
  Spring() {
    declare_input("deflection", 1, "m");
    declare_output("force", 1, "N");
  }
  void outputs(const Eval& e, double* const* y) const override {
    const double delta = e.u[0][0];
    y[0][0] = e.p[kPreload] + law(e.p, delta) + stops(e.p, delta);
  }
  void outputs_tangent(const Eval& e, const Seeds& s, const DirView* dy) const override {
    const double delta = e.u[0][0];
    const Stops at = stops_at(e.p, delta);
    for (int d = 0; d < s.directions; ++d) {
      const double d_delta = s.u[0](0, d);
      dy[0](0, d) = s.p(kPreload, d) + law_tangent(e.p, delta, s, d_delta, d) + stops_tangent(e.p, at, s, d_delta, d);
    }
  }

 protected:
  /// The elastic law without preload and stops, zero at zero deflection.
  virtual double law(const double* p, double delta) const = 0;
  virtual double law_tangent(const double* p, double delta, const Seeds& s, double d_delta, int d) const = 0;
};

/// F = k delta.
class LinearSpring : public Spring {
  enum { kStiffness = kNumStop };
  double law(const double* p, double delta) const override { return p[kStiffness] * delta; }
  double law_tangent(const double* p, double delta, const Seeds& s, double d_delta, int d) const override {
    return s.p(kStiffness, d) * delta + p[kStiffness] * d_delta;
  }
};

/// Rate rising smoothly from k0 to k1 around delta_t over a width w:
///   k(delta) = k0 + (k1 - k0) sigma((delta - delta_t) / w),  sigma(z) = (1 + z / sqrt(1 + z^2)) / 2,
///   F = k0 delta + (k1 - k0) w [S((delta - delta_t) / w) - S(-delta_t / w)],  S(z) = (z + sqrt(1 + z^2)) / 2.
class ProgressiveSpring : public Spring {
  enum { kInitialRate = kNumStop, kFinalRate, kTransition, kTransitionWidth };
  struct S {
    double value, slope;  // S(z) and sigma(z) = S'(z)
  };
  static S s_of(double z) {
    const double r = std::sqrt(1 + z * z);
    return {0.5 * (z + r), 0.5 * (1 + z / r)};
  }
  double law(const double* p, double delta) const override {
    const double w = p[kTransitionWidth];
    return p[kInitialRate] * delta + (p[kFinalRate] - p[kInitialRate]) * w *
                                         (s_of((delta - p[kTransition]) / w).value - s_of(-p[kTransition] / w).value);
  }
  double law_tangent(const double* p, double delta, const Seeds& s, double d_delta, int d) const override {
    const double w = p[kTransitionWidth], dw = s.p(kTransitionWidth, d), dt = s.p(kTransition, d);
    const double z1 = (delta - p[kTransition]) / w, z0 = -p[kTransition] / w;
    const S a = s_of(z1), b = s_of(z0);
    const double dk = s.p(kFinalRate, d) - s.p(kInitialRate, d), k = p[kFinalRate] - p[kInitialRate];
    const double dz1 = (d_delta - dt) / w - z1 * dw / w, dz0 = -dt / w - z0 * dw / w;
    return s.p(kInitialRate, d) * delta + p[kInitialRate] * d_delta + dk * w * (a.value - b.value) +
           k * dw * (a.value - b.value) + k * w * (a.slope * dz1 - b.slope * dz0);
  }
};

const std::vector<engine::ParamSpec> kStopParams = {
    {"preload", "N", 0.0, false, -kInf, kInf, "force at zero deflection"},
    {"bump_clearance", "m", 0.07, false, -kInf, kInf, "deflection at which the bump stop engages"},
    {"bump_stiffness", "N/m", 500e3, false, 0.0, kInf, "bump stop stiffness"},
    {"rebound_clearance", "m", 0.08, false, -kInf, kInf, "extension (negative deflection) at which the rebound stop engages"},
    {"rebound_stiffness", "N/m", 500e3, false, 0.0, kInf, "rebound stop stiffness"},
    {"stop_width", "m", 0.002, false, 1e-9, kInf, "travel over which a stop's contact is rounded"}};

std::vector<engine::ParamSpec> with_stops(std::vector<engine::ParamSpec> own) {
  std::vector<engine::ParamSpec> all = kStopParams;
  all.insert(all.end(), own.begin(), own.end());
  return all;
}

const engine::BlockRegistration linear({
    "spring.linear", "suspension",
    "Linear spring with preload and smooth bump/rebound stops; deflection and force positive in compression.",
    with_stops({{"stiffness", "N/m", 30e3, false, 0.0, kInf, "spring rate"}}),
    {},
    [](const engine::BlockSettings&) -> std::unique_ptr<Block> { return std::make_unique<LinearSpring>(); }});

const engine::BlockRegistration progressive({
    "spring.progressive", "suspension",
    "Progressive spring: rate rising smoothly from initial_rate to final_rate around a deflection; preload and stops.",
    with_stops({{"initial_rate", "N/m", 25e3, false, 0.0, kInf, "rate at small deflection"},
                {"final_rate", "N/m", 45e3, false, 0.0, kInf, "rate at large deflection"},
                {"transition_deflection", "m", 0.03, false, -kInf, kInf, "deflection at the middle of the rise"},
                {"transition_width", "m", 0.01, false, 1e-9, kInf, "width of the rise"}}),
    {},
    [](const engine::BlockSettings&) -> std::unique_ptr<Block> { return std::make_unique<ProgressiveSpring>(); }});

}  // namespace
}  // namespace dydp::blocks
