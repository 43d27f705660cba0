// The numerical multibody formalism: forward kinematics and recursive Newton-Euler evaluated
// with Eigen at run time, in ground-frame components, with 3x3 rotations. No symbolic anything:
// it is the test oracle of the generated functions and the "numerical" baseline of benchmarks.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <vector>

#include "symbolic/mbs/model.hpp"

namespace dydp::mbs {

class NumericDynamics {
 public:
  using Vector = Eigen::VectorXd;
  using Matrix = Eigen::MatrixXd;
  using V3 = Eigen::Vector3d;
  using M3 = Eigen::Matrix3d;

  explicit NumericDynamics(Model model);

  const Model& model() const { return model_; }
  int n() const { return model_.coordinates(); }
  int m() const { return model_.constraint_count(); }
  // Values of the symbolic parameters (in the order they are declared, folded ones skipped).
  void set_symbolic_parameters(const double* p);

  // Positions, velocities, accelerations of every joint frame (ground components).
  struct Kinematics {
    std::vector<M3> rotation;
    std::vector<V3> origin, omega, velocity, alpha, acceleration;
  };
  Kinematics kinematics(const Vector& q, const Vector& qd, const Vector& qdd) const;

  // r = M(q) qdd + c(q, qd, inputs) - J(q)^T lam: the joint forces needed (recursive
  // Newton-Euler), with the cut forces lam applied as external forces.
  Vector residual(const Vector& q, const Vector& qd, const Vector& qdd, const Vector& lam, const Vector& inputs) const;
  // M by unit accelerations: column j = residual(q, 0, e_j, 0, 0) - residual(q, 0, 0, 0, 0) without gravity.
  Matrix mass(const Vector& q) const;
  Vector nonlinear(const Vector& q, const Vector& qd, const Vector& inputs) const;  // c

  Vector constraints(const Vector& q) const;                         // h
  Matrix constraint_jacobian(const Vector& q) const;                 // J
  Vector constraint_bias(const Vector& q, const Vector& qd) const;   // Jdot qd
  Vector sensors(const Vector& q, const Vector& qd, const Vector& qdd) const;
  Matrix point_jacobian(const Vector& q, PointRef point) const;      // d(position)/dq, 3 x n

  // Direct dynamics with the coordinates split into independent `u`, dependent v and driven:
  // solves h(q) = 0 for v by Newton-Raphson (from the v in q), v_dot from J qd = 0, and the
  // accelerations and multipliers from the augmented system [M -J^T; J 0].
  struct State {
    Vector q, qd, qdd, lam;
  };
  // q, qd hold u, u_dot and a guess of v; driven coordinates are taken from the inputs.
  State direct_dynamics(Vector q, Vector qd, const Vector& inputs, const std::vector<int>& independent) const;

 private:
  V3 point_position(const Kinematics& k, PointRef p) const;
  V3 point_velocity(const Kinematics& k, PointRef p) const;
  V3 point_acceleration(const Kinematics& k, PointRef p) const;
  M3 frame_rotation(const Kinematics& k, int body) const;
  V3 frame_origin(const Kinematics& k, int body) const;
  // A hinge cut's axis_b carried by b's body and the normals of axis_a by a's, ground components.
  struct HingeFrame {
    V3 b;
    std::array<V3, 2> normals;
  };
  HingeFrame hinge_frame(const Kinematics& k, const Cut& c) const;
  // d(omega)/d(qd), 3 x n: of a body, and of a joint frame (-1: the ground, zero)
  Matrix angular_jacobian(const Kinematics& k, int body) const;
  // A cut's equations are written in the components of the nearest joint frame carrying both
  // its bodies (-1: the ground; always the ground for a ball cut keeping some components).
  int cut_frame(const Cut& c) const;
  M3 cut_rotation(const Kinematics& k, const Cut& c) const;
  Matrix frame_angular_jacobian(const Kinematics& k, int frame) const;
  V3 vec(const Vec3Value& v) const { return {value(v[0]), value(v[1]), value(v[2])}; }
  double value(const Value& v) const { return model_.value(v); }
  bool is_ancestor(int joint, int descendant) const;

  Model model_;
};

}  // namespace dydp::mbs
