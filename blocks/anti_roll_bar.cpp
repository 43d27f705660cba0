// anti_roll_bar: a torsion bar with two levers. Each lever end follows its wheel travel z
// (positive up, in bump); lever angle theta = asin(z / a); twist phi = theta_l - theta_r;
// torque T = k phi. The vertical force at each lever end is dE/dz of E = k phi^2 / 2:
//   F_l = k phi / sqrt(a^2 - z_l^2),  F_r = -k phi / sqrt(a^2 - z_r^2),
// positive when it opposes a positive travel (pushes that wheel down).
#include <cmath>
#include <limits>

#include "engine/framework/registry.hpp"

namespace dydp::blocks {
namespace {

using engine::Block;
using engine::DirView;
using engine::Eval;
using engine::OutOfDomain;
using engine::Seeds;

constexpr double kInf = std::numeric_limits<double>::infinity();

class AntiRollBar : public Block {
 public:
  enum { kStiffness, kLever };
  AntiRollBar() {
    declare_input("travel_left", 1, "m");
    declare_input("travel_right", 1, "m");
    declare_output("force_left", 1, "N");
    declare_output("force_right", 1, "N");
    declare_output("twist", 1, "rad");
  }

  /// Lever geometry of one side: root = sqrt(a^2 - z^2) = a cos(theta), theta = asin(z / a).
  struct Lever {
    double root, theta;
  };
  static Lever lever(double z, double a) {
    if (!(std::fabs(z) < a)) throw OutOfDomain{"wheel travel beyond the anti-roll bar's lever arm"};
    return {std::sqrt(a * a - z * z), std::asin(z / a)};
  }

  void outputs(const Eval& e, double* const* y) const override {
    const double k = e.p[kStiffness], a = e.p[kLever];
    const Lever l = lever(e.u[0][0], a), r = lever(e.u[1][0], a);
    const double phi = l.theta - r.theta;
    y[0][0] = k * phi / l.root;
    y[1][0] = -k * phi / r.root;
    y[2][0] = phi;
  }
  void outputs_tangent(const Eval& e, const Seeds& s, const DirView* dy) const override {
    const double k = e.p[kStiffness], a = e.p[kLever];
    const double zl = e.u[0][0], zr = e.u[1][0];
    const Lever l = lever(zl, a), r = lever(zr, a);
    const double phi = l.theta - r.theta;
    for (int d = 0; d < s.directions; ++d) {
      const double dzl = s.u[0](0, d), dzr = s.u[1](0, d), da = s.p(kLever, d), dk = s.p(kStiffness, d);
      // d theta = (dz - z da / a) / root;  d root = (a da - z dz) / root
      const double dth_l = (dzl - zl * da / a) / l.root, dth_r = (dzr - zr * da / a) / r.root;
      const double droot_l = (a * da - zl * dzl) / l.root, droot_r = (a * da - zr * dzr) / r.root;
      const double dphi = dth_l - dth_r;
      dy[0](0, d) = (dk * phi + k * dphi) / l.root - k * phi * droot_l / (l.root * l.root);
      dy[1](0, d) = -(dk * phi + k * dphi) / r.root + k * phi * droot_r / (r.root * r.root);
      dy[2](0, d) = dphi;
    }
  }
};

const engine::BlockRegistration anti_roll_bar({
    "anti_roll_bar", "suspension",
    "Torsion anti-roll bar with levers: forces at the two lever ends from the wheel travels (positive up).",
    {{"torsion_stiffness", "N m/rad", 2000.0, false, 0.0, kInf, "torsional stiffness of the bar"},
     {"lever_arm", "m", 0.25, false, 1e-6, kInf, "length of each lever"}},
    {},
    [](const engine::BlockSettings&) -> std::unique_ptr<Block> { return std::make_unique<AntiRollBar>(); }});

}  // namespace
}  // namespace dydp::blocks
