// The generator behind build_model_lists (newton_euler.hpp): the vectors of its recursive scheme
// and the one class whose members are defined by concept in newton_euler.cpp (the lists),
// newton_euler_kinematics.cpp, _dynamics.cpp (the Newton-Euler passes), _mass.cpp,
// _constraints.cpp and _sensors.cpp. A private header, used only by the newton_euler*.cpp files.
#pragma once

#include <array>
#include <cstddef>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "symbolic/equation_list.hpp"
#include "symbolic/mbs/model.hpp"
#include "symbolic/mbs/newton_euler.hpp"

namespace dydp::mbs::detail {

using symbolic::ArrayId;
using symbolic::Context;
using symbolic::EquationList;
using symbolic::Expr;
using symbolic::NodeId;
using symbolic::Output;
using symbolic::SymbolKind;

struct V3 {
  std::array<Expr, 3> c;
  Expr& operator[](int i) { return c[i]; }
  Expr operator[](int i) const { return c[i]; }
};
inline V3 operator+(const V3& a, const V3& b) { return {{a[0] + b[0], a[1] + b[1], a[2] + b[2]}}; }
inline V3 operator-(const V3& a, const V3& b) { return {{a[0] - b[0], a[1] - b[1], a[2] - b[2]}}; }
inline V3 operator-(const V3& a) { return {{-a[0], -a[1], -a[2]}}; }
inline V3 operator*(Expr s, const V3& a) { return {{s * a[0], s * a[1], s * a[2]}}; }
inline Expr dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline V3 cross(const V3& a, const V3& b) {
  return {{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}};
}

// A rotation matrix by its columns (ground components of the frame's unit vectors).
struct Rot {
  std::array<V3, 3> col;
  V3 apply(const V3& v) const { return v[0] * col[0] + v[1] * col[1] + v[2] * col[2]; }
  V3 apply_transpose(const V3& v) const { return {{dot(col[0], v), dot(col[1], v), dot(col[2], v)}}; }
};

inline EquationList with_outputs(const EquationList& source, std::vector<Output> outputs) {
  EquationList list(source.context());
  for (const auto& a : source.assignments()) list.append(a);
  for (auto& o : outputs) list.add_output(std::move(o));
  return list;
}

// Builds a model's lists (run()). Every part (the kinematics, the Newton-Euler passes, M, the cut
// equations, the sensors) appends its assignments to one recursive scheme, all_, and each list is
// the part of it that its outputs read, eliminated: the order in which the parts assign, and make
// their nodes, decides the generated code.
class Generator {
 public:
  Generator(const Model& model, ModelLists& out);
  void run(MassForm mass_form);

 private:
  // A joint frame's rotation and origin relative to an ancestor frame (relative_placement()).
  struct Placement {
    Rot rot;
    V3 origin;
  };
  // A hinge cut's axes (hinge_axes()).
  struct HingeAxes {
    V3 b;
    std::array<V3, 2> normals;
  };
  // A point's velocity and acceleration (point_motion(), relative_point_motion()).
  struct PointMotion {
    V3 velocity, acceleration;
  };
  // A joint frame's motion relative to an ancestor frame (relative_motion()).
  struct RelativeMotion {
    V3 omega, velocity, alpha, acc;
  };
  // The forward pass of dynamics(): angular velocity, angular acceleration and origin acceleration
  // of every joint frame, own components.
  struct ForwardPass {
    std::vector<V3> omega, alpha, acc;
  };
  // The loads of one pass of dynamics() (external_loads()).
  struct ExternalLoads {
    // External wrenches on each body about its frame origin, body components.
    std::vector<V3> ext_f, ext_n;
    std::map<std::pair<int, int>, V3> point_force;  // by (body, anchor), summed (apply_in())
    std::vector<Expr> joint_force;                  // the joint force elements, by joint
  };
  // A symmetric 3 x 3 matrix (rotational inertia) by its six entries.
  struct Sym {
    Expr xx, yy, zz, xy, xz, yz;
    Expr at(int a, int b) const {
      if (a > b) std::swap(a, b);
      if (a == b) return a == 0 ? xx : a == 1 ? yy : zz;
      return a == 0 ? (b == 1 ? xy : xz) : yz;
    }
    V3 apply(const V3& v) const {
      return {{xx * v[0] + xy * v[1] + xz * v[2], xy * v[0] + yy * v[1] + yz * v[2], xz * v[0] + yz * v[1] + zz * v[2]}};
    }
  };
  // The inertia of a subtree about a joint frame's origin, in its components: mass, first
  // moment h = sum m c, rotational inertia J about the origin.
  struct Composite {
    Expr mass;
    V3 moment;
    Sym inertia;
  };
  // One entry M(row, col) of the composite-inertia mass matrix (mass_matrix()).
  struct MassEntry {
    int row, col;
    Expr value;
  };
  // Entries of the composite-inertia M: one per joint and each of its ancestors. Their code grows
  // like n times the tree's mean depth; past kMassEntriesPerCoordinate per coordinate (a long
  // chain: chain200 has 20 100 entries, 321 k operations) they are written as loops
  // (mass_loops()), whose code is one loop body per joint.
  static constexpr std::size_t kMassEntriesPerCoordinate = 16;

