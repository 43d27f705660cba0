// mass_spring_damper: m a = f - c v - k x, the engine's analytic reference system.
// States x [m], v [m/s]; input f [N]; outputs x, v, a.
#include "engine/framework/registry.hpp"

namespace dydp::blocks {
namespace {

using engine::Block;
using engine::DirView;
using engine::Eval;
using engine::Seeds;

constexpr double kInf = std::numeric_limits<double>::infinity();

class MassSpringDamper : public Block {
 public:
  enum { kMass, kStiffness, kDamping, kX0, kV0 };
  MassSpringDamper() {
    declare_input("f", 1, "N");
    declare_output("x", 1, "m", false);
    declare_output("v", 1, "m/s", false);
    declare_output("a", 1, "m/s^2");
    declare_states({"x", "v"});
  }

  /// a = (f - c v - k x) / m
  static double acceleration(const Eval& e) {
    return (e.u[0][0] - e.p[kDamping] * e.x[1] - e.p[kStiffness] * e.x[0]) / e.p[kMass];
  }
  /// da = (df - c dv - k dx - v dc - x dk - a dm) / m
  static double acceleration_tangent(const Eval& e, const Seeds& s, int d) {
    const double m = e.p[kMass], k = e.p[kStiffness], c = e.p[kDamping];
    return (s.u[0](0, d) - c * s.x(1, d) - k * s.x(0, d) - e.x[1] * s.p(kDamping, d) -
            e.x[0] * s.p(kStiffness, d) - acceleration(e) * s.p(kMass, d)) / m;
  }

  void initial_state(const Eval& e, double* x0) const override {
    x0[0] = e.p[kX0];
    x0[1] = e.p[kV0];
  }
  void initial_state_tangent(const Eval&, const Seeds& s, DirView dx0) const override {
    for (int d = 0; d < s.directions; ++d) {
      dx0(0, d) = s.p(kX0, d);
      dx0(1, d) = s.p(kV0, d);
    }
  }
  void outputs(const Eval& e, double* const* y) const override {
    y[0][0] = e.x[0];
    y[1][0] = e.x[1];
    if (e.inputs_ready) y[2][0] = acceleration(e);
  }
  void outputs_tangent(const Eval& e, const Seeds& s, const DirView* dy) const override {
    for (int d = 0; d < s.directions; ++d) {
      dy[0](0, d) = s.x(0, d);
      dy[1](0, d) = s.x(1, d);
      if (e.inputs_ready) dy[2](0, d) = acceleration_tangent(e, s, d);
    }
  }
  void derivatives(const Eval& e, double* xdot) const override {
    xdot[0] = e.x[1];
    xdot[1] = acceleration(e);
  }
  void derivatives_tangent(const Eval& e, const Seeds& s, DirView dxdot) const override {
    for (int d = 0; d < s.directions; ++d) {
      dxdot(0, d) = s.x(1, d);
      dxdot(1, d) = acceleration_tangent(e, s, d);
    }
  }
};

const engine::BlockRegistration msd({
    "mass_spring_damper", "mechanics", "A mass on a linear spring and damper, driven by force f.",
    {{"m", "kg", 1.0, false, 1e-12, kInf, "mass"},
     {"k", "N/m", 1.0, false, 0.0, kInf, "spring stiffness"},
     {"c", "N s/m", 0.0, false, 0.0, kInf, "damping coefficient"},
     {"x0", "m", 0.0, false, -kInf, kInf, "initial position"},
     {"v0", "m/s", 0.0, false, -kInf, kInf, "initial velocity"}},
    {},
    [](const engine::BlockSettings&) -> std::unique_ptr<Block> { return std::make_unique<MassSpringDamper>(); }});

}  // namespace
}  // namespace dydp::blocks
