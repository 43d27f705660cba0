// The Newton-Euler passes (dynamics()): the joint frames' accelerations forward from the ground,
// the loads on the bodies (link forces, the given loads, cut forces, force elements) summed per
// point, then the wrenches backward, each joint force read off its joint's wrench.
#include "symbolic/mbs/newton_euler_generator.hpp"

#include <algorithm>
#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace dydp::mbs::detail {

// The Newton-Euler passes. `full`: gravity, velocities, loads, force elements and cut forces;
// otherwise the inertial pass (M qdd). Returns the joint forces.
// `cut_forces` false: without the cut forces J^T lam (the inverse dynamics proper, which the
// coordinate partitioning needs; the multipliers enter only its tangent). A second full pass
// reuses the first one's forward kinematics.
std::vector<Expr> Generator::dynamics(const std::vector<Expr>& qdd, bool full, const std::string& tag,
                                     bool cut_forces) {
  const ForwardPass forward = forward_accelerations(qdd, full, tag);
  const ExternalLoads loads = external_loads(full, cut_forces, tag);
  return backward_wrenches(forward, loads, tag);
}

// The forward pass: every joint frame's angular and origin accelerations, own components; in the
// inertial pass at qd = 0 with the ground at rest, in a full one with the velocities of
// velocities() and the ground accelerating at -g (gravity as an inertial force). A full pass keeps
// its accelerations (full_alpha_, full_acc_) for the cut accelerations and the next full pass.
Generator::ForwardPass Generator::forward_accelerations(const std::vector<Expr>& qdd, bool full,
                                                        const std::string& tag) {
  const int n = m_.coordinates();
  std::vector<V3> omega(n), alpha(n), acc(n);
  const bool forward_known = full && !full_alpha_.empty();
  if (forward_known) {
    omega = omega_;
    alpha = full_alpha_;
    acc = full_acc_;
  }
  for (const int k : m_.order) {
    if (forward_known) break;
    const Joint& j = m_.joints[k];
    const V3 wp = j.parent >= 0 ? omega[j.parent] : zero3();
    const V3 ap = j.parent >= 0 ? alpha[j.parent] : zero3();
    V3 accp = zero3();
    if (j.parent >= 0) accp = acc[j.parent];
    else if (full) accp = -V3{{ctx_->constant(m_.gravity[0]), ctx_->constant(m_.gravity[1]), ctx_->constant(m_.gravity[2])}};
    const V3 e = joint_axis(k);
    const Expr qd = full ? ctx_->element(out_.qd, k) : ctx_->zero();
    const V3 r = offset_[k];
    V3 a = rotate_back(k, accp + cross(ap, r) + cross(wp, cross(wp, r)));
    V3 al = rotate_back(k, ap);
    if (is_revolute(j.type)) {
      al = al + qdd[k] * e + cross(rotate_back(k, wp), qd * e);
    } else {
      a = a + qdd[k] * e + 2.0 * qd * cross(rotate_back(k, wp), e);
    }
    omega[k] = full ? omega_[k] : zero3();
    alpha[k] = assign("OMP" + tag, k, al);
    acc[k] = assign("A" + tag, k, a);
  }
  if (full) {
    full_alpha_ = alpha;
    full_acc_ = acc;
  }
  return {omega, alpha, acc};
}

// The loads of one pass on the bodies: none in the inertial pass; in a full one the link forces,
// the given loads, the cut forces (unless `cut_forces` is false) and the force elements, in that
// order, then the forces summed per point.
Generator::ExternalLoads Generator::external_loads(bool full, bool cut_forces, const std::string& tag) {
  ExternalLoads loads;
  loads.ext_f.assign(m_.bodies.size(), zero3());
  loads.ext_n.assign(m_.bodies.size(), zero3());
  loads.joint_force.assign(m_.coordinates(), ctx_->zero());
  if (full) {
    apply_link_forces(loads);
    apply_given_loads(loads);
    if (cut_forces) apply_cut_forces(loads);
    apply_force_elements(loads);
  }
  sum_point_forces(loads, tag);
  return loads;
}

// A force given in the components of joint frame `frame`, at a point: turned into the
// point's body frame by the relative rotation when `frame` is an ancestor (for a spring
// between chassis and wishbone, one joint's rotation) instead of through the ground.
// Forces are summed per point of application (the tyre's three components at its contact
// point, the cut forces at a ball joint) and their moment taken once, after every load.
void Generator::apply_in(ExternalLoads& loads, PointRef p, int frame, const V3& force) {
  if (p.body == 0) return;
  const V3 f = to_body(p.body, frame, force);
  const auto key = std::make_pair(p.body, p.anchor);
  const auto it = loads.point_force.find(key);
  loads.point_force[key] = it == loads.point_force.end() ? f : it->second + f;
}