  // The lists (newton_euler.cpp)
  std::unique_ptr<EquationList> merged(std::vector<Output> base_outputs, std::vector<const EquationList*> lists,
                                       std::vector<Output> outputs);

  // Kinematics (newton_euler_kinematics.cpp)
  Expr val(const Value& v);
  V3 vec(const Vec3Value& v) { return {{val(v[0]), val(v[1]), val(v[2])}}; }
  V3 zero3() { return {{ctx_->zero(), ctx_->zero(), ctx_->zero()}}; }
  V3 unit(int axis);
  V3 assign(const std::string& name, int k, const V3& v);
  V3 joint_axis(int k);
  V3 rotate(int k, const V3& v);
  V3 rotate_back(int k, const V3& v);
  V3 joint_offset(int k);
  void positions();
  void velocities();
  Rot body_rotation(int body);
  V3 body_origin(int body);
  V3 anchor(PointRef p) { return vec(m_.bodies[p.body].anchors[p.anchor].position); }
  V3 point_position(PointRef p) { return body_origin(p.body) + body_rotation(p.body).apply(anchor(p)); }
  Rot frame_rotation(int frame) { return frame < 0 ? Rot{{unit(0), unit(1), unit(2)}} : rot_[frame]; }
  // v, given in the components of joint frame `frame` (-1: the ground), in body's frame.
  V3 to_body(int body, int frame, const V3& v) { return change_frame(frame, m_.bodies[body].frame, v); }
  bool carries(int c, int k) const;
  V3 change_frame(int from, int to, const V3& v);
  int common_frame(int fa, int fb) const;
  Placement relative_placement(int k, int c);
  V3 point_in(PointRef p, int c);
  V3 velocity_in(PointRef p, int to);
  V3 acceleration_in(PointRef p, int to);

  // The Newton-Euler passes (newton_euler_dynamics.cpp)
  std::vector<Expr> dynamics(const std::vector<Expr>& qdd, bool full, const std::string& tag, bool cut_forces = true);
  ForwardPass forward_accelerations(const std::vector<Expr>& qdd, bool full, const std::string& tag);
  ExternalLoads external_loads(bool full, bool cut_forces, const std::string& tag);
  void apply_in(ExternalLoads& loads, PointRef p, int frame, const V3& force);
  void apply_link_forces(ExternalLoads& loads);
  void apply_given_loads(ExternalLoads& loads);
  void apply_cut_forces(ExternalLoads& loads);
  void apply_force_elements(ExternalLoads& loads);
  void sum_point_forces(ExternalLoads& loads, const std::string& tag);
  std::vector<Expr> backward_wrenches(const ForwardPass& forward, const ExternalLoads& loads, const std::string& tag);

  // The mass matrix (newton_euler_mass.cpp)
  Sym sym_from(const std::function<Expr(int, int)>& entry);
  Composite to_parent(int k, const Composite& c);
  Composite body_composite(int k);
  std::size_t mass_entry_count() const;
  std::vector<Composite> composites();
  std::pair<V3, V3> unit_wrench(int i, const Composite& c);
  Expr mass_entry(int k, const V3& F, const V3& N);
  std::vector<MassEntry> mass_matrix();
  std::unique_ptr<MassLoops> mass_loops();

  // The cut joints' equations and their derivatives (newton_euler_constraints.cpp)
  int cut_frame(const Cut& c) const;
  V3 cut_vector(std::size_t i);
  HingeAxes hinge_axes(const Cut& c);
  std::vector<Expr> constraint_values();
  std::vector<int> path_to(int frame, int c) const;
  V3 point_rate(PointRef p, int c, int j);
  std::map<int, V3> cut_vector_rates(const Cut& c);
  std::vector<std::vector<Expr>> constraint_jacobian();
  PointMotion point_motion(PointRef p, int c);
  RelativeMotion relative_motion(int k, int c, bool with_qdd = true);
  PointMotion relative_point_motion(PointRef p, int c, bool with_qdd = true);
  std::vector<Expr> constraint_bias();
  void relative_cut_rows(std::size_t ci, bool with_qdd, const std::string& prefix, int& row, std::vector<Expr>& rows);
  std::vector<Expr> cut_accelerations();

  // The sensors (newton_euler_sensors.cpp)
  std::vector<Expr> sensor_values();

  const Model& m_;
  ModelLists& out_;
  Context* ctx_ = nullptr;
  std::unique_ptr<EquationList> all_;
  std::vector<int> param_index_;
  std::vector<Expr> cos_, sin_;
  std::vector<std::array<std::array<Expr, 3>, 3>> relative_rotation_;  // R of joints about arbitrary axes
  std::map<std::pair<int, int>, Placement> relative_;  // frame k relative to its ancestor c
  std::map<std::tuple<int, int, bool>, RelativeMotion> relative_motion_;
  std::vector<V3> cut_vectors_;
  std::vector<Rot> rot_;
  std::vector<V3> origin_, offset_, omega_, velocity_, full_alpha_, full_acc_;
};

}  // namespace dydp::mbs::detail
