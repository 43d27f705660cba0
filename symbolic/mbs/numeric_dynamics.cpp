// Numerical recursive Newton-Euler in ground-frame components (the oracle).
#include "symbolic/mbs/numeric_dynamics.hpp"

#include <stdexcept>

namespace dydp::mbs {
namespace {

using V3 = Eigen::Vector3d;
using M3 = Eigen::Matrix3d;

// The joint's axis, parent-frame components.
V3 axis_of_joint(const Joint& joint) { return V3(joint.axis[0], joint.axis[1], joint.axis[2]); }

M3 rotation_about(const V3& axis, double angle) { return Eigen::AngleAxisd(angle, axis).toRotationMatrix(); }

}  // namespace

NumericDynamics::NumericDynamics(Model model) : model_(std::move(model)) {}

void NumericDynamics::set_symbolic_parameters(const double* p) {
  int k = 0;
  for (Parameter& par : model_.parameters)
    if (par.symbolic) par.value = p[k++];
}

bool NumericDynamics::is_ancestor(int joint, int descendant) const {
  for (int j = descendant; j >= 0; j = model_.joints[j].parent)
    if (j == joint) return true;
  return false;
}

NumericDynamics::Kinematics NumericDynamics::kinematics(const Vector& q, const Vector& qd, const Vector& qdd) const {
  const int n = this->n();
  Kinematics k;
  k.rotation.resize(n);
  k.origin.resize(n);
  k.omega.resize(n);
  k.velocity.resize(n);
  k.alpha.resize(n);
  k.acceleration.resize(n);
  for (const int j : model_.order) {
    const Joint& joint = model_.joints[j];
    M3 Rp = M3::Identity();
    V3 xp = V3::Zero(), wp = V3::Zero(), vp = V3::Zero(), ap = V3::Zero(), acc_p = V3::Zero();
    if (joint.parent >= 0) {
      Rp = k.rotation[joint.parent];
      xp = k.origin[joint.parent];
      wp = k.omega[joint.parent];
      vp = k.velocity[joint.parent];
      ap = k.alpha[joint.parent];
      acc_p = k.acceleration[joint.parent];
    }
    const V3 axis = axis_of_joint(joint);
    const V3 a = Rp * axis;  // joint axis, ground components
    V3 local = vec(joint.offset);
    if (!is_revolute(joint.type)) local += q[j] * axis;
    const V3 r = Rp * local;
    k.origin[j] = xp + r;
    if (is_revolute(joint.type)) {
      k.rotation[j] = Rp * rotation_about(axis, q[j]);
      k.omega[j] = wp + a * qd[j];
      k.alpha[j] = ap + a * qdd[j] + wp.cross(a * qd[j]);
      k.velocity[j] = vp + wp.cross(r);
      k.acceleration[j] = acc_p + ap.cross(r) + wp.cross(wp.cross(r));
    } else {
      k.rotation[j] = Rp;
      k.omega[j] = wp;
      k.alpha[j] = ap;
      k.velocity[j] = vp + wp.cross(r) + a * qd[j];
      k.acceleration[j] = acc_p + ap.cross(r) + wp.cross(wp.cross(r)) + a * qdd[j] + 2.0 * wp.cross(a * qd[j]);
    }
  }
  return k;
}

M3 NumericDynamics::frame_rotation(const Kinematics& k, int body) const {
  const int f = model_.bodies[body].frame;
  return f < 0 ? M3::Identity() : k.rotation[f];
}

V3 NumericDynamics::frame_origin(const Kinematics& k, int body) const {
  const int f = model_.bodies[body].frame;
  return f < 0 ? V3::Zero() : k.origin[f];
}

V3 NumericDynamics::point_position(const Kinematics& k, PointRef p) const {
  return frame_origin(k, p.body) + frame_rotation(k, p.body) * vec(model_.bodies[p.body].anchors[p.anchor].position);
}

V3 NumericDynamics::point_velocity(const Kinematics& k, PointRef p) const {
  const int f = model_.bodies[p.body].frame;
  if (f < 0) return V3::Zero();
  const V3 r = point_position(k, p) - k.origin[f];
  return k.velocity[f] + k.omega[f].cross(r);
}

V3 NumericDynamics::point_acceleration(const Kinematics& k, PointRef p) const {
  const int f = model_.bodies[p.body].frame;
  if (f < 0) return V3::Zero();
  const V3 r = point_position(k, p) - k.origin[f];
  return k.acceleration[f] + k.alpha[f].cross(r) + k.omega[f].cross(k.omega[f].cross(r));
}

NumericDynamics::Vector NumericDynamics::residual(const Vector& q, const Vector& qd, const Vector& qdd,
                                                  const Vector& lam, const Vector& inputs) const {
  const int n = this->n();
  // Driven joints are read from q, qd, qdd like the others (direct_dynamics puts them there).
  const Kinematics k = kinematics(q, qd, qdd);
  const V3 g(model_.gravity[0], model_.gravity[1], model_.gravity[2]);

  // External forces and torques on each body, about its frame origin (ground components).
  std::vector<V3> force(model_.bodies.size(), V3::Zero()), torque(model_.bodies.size(), V3::Zero());
  auto apply = [&](PointRef p, const V3& f) {
    if (p.body == 0) return;
    force[p.body] += f;
    torque[p.body] += (point_position(k, p) - frame_origin(k, p.body)).cross(f);
  };
  int at = 0;
  for (const Load& l : model_.loads) {
    if (l.type == Load::Type::LinkForce) {
      const V3 d = point_position(k, l.b) - point_position(k, l.point);
      const V3 f = (l.compression ? 1.0 : -1.0) * inputs[at++] * d / d.norm();  // on b
      apply(l.b, f);
      apply(l.point, -f);
      continue;
    }
    V3 given = V3::Zero();
    for (int c : l.components) given[c] = inputs[at++];
    const V3 v = frame_rotation(k, l.frame) * given;
    if (l.type == Load::Type::Force) apply(l.point, v);
    else {
      if (l.point.body != 0) torque[l.point.body] += v;
      if (l.reaction > 0) torque[l.reaction] -= v;
    }
  }
  int row = 0;
  for (const Cut& c : model_.cuts) {
    const M3 Rc = cut_rotation(k, c);
    if (c.type == Cut::Type::Ball) {
      V3 f = V3::Zero();
      for (int comp : c.components) f[comp] = lam.size() ? lam[row++] : 0.0;
      apply(c.b, Rc * f);
      apply(c.a, -(Rc * f));
    } else if (c.type == Cut::Type::Hinge) {
      // a force at the joined points and a torque normal to the hinge axis: the virtual work of
      // lam on the constraint variations dh (see constraint_jacobian)
      V3 f = V3::Zero(), moment = V3::Zero();
      const HingeFrame axes = hinge_frame(k, c);
      for (int comp = 0; comp < 3; ++comp) f[comp] = lam.size() ? lam[row++] : 0.0;
      f = Rc * f;
      for (const V3& normal : axes.normals) moment += (lam.size() ? lam[row++] : 0.0) * axes.b.cross(normal);
      apply(c.b, f);
      apply(c.a, -f);
      if (c.b.body != 0) torque[c.b.body] += moment;
      if (c.a.body != 0) torque[c.a.body] -= moment;
    } else {
      // h = (d.d - L^2) / 2L, whose gradient is d / L
      const V3 d = point_position(k, c.b) - point_position(k, c.a);
      const V3 f = (lam.size() ? lam[row++] : 0.0) * d / value(c.length);
      apply(c.b, f);
      apply(c.a, -f);
    }
  }
  Vector joint_force = Vector::Zero(n);
  for (const ForceElement& e : model_.forces) {
    if (e.type == ForceElement::Type::JointForce) {
      joint_force[e.joint] += value(e.value);
      continue;
    }
    const V3 d = point_position(k, e.b) - point_position(k, e.a);
    const double length = d.norm();
    const V3 u = d / length;
    const double rate = u.dot(point_velocity(k, e.b) - point_velocity(k, e.a));
    const double tension = value(e.stiffness) * (length - value(e.rest_length)) + value(e.damping) * rate;
    apply(e.a, tension * u);
    apply(e.b, -tension * u);
  }

  // Backward pass: wrench each joint transmits to its subtree, about the joint frame origin.
  std::vector<V3> f(n, V3::Zero()), t(n, V3::Zero());
  for (auto it = model_.order.rbegin(); it != model_.order.rend(); ++it) {
    const int j = *it;
    const Joint& joint = model_.joints[j];
    if (joint.body >= 0) {
      const Body& b = model_.bodies[joint.body];
      const double mass = value(b.mass);
      const M3 R = k.rotation[j];
      const V3 rc = R * vec(b.com);
      const V3 acc_c = k.acceleration[j] + k.alpha[j].cross(rc) + k.omega[j].cross(k.omega[j].cross(rc));
      M3 I;
      I << value(b.inertia[0]), value(b.inertia[3]), value(b.inertia[4]),
           value(b.inertia[3]), value(b.inertia[1]), value(b.inertia[5]),
           value(b.inertia[4]), value(b.inertia[5]), value(b.inertia[2]);
      const M3 Ig = R * I * R.transpose();
      const V3 inertial = mass * (acc_c - g);
      f[j] += inertial - force[joint.body];
      t[j] += Ig * k.alpha[j] + k.omega[j].cross(Ig * k.omega[j]) + rc.cross(inertial) - torque[joint.body];
    }
    if (joint.parent >= 0) {
      f[joint.parent] += f[j];
      t[joint.parent] += t[j] + (k.origin[j] - k.origin[joint.parent]).cross(f[j]);
    }
  }
  Vector r(n);
  for (int j = 0; j < n; ++j) {
    const Joint& joint = model_.joints[j];
    const M3 Rp = joint.parent >= 0 ? k.rotation[joint.parent] : M3::Identity();
    const V3 a = Rp * axis_of_joint(joint);
    r[j] = (is_revolute(joint.type) ? a.dot(t[j]) : a.dot(f[j])) - joint_force[j];
  }
  return r;
}

NumericDynamics::Matrix NumericDynamics::mass(const Vector& q) const {
  const int n = this->n();
  // Gravity and loads do not depend on qdd: the columns are differences of residuals at rest.
  const Vector zero = Vector::Zero(n);
  const Vector inputs = Vector::Zero(model_.input_count());
  const Vector lam;
  const Vector r0 = residual(q, zero, zero, lam, inputs);
  Matrix M(n, n);
  for (int j = 0; j < n; ++j) {
    Vector e = zero;
    e[j] = 1.0;
    M.col(j) = residual(q, zero, e, lam, inputs) - r0;
  }
  // Driven coordinates are inputs; their columns and rows are still the inertia coupling.
  return M;
}

NumericDynamics::Vector NumericDynamics::nonlinear(const Vector& q, const Vector& qd, const Vector& inputs) const {
  return residual(q, qd, Vector::Zero(n()), Vector(), inputs);
}

NumericDynamics::Vector NumericDynamics::constraints(const Vector& q) const {
  const Kinematics k = kinematics(q, Vector::Zero(n()), Vector::Zero(n()));
  Vector h(m());
  int row = 0;
  for (const Cut& c : model_.cuts) {
    const V3 d = point_position(k, c.b) - point_position(k, c.a);
    const V3 dc = cut_rotation(k, c).transpose() * d;  // in the cut's frame
    if (c.type == Cut::Type::Ball) {
      for (int comp : c.components) h[row++] = dc[comp];
    } else if (c.type == Cut::Type::Hinge) {
      const HingeFrame axes = hinge_frame(k, c);
      for (int comp = 0; comp < 3; ++comp) h[row++] = dc[comp];
      for (const V3& normal : axes.normals) h[row++] = normal.dot(axes.b);
    } else {
      const double length = value(c.length);
      h[row++] = (d.squaredNorm() - length * length) / (2.0 * length);
    }
  }
  return h;
}

NumericDynamics::Matrix NumericDynamics::point_jacobian(const Vector& q, PointRef p) const {
  const Kinematics k = kinematics(q, Vector::Zero(n()), Vector::Zero(n()));
  const V3 x = point_position(k, p);
  const int frame = model_.bodies[p.body].frame;
  Matrix J = Matrix::Zero(3, n());
  for (int j = 0; j < n(); ++j) {
    if (frame < 0 || !is_ancestor(j, frame)) continue;
    const Joint& joint = model_.joints[j];
    const M3 Rp = joint.parent >= 0 ? k.rotation[joint.parent] : M3::Identity();
    const V3 a = Rp * axis_of_joint(joint);
    J.col(j) = is_revolute(joint.type) ? V3(a.cross(x - k.origin[j])) : a;
  }
  return J;
}

NumericDynamics::HingeFrame NumericDynamics::hinge_frame(const Kinematics& k, const Cut& c) const {
  const M3 Ra = frame_rotation(k, c.a.body);
  const V3 n1(c.normals_a[0][0], c.normals_a[0][1], c.normals_a[0][2]);
  const V3 n2(c.normals_a[1][0], c.normals_a[1][1], c.normals_a[1][2]);
  return {frame_rotation(k, c.b.body) * V3(c.axis_b[0], c.axis_b[1], c.axis_b[2]), {Ra * n1, Ra * n2}};
}

NumericDynamics::Matrix NumericDynamics::angular_jacobian(const Kinematics& k, int body) const {
  return frame_angular_jacobian(k, model_.bodies[body].frame);
}

int NumericDynamics::cut_frame(const Cut& c) const {
  if (c.type == Cut::Type::Ball && c.components.size() < 3) return -1;
  const int fa = model_.bodies[c.a.body].frame, fb = model_.bodies[c.b.body].frame;
  for (int k = fb; k >= 0; k = model_.joints[k].parent)
    if (fa >= 0 && is_ancestor(k, fa)) return k;
  return -1;
}

NumericDynamics::M3 NumericDynamics::cut_rotation(const Kinematics& k, const Cut& c) const {
  const int frame = cut_frame(c);
  return frame < 0 ? M3(M3::Identity()) : k.rotation[frame];
}

NumericDynamics::Matrix NumericDynamics::frame_angular_jacobian(const Kinematics& k, int frame) const {
  Matrix J = Matrix::Zero(3, n());
  for (int j = 0; j < n(); ++j) {
    const Joint& joint = model_.joints[j];
    if (frame < 0 || !is_revolute(joint.type) || !is_ancestor(j, frame)) continue;
    const M3 Rp = joint.parent >= 0 ? k.rotation[joint.parent] : M3::Identity();
    J.col(j) = Rp * axis_of_joint(joint);
  }
  return J;
}

NumericDynamics::Matrix NumericDynamics::constraint_jacobian(const Vector& q) const {
  const Kinematics k = kinematics(q, Vector::Zero(n()), Vector::Zero(n()));
  Matrix J(m(), n());
  int row = 0;
  for (const Cut& c : model_.cuts) {
    const Matrix Jd = point_jacobian(q, c.b) - point_jacobian(q, c.a);
    // d(Rc^T d)/dq_j = Rc^T (dd/dq_j - w_j x d), w_j the turn of the cut's frame per unit q_j
    const V3 d = point_position(k, c.b) - point_position(k, c.a);
    const M3 Rc = cut_rotation(k, c);
    const Matrix Jw = frame_angular_jacobian(k, cut_frame(c));
    Matrix Jc(3, n());
    for (int j = 0; j < n(); ++j) Jc.col(j) = Rc.transpose() * (V3(Jd.col(j)) - V3(Jw.col(j)).cross(d));
    if (c.type == Cut::Type::Ball) {
      for (int comp : c.components) J.row(row++) = Jc.row(comp);
    } else if (c.type == Cut::Type::Hinge) {
      for (int comp = 0; comp < 3; ++comp) J.row(row++) = Jc.row(comp);
      // d/dq of (n . b) with n turning with a's body and b with b's: (omega_b - omega_a) . (b x n)
      // per unit joint rate, where the body's angular velocity gains the ground axis of every
      // revolute joint on its path to the ground.
      const HingeFrame axes = hinge_frame(k, c);
      const Matrix Jw = angular_jacobian(k, c.b.body) - angular_jacobian(k, c.a.body);
      for (const V3& normal : axes.normals) J.row(row++) = axes.b.cross(normal).transpose() * Jw;
    } else {
      J.row(row++) = (d / value(c.length)).transpose() * Jd;
    }
  }
  return J;
}

NumericDynamics::Vector NumericDynamics::constraint_bias(const Vector& q, const Vector& qd) const {
  const Kinematics k = kinematics(q, qd, Vector::Zero(n()));
  Vector b(m());
  int row = 0;
  for (const Cut& c : model_.cuts) {
    const V3 acc = point_acceleration(k, c.b) - point_acceleration(k, c.a);
    const V3 d = point_position(k, c.b) - point_position(k, c.a);
    const V3 vel = point_velocity(k, c.b) - point_velocity(k, c.a);
    // (Rc^T d)'' = Rc^T (d'' - alpha x d - 2 w x d' + w x (w x d)), w and alpha the cut frame's
    const int frame = cut_frame(c);
    const V3 w = frame < 0 ? V3::Zero() : k.omega[frame], al = frame < 0 ? V3::Zero() : k.alpha[frame];
    const V3 accc = cut_rotation(k, c).transpose() * (acc - al.cross(d) - 2.0 * w.cross(vel) + w.cross(w.cross(d)));
    if (c.type == Cut::Type::Ball) {
      for (int comp : c.components) b[row++] = accc[comp];
    } else if (c.type == Cut::Type::Hinge) {
      for (int comp = 0; comp < 3; ++comp) b[row++] = accc[comp];
      // h = n . b with n' = w_a x n, b' = w_b x b: h'' = n'' . b + 2 n' . b' + n . b'', where
      // v'' = alpha x v + w x (w x v) and alpha holds only the velocity terms (qdd = 0)
      const HingeFrame axes = hinge_frame(k, c);
      const int fa = model_.bodies[c.a.body].frame, fb = model_.bodies[c.b.body].frame;
      const V3 wa = fa < 0 ? V3::Zero() : k.omega[fa], wb = fb < 0 ? V3::Zero() : k.omega[fb];
      const V3 aa = fa < 0 ? V3::Zero() : k.alpha[fa], ab = fb < 0 ? V3::Zero() : k.alpha[fb];
      const V3 b_rate = wb.cross(axes.b), b_acc = ab.cross(axes.b) + wb.cross(b_rate);
      for (const V3& normal : axes.normals) {
        const V3 n_rate = wa.cross(normal), n_acc = aa.cross(normal) + wa.cross(n_rate);
        b[row++] = n_acc.dot(axes.b) + 2.0 * n_rate.dot(b_rate) + normal.dot(b_acc);
      }
    } else {
      // h = (d.d - L^2) / 2L: hddot = (d'.d' + d.d'') / L
      b[row++] = (vel.squaredNorm() + d.dot(acc)) / value(c.length);
    }
  }
  return b;
}

NumericDynamics::Vector NumericDynamics::sensors(const Vector& q, const Vector& qd, const Vector& qdd) const {
  const Kinematics k = kinematics(q, qd, qdd);
  std::vector<double> out;
  for (const Sensor& s : model_.sensors) {
    const M3 RF = frame_rotation(k, s.frame);
    V3 v;
    switch (s.type) {
      case Sensor::Type::AngularVelocity: {
        const int f = model_.bodies[s.a.body].frame;
        v = RF.transpose() * (f < 0 ? V3::Zero() : V3(k.omega[f]));
        break;
      }
      case Sensor::Type::Position: v = RF.transpose() * (point_position(k, s.a) - frame_origin(k, s.frame)); break;
      case Sensor::Type::Velocity: v = RF.transpose() * point_velocity(k, s.a); break;
      case Sensor::Type::Acceleration: v = RF.transpose() * point_acceleration(k, s.a); break;
      case Sensor::Type::Joint: v = V3(q[s.joint], qd[s.joint], qdd[s.joint]); break;
      case Sensor::Type::Length: {
        const V3 d = point_position(k, s.b) - point_position(k, s.a);
        const V3 vel = point_velocity(k, s.b) - point_velocity(k, s.a);
        const double sign = s.compression ? -1.0 : 1.0;
        v = V3(sign * (d.norm() - value(s.reference)), sign * d.dot(vel) / d.norm(), 0.0);
        break;
      }
    }
    for (int c : s.components) out.push_back(v[c]);
  }
  return Eigen::Map<Vector>(out.data(), static_cast<Eigen::Index>(out.size()));
}

NumericDynamics::State NumericDynamics::direct_dynamics(Vector q, Vector qd, const Vector& inputs,
                                                        const std::vector<int>& independent) const {
  const int n = this->n(), m = this->m();
  const std::vector<int> driven = model_.driven_joints();
  const int load_inputs = model_.load_input_count();
  Vector qdd = Vector::Zero(n);
  std::vector<bool> known(n, false);
  for (int u : independent) known[u] = true;
  for (std::size_t i = 0; i < driven.size(); ++i) {
    const int j = driven[i];
    q[j] = inputs[load_inputs + 3 * i];
    qd[j] = inputs[load_inputs + 3 * i + 1];
    qdd[j] = inputs[load_inputs + 3 * i + 2];
    known[j] = true;
  }
  std::vector<int> dependent, free;
  for (int j = 0; j < n; ++j) {
    if (!known[j]) dependent.push_back(j);
    if (!model_.joints[j].driven) free.push_back(j);
  }
  if (static_cast<int>(dependent.size()) != m) throw std::runtime_error("direct_dynamics: dependent coordinates != constraints");
  auto columns = [&](const Matrix& A, const std::vector<int>& cols) {
    Matrix B(A.rows(), static_cast<Eigen::Index>(cols.size()));
    for (std::size_t i = 0; i < cols.size(); ++i) B.col(i) = A.col(cols[i]);
    return B;
  };
  if (m > 0) {
    for (int it = 0; it < 50; ++it) {
      const Vector h = constraints(q);
      if (h.lpNorm<Eigen::Infinity>() < 1e-14) break;
      const Vector dv = columns(constraint_jacobian(q), dependent).fullPivLu().solve(h);
      for (int i = 0; i < m; ++i) q[dependent[i]] -= dv[i];
      if (dv.lpNorm<Eigen::Infinity>() < 1e-15) break;
    }
    for (int j : dependent) qd[j] = 0.0;
    const Matrix J = constraint_jacobian(q);
    const Vector vd = columns(J, dependent).fullPivLu().solve(-(J * qd));
    for (int i = 0; i < m; ++i) qd[dependent[i]] = vd[i];
  }
  const Matrix M = mass(q);
  const Vector c = residual(q, qd, qdd, Vector::Zero(m), inputs);  // includes the driven qdd
  const int nf = static_cast<int>(free.size());
  Matrix A = Matrix::Zero(nf + m, nf + m);
  Vector rhs(nf + m);
  for (int a = 0; a < nf; ++a) {
    for (int b = 0; b < nf; ++b) A(a, b) = M(free[a], free[b]);
    rhs[a] = -c[free[a]];
  }
  if (m > 0) {
    const Matrix J = constraint_jacobian(q);
    const Vector bias = constraint_bias(q, qd) + J * qdd;  // driven accelerations are in qdd
    for (int i = 0; i < m; ++i) {
      for (int b = 0; b < nf; ++b) {
        A(nf + i, b) = J(i, free[b]);
        A(b, nf + i) = -J(i, free[b]);
      }
      rhs[nf + i] = -bias[i];
    }
  }
  const Vector x = A.fullPivLu().solve(rhs);
  for (int a = 0; a < nf; ++a) qdd[free[a]] = x[a];
  State s{q, qd, qdd, x.tail(m)};
  return s;
}

}  // namespace dydp::mbs