// Link forces between the same two points (a spring and a damper on one strut) act along
// the same line: their magnitudes are summed and the line's force applied once.
void Generator::apply_link_forces(ExternalLoads& loads) {
  struct LinkGroup {
    PointRef a, b;
    int first_input;
    Expr tension;  // positive pulls the points together
  };
  std::vector<LinkGroup> links;
  {
    int at = 0;
    for (const Load& l : m_.loads) {
      if (l.type != Load::Type::LinkForce) {
        at += l.width();
        continue;
      }
      const Expr magnitude = ctx_->element(out_.inp, at);
      const Expr tension = l.compression ? -magnitude : magnitude;
      auto same = [&](const LinkGroup& g) {
        return g.a.body == l.point.body && g.a.anchor == l.point.anchor && g.b.body == l.b.body && g.b.anchor == l.b.anchor;
      };
      const auto it = std::find_if(links.begin(), links.end(), same);
      if (it == links.end()) links.push_back({l.point, l.b, at, tension});
      else it->tension = it->tension + tension;
      ++at;
    }
  }
  for (const LinkGroup& g : links) {
    // in the frame of the two bodies' common ancestor: lengths do not depend on it
    const int c = common_frame(m_.bodies[g.a.body].frame, m_.bodies[g.b.body].frame);
    const V3 d = assign("DL", g.first_input, point_in(g.b, c) - point_in(g.a, c));
    const Expr length = all_->assign("LL" + std::to_string(g.first_input + 1), symbolic::sqrt(dot(d, d)));
    const V3 f = (-g.tension / length) * d;  // on b
    apply_in(loads, g.b, c, f);
    apply_in(loads, g.a, c, -f);
  }
}

// The given loads: a force at a point, or a torque on a body (and its opposite on the reaction
// body), components in the frame of the load's body; the link forces' inputs are skipped.
void Generator::apply_given_loads(ExternalLoads& loads) {
  int at = 0;
  for (const Load& l : m_.loads) {
    if (l.type == Load::Type::LinkForce) {
      ++at;
      continue;
    }
    V3 given = zero3();
    for (int c : l.components) given[c] = ctx_->element(out_.inp, at++);
    const int frame = m_.bodies[l.frame].frame;
    if (l.type == Load::Type::Force) {
      apply_in(loads, l.point, frame, given);
    } else {
      if (l.point.body != 0)
        loads.ext_n[l.point.body] = loads.ext_n[l.point.body] + to_body(l.point.body, frame, given);
      if (l.reaction > 0)
        loads.ext_n[l.reaction] = loads.ext_n[l.reaction] - to_body(l.reaction, frame, given);
    }
  }
}

// The cut forces J^T lam: each cut's multipliers as a force on b and its opposite on a, and a
// hinge's alignment rows as torques.
void Generator::apply_cut_forces(ExternalLoads& loads) {
  int row = 0;
  for (std::size_t ci = 0; ci < m_.cuts.size(); ++ci) {
    const Cut& c = m_.cuts[ci];
    // ball and hinge rows are components in the cut's frame, and so is their force
    const int frame = cut_frame(c);
    V3 f = zero3();
    if (c.type == Cut::Type::Ball) {
      for (int comp : c.components) f[comp] = ctx_->element(out_.lam, row++);
    } else if (c.type == Cut::Type::Hinge) {
      for (int comp = 0; comp < 3; ++comp) f[comp] = ctx_->element(out_.lam, row++);
      // The alignment rows h = (R_a n) . (R_b axis_b) vary by (dtheta_b - dtheta_a) . (b x n):
      // their multipliers are the torques lam (b x n) on b and the opposite on a.
      const HingeAxes axes = hinge_axes(c);
      V3 torque = zero3();
      for (const V3& normal : axes.normals) torque = torque + ctx_->element(out_.lam, row++) * cross(axes.b, normal);
      torque = assign("TC", row - 1, torque);
      if (c.b.body != 0)
        loads.ext_n[c.b.body] = loads.ext_n[c.b.body] + body_rotation(c.b.body).apply_transpose(torque);
      if (c.a.body != 0)
        loads.ext_n[c.a.body] = loads.ext_n[c.a.body] - body_rotation(c.a.body).apply_transpose(torque);
    } else {
      // h = (d.d - L^2) / 2L: J^T lam is the force (lam / L) d on b
      f = (ctx_->element(out_.lam, row++) / val(c.length)) * cut_vector(ci);
    }
    apply_in(loads, c.b, frame, f);
    apply_in(loads, c.a, frame, -f);
  }
}

