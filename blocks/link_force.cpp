// mechanics.link_force: a force element's tension applied along the line between its two
// anchor points, as the force vectors on each end (for springs, dampers and struts acting
// between bodies of a multibody model).
#include <cmath>

#include "engine/framework/registry.hpp"

namespace dydp::blocks {
namespace {

using engine::Block;
using engine::DirView;
using engine::Eval;
using engine::OutOfDomain;
using engine::Seeds;

/// n = (b - a) / |b - a|; force on a = T n (tension pulls a towards b), force on b = -T n.
class LinkForce : public Block {
 public:
  LinkForce() {
    declare_input("a", 3, "m");
    declare_input("b", 3, "m");
    declare_input("tension", 1, "N");
    declare_output("force_a", 3, "N");
    declare_output("force_b", 3, "N");
  }
  static double direction(const Eval& e, double* n) {
    double len2 = 0;
    for (int i = 0; i < 3; ++i) n[i] = e.u[1][i] - e.u[0][i], len2 += n[i] * n[i];
    const double len = std::sqrt(len2);
    if (!(len > 1e-12)) throw OutOfDomain{"link_force: the two anchor points coincide"};
    for (int i = 0; i < 3; ++i) n[i] /= len;
    return len;
  }
  void outputs(const Eval& e, double* const* y) const override {
    double n[3];
    direction(e, n);
    const double T = e.u[2][0];
    for (int i = 0; i < 3; ++i) y[0][i] = T * n[i], y[1][i] = -T * n[i];
  }
  /// dn = (dr - n (n . dr)) / |r|, r = b - a.
  void outputs_tangent(const Eval& e, const Seeds& s, const DirView* dy) const override {
    double n[3];
    const double len = direction(e, n), T = e.u[2][0];
    for (int d = 0; d < s.directions; ++d) {
      double dr[3], ndr = 0;
      for (int i = 0; i < 3; ++i) dr[i] = s.u[1](i, d) - s.u[0](i, d), ndr += n[i] * dr[i];
      const double dT = s.u[2](0, d);
      for (int i = 0; i < 3; ++i) {
        const double f = dT * n[i] + T * (dr[i] - n[i] * ndr) / len;
        dy[0](i, d) = f;
        dy[1](i, d) = -f;
      }
    }
  }
};

const engine::BlockRegistration link_force({
    "mechanics.link_force", "mechanics",
    "Tension along the line between anchors a and b, as the forces on a (towards b) and on b.",
    {}, {},
    [](const engine::BlockSettings&) -> std::unique_ptr<Block> { return std::make_unique<LinkForce>(); }});

}  // namespace
}  // namespace dydp::blocks
