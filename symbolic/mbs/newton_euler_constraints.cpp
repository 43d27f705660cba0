// The cut joints' equations h, their Jacobian J in closed form, and their second time derivatives
// J qdd + Jdot qd (and Jdot qd alone) from the cut points' motion, absolute or relative to the
// frame a cut is written in.
#include "symbolic/mbs/newton_euler_generator.hpp"

#include <array>
#include <cstddef>
#include <map>
#include <string>
#include <tuple>
#include <vector>

namespace dydp::mbs::detail {

// Every cut's equations are written in the frame of the nearest joint frame that carries both
// of its bodies (for a suspension corner, the chassis), so that they do not depend on the
// coordinates above it: J has zero columns there and each loop's rows read its own
// coordinates only. A ball cut that keeps a subset of components stays in ground components.
std::vector<Expr> Generator::constraint_values() {
  std::vector<Expr> h;
  int row = 0;
  for (std::size_t ci = 0; ci < m_.cuts.size(); ++ci) {
    const Cut& c = m_.cuts[ci];
    const V3 d = cut_vector(ci);
    if (c.type == Cut::Type::Ball) {
      for (int comp : c.components) h.push_back(all_->assign("H" + std::to_string(++row), d[comp]));
    } else if (c.type == Cut::Type::Hinge) {
      for (int comp = 0; comp < 3; ++comp) h.push_back(all_->assign("H" + std::to_string(++row), d[comp]));
      const HingeAxes axes = hinge_axes(c);
      for (const V3& normal : axes.normals) h.push_back(all_->assign("H" + std::to_string(++row), dot(normal, axes.b)));
    } else {
      // |d| = L without a square root: (d.d - L^2) / 2L, with the same Jacobian on |d| = L
      const Expr length = val(c.length);
      h.push_back(all_->assign("H" + std::to_string(++row), (dot(d, d) - length * length) * (0.5 / length)));
    }
  }
  return h;
}

// The frame a cut's equations are written in (constraint_values()); -1: the ground.
int Generator::cut_frame(const Cut& c) const {
  if (c.type == Cut::Type::Ball && c.components.size() < 3) return -1;
  return common_frame(m_.bodies[c.a.body].frame, m_.bodies[c.b.body].frame);
}

// b - a of cut i in the cut's frame (assigned once).
V3 Generator::cut_vector(std::size_t i) {
  if (cut_vectors_.size() < m_.cuts.size()) cut_vectors_.resize(m_.cuts.size());
  if (!cut_vectors_[i].c[0].valid()) {
    const Cut& c = m_.cuts[i];
    const int frame = cut_frame(c);
    cut_vectors_[i] = assign("DC", static_cast<int>(i), point_in(c.b, frame) - point_in(c.a, frame));
  }
  return cut_vectors_[i];
}

// A hinge cut's axes in ground components: axis_b carried by b's body, the normals of axis_a
// by a's body (Cut::normals_a).
Generator::HingeAxes Generator::hinge_axes(const Cut& c) {
  auto constant = [&](const std::array<double, 3>& v) {
    return V3{{ctx_->constant(v[0]), ctx_->constant(v[1]), ctx_->constant(v[2])}};
  };
  const Rot ra = body_rotation(c.a.body), rb = body_rotation(c.b.body);
  return {rb.apply(constant(c.axis_b)), {ra.apply(constant(c.normals_a[0])), ra.apply(constant(c.normals_a[1]))}};
}

// Joints between a point's frame and the ancestor frame c (c excluded), from the point up.
std::vector<int> Generator::path_to(int frame, int c) const {
  std::vector<int> path;
  for (int k = frame; k != c && k >= 0; k = m_.joints[k].parent) path.push_back(k);
  return path;
}

// d(P in c's components)/dq_j for joint j on P's path to c: e_j x (P - o_j) for a revolute
// joint (e_j its axis, o_j its origin, in c's components), e_j for a prismatic one.
V3 Generator::point_rate(PointRef p, int c, int j) {
  const Joint& joint = m_.joints[j];
  const Placement parent = relative_placement(joint.parent, c);
  const V3 e = parent.rot.apply(joint_axis(j));
  if (!is_revolute(joint.type)) return e;
  return cross(e, point_in(p, c) - relative_placement(j, c).origin);
}

// dd/dq_j of a cut's vector d = b - a (cut frame components), by joint.
std::map<int, V3> Generator::cut_vector_rates(const Cut& c) {
  const int frame = cut_frame(c);
  std::map<int, V3> rates;
  for (int j : path_to(m_.bodies[c.b.body].frame, frame)) rates[j] = point_rate(c.b, frame, j);
  for (int j : path_to(m_.bodies[c.a.body].frame, frame)) {
    const V3 r = point_rate(c.a, frame, j);
    const auto it = rates.find(j);
    rates[j] = it == rates.end() ? -r : it->second - r;
  }
  return rates;
}

// J (m x n): the cut equations' rates per joint, in closed form over the relative kinematics.
std::vector<std::vector<Expr>> Generator::constraint_jacobian() {
  const int n = m_.coordinates();
  std::vector<std::vector<Expr>> J;
  int row = 0;
  auto add_row = [&](const std::vector<Expr>& values) {
    ++row;
    std::vector<Expr> assigned(n);
    for (int j = 0; j < n; ++j)
      assigned[j] = all_->assign("JC" + std::to_string(row) + "_" + std::to_string(j + 1), values[j]);
    J.push_back(assigned);
  };
  for (std::size_t ci = 0; ci < m_.cuts.size(); ++ci) {
    const Cut& c = m_.cuts[ci];
    std::map<int, V3> rates = cut_vector_rates(c);
    for (auto& [j, rate] : rates) rate = assign("DCJ" + std::to_string(ci + 1) + "_", j, rate);
    auto component_row = [&](int comp) {
      std::vector<Expr> values(n, ctx_->zero());
      for (const auto& [j, rate] : rates) values[j] = rate[comp];
      add_row(values);
    };
    if (c.type == Cut::Type::Ball) {
      for (int comp : c.components) component_row(comp);
    } else if (c.type == Cut::Type::Hinge) {
      for (int comp = 0; comp < 3; ++comp) component_row(comp);
      // (n . b)' = (w_b - w_a) . (b x n): each revolute joint above b (a) turns it about its
      // ground axis; joints above both cancel.
      const HingeAxes axes = hinge_axes(c);
      for (const V3& normal : axes.normals) {
        const V3 bn = cross(axes.b, normal);
        std::vector<Expr> values(n, ctx_->zero());
        auto turn = [&](int frame, double sign) {
          for (int j : path_to(frame, -1)) {
            if (!is_revolute(m_.joints[j].type)) continue;
            const int parent = m_.joints[j].parent;
            const V3 e = frame_rotation(parent).apply(joint_axis(j));
            values[j] = values[j] + sign * dot(e, bn);
          }
        };
        turn(m_.bodies[c.b.body].frame, 1.0);
        turn(m_.bodies[c.a.body].frame, -1.0);
        add_row(values);
      }
    } else {
      // h = (d.d - L^2) / 2L: dh/dq_j = d/L . dd/dq_j, where a revolute joint turning a
      // point P about its origin o gives d/L . (e x (P - o)) = e . ((P - o) x d/L): the
      // joints that turn P about one origin (a ball joint's three revolutes) share that
      // moment, and each adds one dot product with its axis.
      const int frame = cut_frame(c);
      const V3 scaled = assign("DS" + std::to_string(ci + 1) + "_", 0, (1.0 / val(c.length)) * cut_vector(ci));
      std::vector<Expr> values(n, ctx_->zero());
      auto turn = [&](PointRef point, double sign) {
        std::map<std::array<NodeId, 3>, V3> moments;  // (P - o) x d/L by origin o
        for (int j : path_to(m_.bodies[point.body].frame, frame)) {
          const V3 e = relative_placement(m_.joints[j].parent, frame).rot.apply(joint_axis(j));
          if (!is_revolute(m_.joints[j].type)) {
            values[j] = values[j] + sign * dot(e, scaled);
            continue;
          }
          const V3 o = relative_placement(j, frame).origin;
          const std::array<NodeId, 3> key{o[0].id(), o[1].id(), o[2].id()};
          auto it = moments.find(key);
          if (it == moments.end()) {
            const std::string tag = "DW" + std::to_string(ci + 1) + (sign > 0 ? "b" : "a") + "_";
            it = moments.emplace(key, assign(tag, j, cross(point_in(point, frame) - o, scaled))).first;
          }
          values[j] = values[j] + sign * dot(e, it->second);
        }
      };
      turn(c.b, 1.0);
      turn(c.a, -1.0);
      add_row(values);
    }
  }
  return J;
}

// Velocity and acceleration (the scheme's, ground at -g) of a point, in the components of the
// frame c its body's frame descends from (-1: the ground), from the full pass.
Generator::PointMotion Generator::point_motion(PointRef p, int c) {
  const int f = m_.bodies[p.body].frame;
  if (f < 0) {  // a ground point (then c is the ground too)
    const V3 g{{ctx_->constant(-m_.gravity[0]), ctx_->constant(-m_.gravity[1]), ctx_->constant(-m_.gravity[2])}};
    return {zero3(), g};
  }
  const V3 r = anchor(p);
  const V3 wr = cross(omega_[f], r);
  const V3 v = velocity_[f] + wr;
  const V3 a = full_acc_[f] + cross(full_alpha_[f], r) + cross(omega_[f], wr);
  if (f == c) return {v, a};
  const Rot rot = relative_placement(f, c).rot;
  return {rot.apply(v), rot.apply(a)};
}

// Motion of joint frame k relative to its ancestor frame c, held fixed (c's own motion
// removed), in k's components: the forward recursion of velocities and accelerations started
// at rest at c, over the joints between them.
// `with_qdd` false: at qdd = 0 (the velocity-product terms, Jdot qd).
Generator::RelativeMotion Generator::relative_motion(int k, int c, bool with_qdd) {
  if (k == c) return {zero3(), zero3(), zero3(), zero3()};
  const auto key = std::make_tuple(k, c, with_qdd);
  if (const auto it = relative_motion_.find(key); it != relative_motion_.end()) return it->second;
  const Joint& j = m_.joints[k];
  const RelativeMotion p = relative_motion(j.parent, c, with_qdd);
  const V3 r = offset_[k], e = joint_axis(k);
  const Expr qd = ctx_->element(out_.qd, k), qdd = with_qdd ? ctx_->element(out_.qdd, k) : ctx_->zero();
  const V3 wp = rotate_back(k, p.omega);
  V3 w = wp, v = rotate_back(k, p.velocity + cross(p.omega, r));
  V3 al = rotate_back(k, p.alpha);
  V3 a = rotate_back(k, p.acc + cross(p.alpha, r) + cross(p.omega, cross(p.omega, r)));
  if (is_revolute(j.type)) {
    w = w + qd * e;
    al = al + qdd * e + cross(wp, qd * e);
  } else {
    v = v + qd * e;
    a = a + qdd * e + 2.0 * qd * cross(wp, e);
  }
  const std::string tag = (with_qdd ? "R" : "RB") + std::to_string(c + 1) + "_";
  RelativeMotion m{assign("OM" + tag, k, w), assign("V" + tag, k, v), assign("OMP" + tag, k, al), assign("A" + tag, k, a)};
  return relative_motion_[key] = m;
}

// A point's velocity and acceleration relative to frame c (an ancestor of its body's frame, or
// that frame), in c's components.
Generator::PointMotion Generator::relative_point_motion(PointRef p, int c, bool with_qdd) {
  const int f = m_.bodies[p.body].frame;
  if (f == c) return {zero3(), zero3()};
  const RelativeMotion m = relative_motion(f, c, with_qdd);
  const V3 r = anchor(p);
  const V3 wr = cross(m.omega, r);
  const V3 v = m.velocity + wr;
  const V3 a = m.acc + cross(m.alpha, r) + cross(m.omega, wr);
  const Rot rot = relative_placement(f, c).rot;
  return {rot.apply(v), rot.apply(a)};
}

// Jdot qd, the cut equations' second derivatives at qdd = 0, from the relative passes alone;
// empty when a cut needs the absolute one (a hinge, or a ball in ground components).
std::vector<Expr> Generator::constraint_bias() {
  std::vector<Expr> rows;
  int row = 0;
  for (std::size_t ci = 0; ci < m_.cuts.size(); ++ci) {
    const Cut& c = m_.cuts[ci];
    if (cut_frame(c) < 0 || c.type == Cut::Type::Hinge) return {};
    relative_cut_rows(ci, /*with_qdd=*/false, "HB", row, rows);
  }
  return rows;
}

// The second derivatives of the rows of cut ci (written in a joint frame c, not a hinge): d in
// c's components depends on the joints between c and the two points only, so its derivatives
// are the points' motion relative to c held fixed. `with_qdd` false: at qdd = 0 (Jdot qd).
// Rows are assigned as PREFIX1, PREFIX2, ... counting on from `row`.
void Generator::relative_cut_rows(std::size_t ci, bool with_qdd, const std::string& prefix, int& row,
                                  std::vector<Expr>& rows) {
  const Cut& c = m_.cuts[ci];
  const int frame = cut_frame(c);
  const PointMotion b = relative_point_motion(c.b, frame, with_qdd), a = relative_point_motion(c.a, frame, with_qdd);
  const V3 da = b.acceleration - a.acceleration;
  if (c.type == Cut::Type::Distance) {
    const V3 dv = assign("DCV" + std::string(with_qdd ? "" : "B") + std::to_string(ci + 1) + "_", 0, b.velocity - a.velocity);
    const Expr inverse_length = 1.0 / val(c.length);
    rows.push_back(all_->assign(prefix + std::to_string(++row), (dot(dv, dv) + dot(cut_vector(ci), da)) * inverse_length));
  } else {
    for (int comp : c.components) rows.push_back(all_->assign(prefix + std::to_string(++row), da[comp]));
  }
}

// The second time derivative of every cut equation, J qdd + Jdot qd, from the full pass's
// velocities and accelerations. A cut written in the components of a moving frame c (angular
// velocity w, acceleration al, own components): with d = R_c^T (x_b - x_a),
// d' = R_c^T dx' - w x d and d'' = R_c^T dx'' - 2 w x d' - al x d - w x (w x d).
std::vector<Expr> Generator::cut_accelerations() {
  std::vector<Expr> rows;
  int row = 0;
  for (std::size_t ci = 0; ci < m_.cuts.size(); ++ci) {
    const Cut& c = m_.cuts[ci];
    const int frame = cut_frame(c);
    const std::string tag = std::to_string(ci + 1) + "_";
    if (frame >= 0 && c.type != Cut::Type::Hinge) {
      relative_cut_rows(ci, /*with_qdd=*/true, "HA", row, rows);
      continue;
    }
    const PointMotion b = point_motion(c.b, frame), a = point_motion(c.a, frame);
    const V3 dv = assign("DCV" + tag, 0, b.velocity - a.velocity);  // R_c^T dx'
    const V3 da = b.acceleration - a.acceleration;                   // R_c^T dx''
    const V3 d = cut_vector(ci);
    if (c.type == Cut::Type::Distance) {
      // h = (d.d - L^2) / 2L: h'' = (dx'.dx' + dx.dx'') / L, in any one frame's components
      const Expr inverse_length = 1.0 / val(c.length);
      rows.push_back(all_->assign("HA" + std::to_string(++row), (dot(dv, dv) + dot(d, da)) * inverse_length));
      continue;
    }
    V3 dd = da;
    if (frame >= 0) {
      const V3 w = omega_[frame], al = full_alpha_[frame];
      const V3 wd = assign("DCW" + tag, 0, cross(w, d));
      const V3 rate = assign("DCR" + tag, 0, dv - wd);  // d'
      dd = da - ctx_->constant(2.0) * cross(w, rate) - cross(al, d) - cross(w, wd);
    }
    dd = assign("DCA" + tag, 0, dd);
    if (c.type == Cut::Type::Ball) {
      for (int comp : c.components) rows.push_back(all_->assign("HA" + std::to_string(++row), dd[comp]));
      continue;
    }
    for (int comp = 0; comp < 3; ++comp) rows.push_back(all_->assign("HA" + std::to_string(++row), dd[comp]));
    // hinge alignment h = n . b (ground components): h' = (w_b - w_a) . (b x n),
    // h'' = (al_b - al_a) . (b x n) + (w_b - w_a) . ((w_b x b) x n + b x (w_a x n))
    const HingeAxes axes = hinge_axes(c);
    auto absolute = [&](int body, const std::vector<V3>& own) {
      const int f = m_.bodies[body].frame;
      return f < 0 ? zero3() : rot_[f].apply(own[f]);
    };
    const V3 wa = absolute(c.a.body, omega_), wb = absolute(c.b.body, omega_);
    const V3 dal = absolute(c.b.body, full_alpha_) - absolute(c.a.body, full_alpha_);
    const V3 rate_b = cross(wb, axes.b);
    for (const V3& normal : axes.normals) {
      const V3 bn = cross(axes.b, normal);
      const V3 rate = cross(rate_b, normal) + cross(axes.b, cross(wa, normal));
      rows.push_back(all_->assign("HA" + std::to_string(++row), dot(dal, bn) + dot(wb - wa, rate)));
    }
  }
  return rows;
}

}  // namespace dydp::mbs::detail