// The force elements: a joint force on its coordinate, a spring-damper between two points.
void Generator::apply_force_elements(ExternalLoads& loads) {
  int spring = 0;
  for (const ForceElement& e : m_.forces) {
    if (e.type == ForceElement::Type::JointForce) {
      loads.joint_force[e.joint] = loads.joint_force[e.joint] + val(e.value);
      continue;
    }
    ++spring;
    // in the frame of the two bodies' common ancestor, like the link forces
    const int c = common_frame(m_.bodies[e.a.body].frame, m_.bodies[e.b.body].frame);
    const V3 d = assign("DS", spring - 1, point_in(e.b, c) - point_in(e.a, c));
    const Expr length = all_->assign("LS" + std::to_string(spring), symbolic::sqrt(dot(d, d)));
    const V3 dv = velocity_in(e.b, c) - velocity_in(e.a, c);
    const Expr rate = all_->assign("LSD" + std::to_string(spring), dot(d, dv) / length);
    const Expr tension = all_->assign("FS" + std::to_string(spring),
        val(e.stiffness) * (length - val(e.rest_length)) + val(e.damping) * rate);
    const V3 f = (tension / length) * d;
    apply_in(loads, e.a, c, f);
    apply_in(loads, e.b, c, -f);
  }
}

// Each point's summed force, assigned once, and its moment about the body frame's origin.
void Generator::sum_point_forces(ExternalLoads& loads, const std::string& tag) {
  for (const auto& [key, f] : loads.point_force) {
    const V3 sum = assign("FP" + tag + std::to_string(key.first) + "_", key.second, f);
    loads.ext_f[key.first] = loads.ext_f[key.first] + sum;
    loads.ext_n[key.first] = loads.ext_n[key.first] + cross(anchor(PointRef{key.first, key.second}), sum);
  }
}

// The backward pass: the wrench of each joint's subtree about its origin, own components (the
// body's inertial wrench less its loads, plus the children's carried over), and the joint force
// read off it along the axis, less the joint force elements.
std::vector<Expr> Generator::backward_wrenches(const ForwardPass& forward, const ExternalLoads& loads,
                                               const std::string& tag) {
  const int n = m_.coordinates();
  std::vector<V3> child_f(n, zero3()), child_n(n, zero3());
  std::vector<Expr> q_force(n);
  for (auto it = m_.order.rbegin(); it != m_.order.rend(); ++it) {
    const int k = *it;
    const Joint& j = m_.joints[k];
    V3 f = child_f[k], t = child_n[k];
    if (j.body >= 0) {
      const Body& b = m_.bodies[j.body];
      const Expr mass = val(b.mass);
      const V3 com = vec(b.com);
      const V3 w = forward.omega[k], al = forward.alpha[k];
      const V3 acc_g = forward.acc[k] + cross(al, com) + cross(w, cross(w, com));
      const V3 inertial = mass * acc_g;
      const Expr ixx = val(b.inertia[0]), iyy = val(b.inertia[1]), izz = val(b.inertia[2]);
      const Expr ixy = val(b.inertia[3]), ixz = val(b.inertia[4]), iyz = val(b.inertia[5]);
      auto I = [&](const V3& v) {
        return V3{{ixx * v[0] + ixy * v[1] + ixz * v[2], ixy * v[0] + iyy * v[1] + iyz * v[2],
                   ixz * v[0] + iyz * v[1] + izz * v[2]}};
      };
      f = f + inertial - loads.ext_f[j.body];
      t = t + I(al) + cross(w, I(w)) + cross(com, inertial) - loads.ext_n[j.body];
    }
    f = assign("F" + tag, k, f);
    t = assign("N" + tag, k, t);
    const V3 e = joint_axis(k);
    q_force[k] = all_->assign("Q" + tag + std::to_string(k + 1),
                              (is_revolute(j.type) ? dot(e, t) : dot(e, f)) - loads.joint_force[k]);
    if (j.parent >= 0) {
      const V3 fp = rotate(k, f);
      child_f[j.parent] = child_f[j.parent] + fp;
      child_n[j.parent] = child_n[j.parent] + rotate(k, t) + cross(offset_[k], fp);
    }
  }
  return q_force;
}

}  // namespace dydp::mbs::detail
