// A serial chain of N bodies with 1-DOF revolute joints about x, y, z in turn, written as a
// ROBOTRAN-style recursive Newton-Euler scheme: forward kinematics (OM, OMP, A per body), then a
// backward force recursion giving the joint torques Q. Body origin positions are computed too
// but not flagged as outputs, so elimination has work to do. Deterministic: the benchmark and
// the code generator build the same list.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "symbolic/equation_list.hpp"

namespace dydp::symbolic::bench {

using Vec3 = std::array<Expr, 3>;

struct ChainModel {
  ArrayId q, qd, qdd, p;
};

inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline Vec3 plus(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline Vec3 scaled(Expr s, const Vec3& a) { return {s * a[0], s * a[1], s * a[2]}; }

// v expressed in the child frame of a joint rotating by (C, S) about axis k: R^T v.
inline Vec3 to_child(int k, Expr c, Expr s, const Vec3& v) {
  const int i = (k + 1) % 3, j = (k + 2) % 3;
  Vec3 r = v;
  r[i] = c * v[i] + s * v[j];
  r[j] = c * v[j] - s * v[i];
  return r;
}
// v expressed in the parent frame: R v.
inline Vec3 to_parent(int k, Expr c, Expr s, const Vec3& v) { return to_child(k, c, -s, v); }

inline Vec3 assign(EquationList& list, const std::string& name, std::size_t body, const Vec3& v) {
  Vec3 r;
  for (int c = 0; c < 3; ++c) {
    r[c] = list.assign(name + std::to_string(c + 1) + "_" + std::to_string(body + 1), v[c]);
  }
  return r;
}

inline ChainModel build_chain(EquationList& list, std::size_t bodies) {
  Context& ctx = list.context();
  ChainModel m;
  m.q = ctx.add_array("q", bodies, SymbolKind::Input);
  m.qd = ctx.add_array("qd", bodies, SymbolKind::Input);
  m.qdd = ctx.add_array("qdd", bodies, SymbolKind::Input);
  m.p = ctx.add_array("p", 2 * bodies, SymbolKind::Parameter);  // mass [kg], length [m] per body
  const Expr zero = ctx.zero();
  Vec3 om{zero, zero, zero}, omp{zero, zero, zero}, acc{zero, zero, ctx.constant(9.81)};
  Vec3 pos{zero, zero, zero};
  std::vector<Vec3> oms, omps, accs;
  for (std::size_t b = 0; b < bodies; ++b) {
    const int k = static_cast<int>(b % 3);
    const Expr qb = ctx.element(m.q, b), c = cos(qb), s = sin(qb);
    Vec3 axis{zero, zero, zero};
    axis[k] = ctx.element(m.qd, b);
    Vec3 axis_acc{zero, zero, zero};
    axis_acc[k] = ctx.element(m.qdd, b);
    // origin acceleration of body b from the parent's, along the parent's length (x axis)
    const Vec3 d{b == 0 ? zero : ctx.element(m.p, 2 * b - 1), zero, zero};
    const Vec3 acc_parent = plus(acc, plus(cross(omp, d), cross(om, cross(om, d))));
    pos = assign(list, "PO", b, to_child(k, c, s, plus(pos, d)));
    om = assign(list, "OM", b, plus(to_child(k, c, s, om), axis));
    omp = assign(list, "OMP", b, plus(plus(to_child(k, c, s, omp), axis_acc), cross(om, axis)));
    acc = assign(list, "A", b, to_child(k, c, s, acc_parent));
    oms.push_back(om);
    omps.push_back(omp);
    accs.push_back(acc);
  }
  Vec3 force{zero, zero, zero}, torque{zero, zero, zero};
  std::vector<Vec3> torques(bodies);
  for (std::size_t b = bodies; b-- > 0;) {
    const Expr mass = ctx.element(m.p, 2 * b), length = ctx.element(m.p, 2 * b + 1);
    const Vec3 com{0.5 * length, zero, zero};
    const Vec3 acc_com = plus(accs[b], plus(cross(omps[b], com), cross(oms[b], cross(oms[b], com))));
    const Expr ixx = 0.01 * mass, iyy = mass * length * length / 12.0;
    const Vec3 inertia_om{ixx * oms[b][0], iyy * oms[b][1], iyy * oms[b][2]};
    const Vec3 inertia_omp{ixx * omps[b][0], iyy * omps[b][1], iyy * omps[b][2]};
    Vec3 child_force{zero, zero, zero}, child_torque{zero, zero, zero};
    if (b + 1 < bodies) {
      const int kc = static_cast<int>((b + 1) % 3);
      const Expr qc = ctx.element(m.q, b + 1);
      child_force = to_parent(kc, cos(qc), sin(qc), force);
      child_torque = plus(to_parent(kc, cos(qc), sin(qc), torque),
                          cross(Vec3{length, zero, zero}, child_force));
    }
    force = assign(list, "F", b, plus(scaled(mass, acc_com), child_force));
    torque = assign(list, "N", b,
                    plus(plus(inertia_omp, cross(oms[b], inertia_om)),
                         plus(cross(com, scaled(mass, acc_com)), child_torque)));
    torques[b] = torque;
  }
  // joint torques: the torque component along each joint axis, base to tip
  for (std::size_t b = 0; b < bodies; ++b) {
    list.add_output("Q" + std::to_string(b + 1), torques[b][b % 3]);
  }
  return m;
}

}  // namespace dydp::symbolic::bench
