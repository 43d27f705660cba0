// Handling objectives: objective.slip_angle, the mean carbody slip angle beta = atan2(vy, vx)
// over a window (a steady-state cornering figure), from body-frame velocities of the CM.
#include <cmath>
#include <limits>

#include "blocks/objective_window.hpp"
#include "engine/framework/objective.hpp"
#include "engine/framework/registry.hpp"

namespace dydp::blocks {
namespace {

using engine::Block;
using engine::BlockSettings;
using engine::ConstDirView;
using engine::DirView;
using engine::Eval;
using engine::ObjectiveSamples;
using engine::Seeds;

constexpr double kInf = std::numeric_limits<double>::infinity();

/// Q = integral over [from, to] of atan2(vy, vx); psi = Q / T.
class SlipAngle : public Block, public engine::Objective {
 public:
  SlipAngle(double from, double to) : from_(from), to_(to) {
    declare_input("vx", 1, "m/s", false);
    declare_input("vy", 1, "m/s", false);
    declare_quadratures(1);
  }
  std::string unit(const std::string&) const override { return "rad"; }
  bool inside(const Eval& e) const { return e.reached(from_) && !e.reached(to_); }
  void outputs(const Eval&, double* const*) const override {}
  void outputs_tangent(const Eval&, const Seeds&, const DirView*) const override {}
  void quadratures(const Eval& e, double* qdot) const override {
    qdot[0] = inside(e) ? std::atan2(e.u[1][0], e.u[0][0]) : 0.0;
  }
  /// d beta = (vx dvy - vy dvx) / (vx^2 + vy^2)
  void quadratures_tangent(const Eval& e, const Seeds& s, DirView dq) const override {
    const double vx = e.u[0][0], vy = e.u[1][0], r2 = vx * vx + vy * vy;
    const bool in = inside(e);
    for (int d = 0; d < s.directions; ++d)
      dq(0, d) = in ? (vx * s.u[1](0, d) - vy * s.u[0](0, d)) / r2 : 0.0;
  }
  std::vector<double> breakpoints(const double*, double, double) const override {
    std::vector<double> b;
    if (std::isfinite(from_)) b.push_back(from_);
    if (std::isfinite(to_)) b.push_back(to_);
    return b;
  }
  double objective(const double*, const double* q, ConstDirView dq, const ObjectiveSamples& s,
                   double* dpsi) const override {
    const double T = std::min(to_, s.t_stop) - std::max(from_, s.t_start);
    for (int d = 0; d < s.directions; ++d) dpsi[d] = dq(0, d) / T;
    return q[0] / T;
  }

 private:
  double from_, to_;
};

const engine::BlockRegistration slip_angle({
    "objective.slip_angle", "objectives",
    "psi = mean carbody slip angle atan2(vy, vx) [rad] over the window, from body-frame CM velocities.",
    {},
    {{"window", "[from, to] in s; the whole run when absent", "", false}},
    [](const BlockSettings& s) -> std::unique_ptr<Block> {
      double from = -kInf, to = kInf;
      if (!(s.texts("window").size() == 1 && s.texts("window")[0].empty())) {
        const std::vector<double> v = s.numbers("window");
        if (v.size() != 2 || !(v[0] < v[1])) s.fail("window", "expected [from, to] with from < to");
        from = v[0], to = v[1];
      }
      return std::make_unique<SlipAngle>(from, to);
    },
    window_checks()});

}  // namespace
}  // namespace dydp::blocks
