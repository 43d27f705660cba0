// The generator's kinematics: the joints' rotations and offsets, the joint frames' absolute
// placements and velocities (the forward recursion), placements relative to an ancestor frame,
// and points and vectors carried between frames.
#include "symbolic/mbs/newton_euler_generator.hpp"

#include <string>
#include <utility>
#include <vector>

namespace dydp::mbs::detail {

Expr Generator::val(const Value& v) {
  if (v.param >= 0 && param_index_[v.param] >= 0) return v.scale * ctx_->element(out_.p, param_index_[v.param]);
  return ctx_->constant(m_.value(v));
}

V3 Generator::unit(int axis) {
  V3 e = zero3();
  e[axis] = ctx_->one();
  return e;
}

V3 Generator::assign(const std::string& name, int k, const V3& v) {
  V3 r;
  for (int i = 0; i < 3; ++i) r[i] = all_->assign(name + std::to_string(i + 1) + "_" + std::to_string(k + 1), v[i]);
  return r;
}

// The joint's axis (constants), own and parent components alike.
V3 Generator::joint_axis(int k) {
  const Joint& j = m_.joints[k];
  return {{ctx_->constant(j.axis[0]), ctx_->constant(j.axis[1]), ctx_->constant(j.axis[2])}};
}

// Relative rotation of joint k (its frame to its parent's): v_parent = R v_k.
V3 Generator::rotate(int k, const V3& v) {
  const Joint& j = m_.joints[k];
  if (!is_revolute(j.type)) return v;
  if (axis_of(j.type) < 0) {
    const auto& R = relative_rotation_[k];
    V3 r;
    for (int i = 0; i < 3; ++i) r[i] = R[i][0] * v[0] + R[i][1] * v[1] + R[i][2] * v[2];
    return r;
  }
  const int a = axis_of(j.type), i = (a + 1) % 3, l = (a + 2) % 3;
  const Expr c = cos_[k], s = sin_[k];
  V3 r = v;
  r[i] = c * v[i] - s * v[l];
  r[l] = s * v[i] + c * v[l];
  return r;
}
V3 Generator::rotate_back(int k, const V3& v) {
  const Joint& j = m_.joints[k];
  if (!is_revolute(j.type)) return v;
  if (axis_of(j.type) < 0) {
    const auto& R = relative_rotation_[k];
    V3 r;
    for (int i = 0; i < 3; ++i) r[i] = R[0][i] * v[0] + R[1][i] * v[1] + R[2][i] * v[2];
    return r;
  }
  const int a = axis_of(j.type), i = (a + 1) % 3, l = (a + 2) % 3;
  const Expr c = cos_[k], s = sin_[k];
  V3 r = v;
  r[i] = c * v[i] + s * v[l];
  r[l] = -s * v[i] + c * v[l];
  return r;
}

// Origin of joint k relative to its parent's origin, parent components.
V3 Generator::joint_offset(int k) {
  const Joint& j = m_.joints[k];
  V3 r = vec(j.offset);
  if (!is_revolute(j.type)) r = r + ctx_->element(out_.q, k) * joint_axis(k);
  return r;
}

// Absolute rotations and origins.
void Generator::positions() {
  const int n = m_.coordinates();
  rot_.resize(n);
  origin_.resize(n);
  offset_.resize(n);
  relative_rotation_.resize(n);
  for (int k = 0; k < n; ++k) {
    cos_.push_back(symbolic::cos(ctx_->element(out_.q, k)));
    sin_.push_back(symbolic::sin(ctx_->element(out_.q, k)));
    const Joint& j = m_.joints[k];
    if (!is_revolute(j.type) || axis_of(j.type) >= 0) continue;
    // R = cos q I + sin q [a]x + (1 - cos q) a a^T
    const auto& a = j.axis;
    const double skew[3][3] = {{0.0, -a[2], a[1]}, {a[2], 0.0, -a[0]}, {-a[1], a[0], 0.0}};
    const Expr versine = all_->assign("VC" + std::to_string(k + 1), 1.0 - cos_[k]);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        relative_rotation_[k][r][c] = all_->assign("RJ" + std::to_string(r + 1) + std::to_string(c + 1) + "_" + std::to_string(k + 1),
                                          (r == c ? cos_[k] : ctx_->zero()) + skew[r][c] * sin_[k] +
                                              (a[r] * a[c]) * versine);
  }
  for (const int k : m_.order) {
    const Joint& j = m_.joints[k];
    const Rot parent = j.parent >= 0 ? rot_[j.parent] : Rot{{unit(0), unit(1), unit(2)}};
    const V3 parent_origin = j.parent >= 0 ? origin_[j.parent] : zero3();
    offset_[k] = joint_offset(k);
    Rot r = parent;
    if (is_revolute(j.type) && axis_of(j.type) < 0) {
      for (int c = 0; c < 3; ++c)
        r.col[c] = relative_rotation_[k][0][c] * parent.col[0] + relative_rotation_[k][1][c] * parent.col[1] +
                   relative_rotation_[k][2][c] * parent.col[2];
    } else if (is_revolute(j.type)) {
      const int a = axis_of(j.type), i = (a + 1) % 3, l = (a + 2) % 3;
      r.col[i] = cos_[k] * parent.col[i] + sin_[k] * parent.col[l];
      r.col[l] = -sin_[k] * parent.col[i] + cos_[k] * parent.col[l];
    }
    for (int c = 0; c < 3; ++c) r.col[c] = assign("R" + std::to_string(c + 1), k, r.col[c]);
    rot_[k] = r;
    origin_[k] = assign("X", k, parent_origin + parent.apply(offset_[k]));
  }
}

// Angular velocity and origin velocity of every joint frame, own components.
void Generator::velocities() {
  const int n = m_.coordinates();
  omega_.resize(n);
  velocity_.resize(n);
  for (const int k : m_.order) {
    const Joint& j = m_.joints[k];
    const V3 wp = j.parent >= 0 ? omega_[j.parent] : zero3();
    const V3 vp = j.parent >= 0 ? velocity_[j.parent] : zero3();
    const Expr qd = ctx_->element(out_.qd, k);
    const V3 e = joint_axis(k);
    V3 w = rotate_back(k, wp), v = rotate_back(k, vp + cross(wp, offset_[k]));
    if (is_revolute(j.type)) w = w + qd * e;
    else v = v + qd * e;
    omega_[k] = assign("OM", k, w);
    velocity_[k] = assign("V", k, v);
  }
}

Rot Generator::body_rotation(int body) {
  const int f = m_.bodies[body].frame;
  return f < 0 ? Rot{{unit(0), unit(1), unit(2)}} : rot_[f];
}
V3 Generator::body_origin(int body) {
  const int f = m_.bodies[body].frame;
  return f < 0 ? zero3() : origin_[f];
}

// Whether joint frame c (-1: the ground) is k or one of its ancestors.
bool Generator::carries(int c, int k) const {
  if (c < 0) return true;
  for (; k >= 0; k = m_.joints[k].parent)
    if (k == c) return true;
  return false;
}

// v, given in the components of joint frame `from`, in those of `to` (-1: the ground): by the
// rotation relative to the nearer one when one carries the other (a corner body and the
// chassis: the corner's own joints), through the ground otherwise.
V3 Generator::change_frame(int from, int to, const V3& v) {
  if (from == to) return v;
  if (carries(to, from)) return relative_placement(from, to).rot.apply(v);
  if (carries(from, to)) return relative_placement(to, from).rot.apply_transpose(v);
  return frame_rotation(to).apply_transpose(frame_rotation(from).apply(v));
}

// The nearest common ancestor of two joint frames (-1: the ground).
int Generator::common_frame(int fa, int fb) const {
  std::vector<char> above(m_.coordinates(), 0);
  for (int k = fa; k >= 0; k = m_.joints[k].parent) above[k] = 1;
  int k = fb;
  while (k >= 0 && !above[k]) k = m_.joints[k].parent;
  return k;
}

// Rotation and origin of joint frame k relative to its ancestor frame c, in c's components,
// by the same recursion as the absolute ones (positions()), started at c.
Generator::Placement Generator::relative_placement(int k, int c) {
  if (k < 0) return {Rot{{unit(0), unit(1), unit(2)}}, zero3()};  // the ground (then c < 0)
  if (c < 0) return {rot_[k], origin_[k]};
  if (k == c) return {Rot{{unit(0), unit(1), unit(2)}}, zero3()};
  const auto key = std::make_pair(k, c);
  if (const auto it = relative_.find(key); it != relative_.end()) return it->second;
  const Joint& j = m_.joints[k];
  const Placement parent = relative_placement(j.parent, c);
  Rot r = parent.rot;
  if (is_revolute(j.type) && axis_of(j.type) < 0) {
    for (int col = 0; col < 3; ++col)
      r.col[col] = relative_rotation_[k][0][col] * parent.rot.col[0] + relative_rotation_[k][1][col] * parent.rot.col[1] +
                   relative_rotation_[k][2][col] * parent.rot.col[2];
  } else if (is_revolute(j.type)) {
    const int a = axis_of(j.type), i = (a + 1) % 3, l = (a + 2) % 3;
    r.col[i] = cos_[k] * parent.rot.col[i] + sin_[k] * parent.rot.col[l];
    r.col[l] = -sin_[k] * parent.rot.col[i] + cos_[k] * parent.rot.col[l];
  }
  const std::string tag = std::to_string(k + 1) + "_" + std::to_string(c + 1);
  for (int col = 0; col < 3; ++col) r.col[col] = assign("RL" + std::to_string(col + 1) + "_" + tag + "_", 0, r.col[col]);
  const V3 origin = assign("XL_" + tag + "_", 0, parent.origin + parent.rot.apply(offset_[k]));
  return relative_[key] = Placement{r, origin};
}

// A point in the components of frame c (an ancestor of its body's frame), from c's origin.
V3 Generator::point_in(PointRef p, int c) {
  const int f = m_.bodies[p.body].frame;
  if (c < 0) return point_position(p);
  const Placement placement = relative_placement(f, c);
  return placement.origin + placement.rot.apply(anchor(p));
}

// A point's absolute velocity and acceleration (the true one, gravity removed) in the
// components of joint frame `to`, from its body frame's own components.
V3 Generator::velocity_in(PointRef p, int to) {
  const int f = m_.bodies[p.body].frame;
  if (f < 0) return zero3();
  return change_frame(f, to, velocity_[f] + cross(omega_[f], anchor(p)));
}
V3 Generator::acceleration_in(PointRef p, int to) {
  const int f = m_.bodies[p.body].frame;
  const V3 g{{ctx_->constant(m_.gravity[0]), ctx_->constant(m_.gravity[1]), ctx_->constant(m_.gravity[2])}};
  const V3 gravity = change_frame(-1, to, g);
  if (f < 0) return zero3();
  const V3 r = anchor(p);
  return change_frame(f, to, full_acc_[f] + cross(full_alpha_[f], r) + cross(omega_[f], cross(omega_[f], r))) + gravity;
}

}  // namespace dydp::mbs::detail
