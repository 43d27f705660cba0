// Symbolic recursive Newton-Euler. Kinematics forward from the ground, in the components of each
// joint frame: omega_k = R_k^T omega_p + qd_k e (revolute), accelerations likewise with the
// ground accelerating at -g so that gravity enters as an inertial force; then the wrenches
// backward: f_k = m a_G - F_ext + sum R_c f_c, n_k = I omegadot + omega x I omega + c x m a_G -
// N_ext + sum (R_c n_c + r_c x R_c f_c), joint force Q_k = e . n_k (revolute) or e . f_k.
#include "symbolic/mbs/newton_euler.hpp"

#include <algorithm>
#include <array>
#include <functional>
#include <map>
#include <tuple>

#include "symbolic/compact.hpp"
#include "symbolic/differentiate.hpp"
#include "symbolic/eliminate.hpp"

namespace dydp::mbs {
namespace {

using symbolic::ArrayId;
using symbolic::Context;
using symbolic::Direction;
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
V3 operator+(const V3& a, const V3& b) { return {{a[0] + b[0], a[1] + b[1], a[2] + b[2]}}; }
V3 operator-(const V3& a, const V3& b) { return {{a[0] - b[0], a[1] - b[1], a[2] - b[2]}}; }
V3 operator-(const V3& a) { return {{-a[0], -a[1], -a[2]}}; }
V3 operator*(Expr s, const V3& a) { return {{s * a[0], s * a[1], s * a[2]}}; }
Expr dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V3 cross(const V3& a, const V3& b) {
  return {{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]}};
}

// A rotation matrix by its columns (ground components of the frame's unit vectors).
struct Rot {
  std::array<V3, 3> col;
  V3 apply(const V3& v) const { return v[0] * col[0] + v[1] * col[1] + v[2] * col[2]; }
  V3 apply_transpose(const V3& v) const { return {{dot(col[0], v), dot(col[1], v), dot(col[2], v)}}; }
};

EquationList with_outputs(const EquationList& source, std::vector<Output> outputs) {
  EquationList list(source.context());
  for (const auto& a : source.assignments()) list.append(a);
  for (auto& o : outputs) list.add_output(std::move(o));
  return list;
}

class Generator {
 public:
  Generator(const Model& model, ModelLists& out) : m_(model), out_(out) {
    out_.context = std::make_unique<Context>();
    Context& ctx = *out_.context;
    ctx_ = &ctx;
    const std::size_t n = model.coordinates();
    std::vector<std::string> names;
    for (const Joint& j : model.joints) names.push_back(j.name);
    out_.q = ctx.add_array("q", n, SymbolKind::Input);
    out_.qd = ctx.add_array("qd", n, SymbolKind::Input);
    out_.qdd = ctx.add_array("qdd", n, SymbolKind::Input);
    out_.lam = ctx.add_array("lam", std::max(1, model.constraint_count()), SymbolKind::Input);
    out_.inp = ctx.add_array("inp", std::max(1, model.input_count()), SymbolKind::Input);
    out_.p = ctx.add_array("p", std::max(1, model.symbolic_parameter_count()), SymbolKind::Parameter);
    int k = 0;
    for (const Parameter& par : model.parameters) param_index_.push_back(par.symbolic ? k++ : -1);
    all_ = std::make_unique<EquationList>(ctx);
  }

  void run(MassForm mass_form) {
    positions();
    velocities();
    std::vector<Expr> qdd, zero(m_.coordinates(), ctx_->zero());
    for (int j = 0; j < m_.coordinates(); ++j) qdd.push_back(ctx_->element(out_.qdd, j));

    // The inertial pass: M qdd.
    const std::vector<Expr> inertial = dynamics(qdd, /*full=*/false, "I");
    // The full pass: M qdd + c - J^T lam; and without the cut forces, M qdd + c.
    const std::vector<Expr> residual = dynamics(qdd, /*full=*/true, "");
    const std::vector<Expr> applied = dynamics(qdd, /*full=*/true, "V", /*cut_forces=*/false);
    const std::vector<Expr> h = constraint_values();
    const std::vector<Expr> sensors = sensor_values();

    const int n = m_.coordinates();
    const int mc = m_.constraint_count();
    auto outputs = [](const std::string& prefix, const std::vector<Expr>& values) {
      std::vector<Output> o;
      for (std::size_t i = 0; i < values.size(); ++i) o.push_back({prefix + "[" + std::to_string(i) + "]", values[i].id()});
      return o;
    };
    out_.inertial = std::make_unique<EquationList>(symbolic::eliminate(with_outputs(*all_, outputs("Mqdd", inertial))));
    const bool shallow = mass_entry_count() <= kMassEntriesPerCoordinate * static_cast<std::size_t>(m_.coordinates());
    if (mass_form == MassForm::Entries || (mass_form == MassForm::Automatic && shallow)) {
      std::vector<Output> o;
      for (const MassEntry& e : mass_matrix())
        o.push_back({"M[" + std::to_string(e.row) + "," + std::to_string(e.col) + "]", e.value.id()});
      out_.mass_matrix = merged(o, {}, o);
    } else {
      out_.mass_loops = mass_loops();
    }

    // The constraint kinematics: h and J from the relative kinematics of the cut points (a joint
    // turns a point by e x r: constraint_jacobian()), J qd from them. The residual's constraint
    // accelerations J qdd + Jdot qd are the cut points' relative accelerations from the full
    // pass's forward kinematics (cut_accelerations()); Jdot qd is the same at qdd = 0.
    const std::vector<std::vector<Expr>> J = constraint_jacobian();
    std::vector<Expr> jqd;
    for (int i = 0; i < mc; ++i) {
      std::vector<Expr> terms;
      for (int j = 0; j < n; ++j)
        if (!J[i][j].is_zero()) terms.push_back(J[i][j] * ctx_->element(out_.qd, j));
      jqd.push_back(all_->assign("HD" + std::to_string(i + 1), ctx_->sum(terms)));
    }
    out_.assignments_built = all_->size();
    {
      const std::vector<Output> accelerations = outputs("a", cut_accelerations());
      std::vector<Output> o = outputs("r", residual), v = outputs("r", applied);
      for (const Output& a : accelerations) {
        o.push_back(a);
        v.push_back(a);
      }
      out_.residual = merged(o, {}, o);
      out_.applied = merged(v, {}, v);
    }
    {
      std::vector<Output> o = outputs("h", h);
      for (int i = 0; i < mc; ++i)
        for (int j = 0; j < n; ++j) o.push_back({"J[" + std::to_string(i) + "," + std::to_string(j) + "]", J[i][j].id()});
      out_.constraints = merged(o, {}, o);
    }
    {
      std::vector<Output> o = outputs("h", h);
      for (const Output& a : outputs("hdot", jqd)) o.push_back(a);
      out_.velocity_constraints = merged(o, {}, o);
    }
    if (const std::vector<Expr> bias = constraint_bias(); mc > 0 && !bias.empty()) {
      std::vector<Output> o = outputs("h", h);
      for (int i = 0; i < mc; ++i)
        for (int j = 0; j < n; ++j) o.push_back({"J[" + std::to_string(i) + "," + std::to_string(j) + "]", J[i][j].id()});
      for (const Output& a : outputs("Jdot_qd", bias)) o.push_back(a);
      out_.constraint_kinematics = merged(o, {}, o);
    }
    out_.position_constraints = merged(outputs("h", h), {}, outputs("h", h));
    out_.sensors = std::make_unique<EquationList>(symbolic::eliminate(with_outputs(*all_, outputs("s", sensors))));

    std::vector<Direction> along_q;
    for (int j = 0; j < n; ++j) along_q.push_back(symbolic::along(ctx_->element(out_.q, j)));
    for (const JacobianRequest& request : m_.jacobians) {
      const V3 x = point_position(request.point);
      std::vector<Expr> xs{x[0], x[1], x[2]};
      const EquationList x_list = symbolic::eliminate(with_outputs(*all_, outputs("x", xs)));
      const EquationList dx = symbolic::differentiate(x_list, along_q);
      std::vector<Output> o;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < n; ++j)
          o.push_back({"J[" + std::to_string(i) + "," + std::to_string(j) + "]", dx.outputs()[3 + 3 * j + i].value});
      EquationList list(*ctx_);
      for (const auto& a : dx.assignments()) list.append(a);
      for (auto& output : o) list.add_output(std::move(output));
      out_.jacobians.push_back({request.name, std::make_unique<EquationList>(symbolic::eliminate(list))});
    }
  }

 private:
  // One list from the recursive scheme (the part `base_outputs` needs) followed by every
  // assignment of the given lists not already in it (their primal parts are compactions of the
  // scheme, their derivative parts new), eliminated. An assignment reads only earlier ones of
  // its own list, which are placed before it.
  std::unique_ptr<EquationList> merged(std::vector<Output> base_outputs, std::vector<const EquationList*> lists,
                                       std::vector<Output> outputs) {
    const EquationList base = symbolic::eliminate(with_outputs(*all_, std::move(base_outputs)));
    EquationList list(*ctx_);
    std::vector<bool> seen(ctx_->size(), false);
    for (const auto& a : base.assignments()) {
      list.append(a);
      seen[a.target] = true;
    }
    for (const EquationList* l : lists) {
      for (const auto& a : l->assignments()) {
        if (a.target >= seen.size()) seen.resize(ctx_->size(), false);
        if (seen[a.target]) continue;
        seen[a.target] = true;
        list.append(a);
      }
    }
    for (auto& o : outputs) list.add_output(std::move(o));
    return std::make_unique<EquationList>(symbolic::eliminate(list));
  }

  Expr val(const Value& v) {
    if (v.param >= 0 && param_index_[v.param] >= 0) return v.scale * ctx_->element(out_.p, param_index_[v.param]);
    return ctx_->constant(m_.value(v));
  }
  V3 vec(const Vec3Value& v) { return {{val(v[0]), val(v[1]), val(v[2])}}; }
  V3 zero3() { return {{ctx_->zero(), ctx_->zero(), ctx_->zero()}}; }
  V3 unit(int axis) {
    V3 e = zero3();
    e[axis] = ctx_->one();
    return e;
  }
  V3 assign(const std::string& name, int k, const V3& v) {
    V3 r;
    for (int i = 0; i < 3; ++i) r[i] = all_->assign(name + std::to_string(i + 1) + "_" + std::to_string(k + 1), v[i]);
    return r;
  }

  // The joint's axis (constants), own and parent components alike.
  V3 joint_axis(int k) {
    const Joint& j = m_.joints[k];
    return {{ctx_->constant(j.axis[0]), ctx_->constant(j.axis[1]), ctx_->constant(j.axis[2])}};
  }

  // Relative rotation of joint k (its frame to its parent's): v_parent = R v_k.
  V3 rotate(int k, const V3& v) {
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
  V3 rotate_back(int k, const V3& v) {
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
  V3 joint_offset(int k) {
    const Joint& j = m_.joints[k];
    V3 r = vec(j.offset);
    if (!is_revolute(j.type)) r = r + ctx_->element(out_.q, k) * joint_axis(k);
    return r;
  }

  // Absolute rotations and origins.
  void positions() {
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
  void velocities() {
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

  Rot body_rotation(int body) {
    const int f = m_.bodies[body].frame;
    return f < 0 ? Rot{{unit(0), unit(1), unit(2)}} : rot_[f];
  }
  V3 body_origin(int body) {
    const int f = m_.bodies[body].frame;
    return f < 0 ? zero3() : origin_[f];
  }
  V3 anchor(PointRef p) { return vec(m_.bodies[p.body].anchors[p.anchor].position); }
  V3 point_position(PointRef p) { return body_origin(p.body) + body_rotation(p.body).apply(anchor(p)); }

  // The Newton-Euler passes. `full`: gravity, velocities, loads, force elements and cut forces;
  // otherwise the inertial pass (M qdd). Returns the joint forces.
  // `cut_forces` false: without the cut forces J^T lam (the inverse dynamics proper, which the
  // coordinate partitioning needs; the multipliers enter only its tangent). A second full pass
  // reuses the first one's forward kinematics.
  std::vector<Expr> dynamics(const std::vector<Expr>& qdd, bool full, const std::string& tag, bool cut_forces = true) {
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

    // External wrenches on each body about its frame origin, body components.
    std::vector<V3> ext_f(m_.bodies.size(), zero3()), ext_n(m_.bodies.size(), zero3());
    // A force given in the components of joint frame `frame`, at a point: turned into the
    // point's body frame by the relative rotation when `frame` is an ancestor (for a spring
    // between chassis and wishbone, one joint's rotation) instead of through the ground.
    // Forces are summed per point of application (the tyre's three components at its contact
    // point, the cut forces at a ball joint) and their moment taken once, after every load.
    std::map<std::pair<int, int>, V3> point_force;
    auto apply_in = [&](PointRef p, int frame, const V3& force) {
      if (p.body == 0) return;
      const V3 f = to_body(p.body, frame, force);
      const auto key = std::make_pair(p.body, p.anchor);
      const auto it = point_force.find(key);
      point_force[key] = it == point_force.end() ? f : it->second + f;
    };
    std::vector<Expr> joint_force(n, ctx_->zero());
    if (full) {
      // Link forces between the same two points (a spring and a damper on one strut) act along
      // the same line: their magnitudes are summed and the line's force applied once.
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
        apply_in(g.b, c, f);
        apply_in(g.a, c, -f);
      }
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
          apply_in(l.point, frame, given);
        } else {
          if (l.point.body != 0) ext_n[l.point.body] = ext_n[l.point.body] + to_body(l.point.body, frame, given);
          if (l.reaction > 0) ext_n[l.reaction] = ext_n[l.reaction] - to_body(l.reaction, frame, given);
        }
      }
      int row = 0;
      for (std::size_t ci = 0; ci < m_.cuts.size() && cut_forces; ++ci) {
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
          if (c.b.body != 0) ext_n[c.b.body] = ext_n[c.b.body] + body_rotation(c.b.body).apply_transpose(torque);
          if (c.a.body != 0) ext_n[c.a.body] = ext_n[c.a.body] - body_rotation(c.a.body).apply_transpose(torque);
        } else {
          // h = (d.d - L^2) / 2L: J^T lam is the force (lam / L) d on b
          f = (ctx_->element(out_.lam, row++) / val(c.length)) * cut_vector(ci);
        }
        apply_in(c.b, frame, f);
        apply_in(c.a, frame, -f);
      }
      int spring = 0;
      for (const ForceElement& e : m_.forces) {
        if (e.type == ForceElement::Type::JointForce) {
          joint_force[e.joint] = joint_force[e.joint] + val(e.value);
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
        apply_in(e.a, c, f);
        apply_in(e.b, c, -f);
      }
    }
    for (const auto& [key, f] : point_force) {
      const V3 sum = assign("FP" + tag + std::to_string(key.first) + "_", key.second, f);
      ext_f[key.first] = ext_f[key.first] + sum;
      ext_n[key.first] = ext_n[key.first] + cross(anchor(PointRef{key.first, key.second}), sum);
    }

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
        const V3 w = omega[k], al = alpha[k];
        const V3 acc_g = acc[k] + cross(al, com) + cross(w, cross(w, com));
        const V3 inertial = mass * acc_g;
        const Expr ixx = val(b.inertia[0]), iyy = val(b.inertia[1]), izz = val(b.inertia[2]);
        const Expr ixy = val(b.inertia[3]), ixz = val(b.inertia[4]), iyz = val(b.inertia[5]);
        auto I = [&](const V3& v) {
          return V3{{ixx * v[0] + ixy * v[1] + ixz * v[2], ixy * v[0] + iyy * v[1] + iyz * v[2],
                     ixz * v[0] + iyz * v[1] + izz * v[2]}};
        };
        f = f + inertial - ext_f[j.body];
        t = t + I(al) + cross(w, I(w)) + cross(com, inertial) - ext_n[j.body];
      }
      f = assign("F" + tag, k, f);
      t = assign("N" + tag, k, t);
      const V3 e = joint_axis(k);
      q_force[k] = all_->assign("Q" + tag + std::to_string(k + 1), (is_revolute(j.type) ? dot(e, t) : dot(e, f)) - joint_force[k]);
      if (j.parent >= 0) {
        const V3 fp = rotate(k, f);
        child_f[j.parent] = child_f[j.parent] + fp;
        child_n[j.parent] = child_n[j.parent] + rotate(k, t) + cross(offset_[k], fp);
      }
    }
    return q_force;
  }

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
  Sym sym_from(const std::function<Expr(int, int)>& entry) {
    return {entry(0, 0), entry(1, 1), entry(2, 2), entry(0, 1), entry(0, 2), entry(1, 2)};
  }
  // Composite k moved into its parent's frame: rotation R (rotate(k, .)), origin r there:
  // h' = R h + m r, J' = R J R^T - (h' r^T + r h'^T) + (2 r.h' + m |r|^2) E - m r r^T, with
  // R h the moment about O_k and h' about the parent's origin (of R h + m r, the R h part).
  Composite to_parent(int k, const Composite& c) {
    const V3 r = offset_[k];
    const V3 h = rotate(k, c.moment);  // about O_k, parent components
    std::array<V3, 3> columns;          // R J R^T by columns: R (J (R^T e_c))
    for (int col = 0; col < 3; ++col) columns[col] = rotate(k, c.inertia.apply(rotate_back(k, unit(col))));
    const Expr rh = dot(r, h), rr = dot(r, r);
    const Expr diagonal = ctx_->constant(2.0) * rh + c.mass * rr;
    const Sym J = sym_from([&](int a, int b) {
      Expr e = columns[b][a] - (h[a] * r[b] + r[a] * h[b]) - c.mass * (r[a] * r[b]);
      return a == b ? e + diagonal : e;
    });
    return {c.mass, h + c.mass * r, J};
  }
  Composite body_composite(int k) {
    const Joint& j = m_.joints[k];
    if (j.body < 0) return {ctx_->zero(), zero3(), {ctx_->zero(), ctx_->zero(), ctx_->zero(), ctx_->zero(), ctx_->zero(), ctx_->zero()}};
    const Body& b = m_.bodies[j.body];
    const Expr mass = val(b.mass);
    const V3 c = vec(b.com);
    const Sym I{val(b.inertia[0]), val(b.inertia[1]), val(b.inertia[2]), val(b.inertia[3]), val(b.inertia[4]), val(b.inertia[5])};
    const Expr cc = dot(c, c);
    // about the frame origin: I_G + m (|c|^2 E - c c^T)
    const Sym J = sym_from([&](int a, int e) {
      Expr v = I.at(a, e) - mass * (c[a] * c[e]);
      return a == e ? v + mass * cc : v;
    });
    return {mass, mass * c, J};
  }

  // The mass matrix by composite inertias: the subtrees' inertias backward, then for each joint
  // i the force and torque its unit acceleration needs on its subtree (revolute axis e:
  // F = e x h, N = J e; prismatic: F = m e, N = h x e), carried to every ancestor k, where
  // M(i, k) is k's axis against them. Entries of two joints neither of which carries the other
  // are zero and not computed (two suspension corners). One entry (i, k) per joint i and k = i
  // or an ancestor of i: M(i, k) = M(k, i).
  struct MassEntry {
    int row, col;
    Expr value;
  };
  // Entries of the composite-inertia M: one per joint and each of its ancestors. Their code grows
  // like n times the tree's mean depth; past kMassEntriesPerCoordinate per coordinate (a long
  // chain: chain200 has 20 100 entries, 321 k operations) they are written as loops
  // (mass_loops()), whose code is one loop body per joint.
  static constexpr std::size_t kMassEntriesPerCoordinate = 16;
  std::size_t mass_entry_count() const {
    std::size_t count = 0;
    for (int i = 0; i < m_.coordinates(); ++i)
      for (int k = i; k >= 0; k = m_.joints[k].parent) ++count;
    return count;
  }
  // The composite inertia of every joint's subtree about its origin, in its components.
  std::vector<Composite> composites() {
    const int n = m_.coordinates();
    std::vector<Composite> composite(n);
    for (const int k : m_.order) composite[k] = body_composite(k);
    for (auto it = m_.order.rbegin(); it != m_.order.rend(); ++it) {
      const int k = *it;
      Composite& c = composite[k];
      const std::string tag = "CM" + std::to_string(k + 1);
      c.mass = all_->assign(tag + "_m", c.mass);
      c.moment = assign(tag + "_h", 0, c.moment);
      c.inertia = sym_from([&](int a, int b) {
        return all_->assign(tag + "_J" + std::to_string(a + 1) + std::to_string(b + 1), c.inertia.at(a, b));
      });
      const int parent = m_.joints[k].parent;
      if (parent < 0) continue;
      const Composite moved = to_parent(k, c);
      Composite& p = composite[parent];
      p.mass = p.mass + moved.mass;
      p.moment = p.moment + moved.moment;
      p.inertia = sym_from([&](int a, int b) { return p.inertia.at(a, b) + moved.inertia.at(a, b); });
    }
    return composite;
  }
  // The force and torque (about its origin, its components) joint i's unit acceleration needs
  // on its subtree: revolute axis e: F = e x h, N = J e; prismatic: F = m e, N = h x e.
  std::pair<V3, V3> unit_wrench(int i, const Composite& c) {
    const V3 e = joint_axis(i);
    if (is_revolute(m_.joints[i].type)) return {cross(e, c.moment), c.inertia.apply(e)};
    return {c.mass * e, cross(c.moment, e)};
  }
  // M(i, k) from joint i's wrench in joint k's frame: k's axis against N (revolute) or F.
  Expr mass_entry(int k, const V3& F, const V3& N) {
    const V3 axis = joint_axis(k);
    return is_revolute(m_.joints[k].type) ? dot(axis, N) : dot(axis, F);
  }
  std::vector<MassEntry> mass_matrix() {
    const int n = m_.coordinates();
    const std::vector<Composite> composite = composites();
    std::vector<MassEntry> entries;
    for (int i = 0; i < n; ++i) {
      const std::pair<V3, V3> wrench = unit_wrench(i, composite[i]);
      V3 F = wrench.first, N = wrench.second;
      auto entry = [&](int k) {
        entries.push_back({i, k, all_->assign("MM" + std::to_string(i + 1) + "_" + std::to_string(k + 1), mass_entry(k, F, N))});
      };
      entry(i);
      for (int k = i; m_.joints[k].parent >= 0; k = m_.joints[k].parent) {
        F = rotate(k, F);
        N = rotate(k, N) + cross(offset_[k], F);
        const std::string tag = std::to_string(i + 1) + "_" + std::to_string(k + 1);
        F = assign("MF" + tag + "_", 0, F);
        N = assign("MN" + tag + "_", 0, N);
        entry(m_.joints[k].parent);
      }
    }
    return entries;
  }

  // The same recursion with its sweeps as loops (MassLoops): the lanes in depth-first order,
  // then for each joint k below a root, deepest first, the lanes of k's subtree (all in k's
  // frame by then) carried to its parent's frame, F' = R F, N' = R N + r x F', and
  // M(i, parent) read off them. The sweeps' expressions are in placeholders, so that their code
  // is one loop body per joint whatever the number of lanes it carries.
  std::unique_ptr<MassLoops> mass_loops() {
    const int n = m_.coordinates();
    auto loops = std::make_unique<MassLoops>();
    std::vector<std::vector<int>> children(n);
    std::vector<int> roots;
    for (int k = 0; k < n; ++k) (m_.joints[k].parent < 0 ? roots : children[m_.joints[k].parent]).push_back(k);
    std::vector<int> position(n), size(n, 1);
    std::vector<int> stack(roots.rbegin(), roots.rend());
    while (!stack.empty()) {
      const int k = stack.back();
      stack.pop_back();
      position[k] = static_cast<int>(loops->lane_joint.size());
      loops->lane_joint.push_back(k);
      for (auto c = children[k].rbegin(); c != children[k].rend(); ++c) stack.push_back(*c);
    }
    for (auto t = loops->lane_joint.rbegin(); t != loops->lane_joint.rend(); ++t)
      if (m_.joints[*t].parent >= 0) size[m_.joints[*t].parent] += size[*t];

    const std::vector<Composite> composite = composites();
    std::vector<Output> o(7 * static_cast<std::size_t>(n));
    for (int t = 0; t < n; ++t) {
      const int i = loops->lane_joint[t];
      const std::pair<V3, V3> wrench = unit_wrench(i, composite[i]);
      const V3& F = wrench.first;
      const V3& N = wrench.second;
      const std::string tag = std::to_string(i + 1);
      for (int a = 0; a < 3; ++a) {
        o[a * n + t] = {"F" + std::to_string(a + 1) + "[" + tag + "]", F[a].id()};
        o[(a + 3) * n + t] = {"N" + std::to_string(a + 1) + "[" + tag + "]", N[a].id()};
      }
      o[6 * n + t] = {"M[" + std::to_string(i) + "," + std::to_string(i) + "]", mass_entry(i, F, N).id()};
    }
    V3 F, N, Fm, Nm;
    for (int a = 0; a < 3; ++a) {
      F[a] = ctx_->aux("mf" + std::to_string(a + 1));
      N[a] = ctx_->aux("mn" + std::to_string(a + 1));
      Fm[a] = ctx_->aux("mg" + std::to_string(a + 1));
      Nm[a] = ctx_->aux("mh" + std::to_string(a + 1));
      loops->lane[a] = F[a].id();
      loops->lane[a + 3] = N[a].id();
      loops->moved_lane[a] = Fm[a].id();
      loops->moved_lane[a + 3] = Nm[a].id();
    }
    for (auto t = loops->lane_joint.rbegin(); t != loops->lane_joint.rend(); ++t) {
      const int k = *t, parent = m_.joints[k].parent;
      if (parent < 0) continue;
      MassLoops::Sweep sweep{k, parent, position[k], position[k] + size[k]};
      const V3 f = rotate(k, F), moment = rotate(k, N) + cross(offset_[k], Fm);
      for (int a = 0; a < 3; ++a) {
        sweep.moved[a] = f[a].id();
        sweep.moved[a + 3] = moment[a].id();
      }
      sweep.entry = mass_entry(parent, Fm, Nm).id();
      loops->sweeps.push_back(sweep);
    }

    // What the sweeps read besides the placeholders and the function's arrays: auxiliaries
    // (an arbitrary axis's rotation, an offset along a prismatic joint) and sin/cos.
    std::vector<char> placeholder(ctx_->size(), 0), seen(ctx_->size(), 0);
    for (int a = 0; a < 6; ++a) placeholder[loops->lane[a]] = placeholder[loops->moved_lane[a]] = 1;
    std::vector<NodeId> pending;
    for (const MassLoops::Sweep& sweep : loops->sweeps) {
      pending.insert(pending.end(), sweep.moved.begin(), sweep.moved.end());
      pending.push_back(sweep.entry);
    }
    while (!pending.empty()) {
      const NodeId x = pending.back();
      pending.pop_back();
      if (seen[x]) continue;
      seen[x] = 1;
      if (placeholder[x]) continue;
      if (ctx_->is_abbreviation(x) || ctx_->is_symbol(x, SymbolKind::Aux)) {
        loops->reads.push_back(x);
        o.push_back({"read " + std::to_string(loops->reads.size() - 1), x});
        continue;
      }
      const auto c = ctx_->children(x);
      pending.insert(pending.end(), c.begin(), c.end());
    }
    loops->start = std::make_unique<EquationList>(symbolic::eliminate(with_outputs(*all_, std::move(o))));
    return loops;
  }

  // Every cut's equations are written in the frame of the nearest joint frame that carries both
  // of its bodies (for a suspension corner, the chassis), so that they do not depend on the
  // coordinates above it: J has zero columns there and each loop's rows read its own
  // coordinates only. A ball cut that keeps a subset of components stays in ground components.
  std::vector<Expr> constraint_values() {
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

  // Joints between a point's frame and the ancestor frame c (c excluded), from the point up.
  std::vector<int> path_to(int frame, int c) const {
    std::vector<int> path;
    for (int k = frame; k != c && k >= 0; k = m_.joints[k].parent) path.push_back(k);
    return path;
  }
  // d(P in c's components)/dq_j for joint j on P's path to c: e_j x (P - o_j) for a revolute
  // joint (e_j its axis, o_j its origin, in c's components), e_j for a prismatic one.
  V3 point_rate(PointRef p, int c, int j) {
    const Joint& joint = m_.joints[j];
    const Placement parent = relative_placement(joint.parent, c);
    const V3 e = parent.rot.apply(joint_axis(j));
    if (!is_revolute(joint.type)) return e;
    return cross(e, point_in(p, c) - relative_placement(j, c).origin);
  }
  // dd/dq_j of a cut's vector d = b - a (cut frame components), by joint.
  std::map<int, V3> cut_vector_rates(const Cut& c) {
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
  std::vector<std::vector<Expr>> constraint_jacobian() {
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

  // v, given in the components of joint frame `frame` (-1: the ground), in body's frame.
  V3 to_body(int body, int frame, const V3& v) { return change_frame(frame, m_.bodies[body].frame, v); }

  // Whether joint frame c (-1: the ground) is k or one of its ancestors.
  bool carries(int c, int k) const {
    if (c < 0) return true;
    for (; k >= 0; k = m_.joints[k].parent)
      if (k == c) return true;
    return false;
  }
  // v, given in the components of joint frame `from`, in those of `to` (-1: the ground): by the
  // rotation relative to the nearer one when one carries the other (a corner body and the
  // chassis: the corner's own joints), through the ground otherwise.
  V3 change_frame(int from, int to, const V3& v) {
    if (from == to) return v;
    if (carries(to, from)) return relative_placement(from, to).rot.apply(v);
    if (carries(from, to)) return relative_placement(to, from).rot.apply_transpose(v);
    return frame_rotation(to).apply_transpose(frame_rotation(from).apply(v));
  }

  // The nearest common ancestor of two joint frames (-1: the ground).
  int common_frame(int fa, int fb) const {
    std::vector<char> above(m_.coordinates(), 0);
    for (int k = fa; k >= 0; k = m_.joints[k].parent) above[k] = 1;
    int k = fb;
    while (k >= 0 && !above[k]) k = m_.joints[k].parent;
    return k;
  }
  int cut_frame(const Cut& c) const {
    if (c.type == Cut::Type::Ball && c.components.size() < 3) return -1;
    return common_frame(m_.bodies[c.a.body].frame, m_.bodies[c.b.body].frame);
  }
  Rot frame_rotation(int frame) { return frame < 0 ? Rot{{unit(0), unit(1), unit(2)}} : rot_[frame]; }

  // Rotation and origin of joint frame k relative to its ancestor frame c, in c's components,
  // by the same recursion as the absolute ones (positions()), started at c.
  struct Placement {
    Rot rot;
    V3 origin;
  };
  Placement relative_placement(int k, int c) {
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
  V3 point_in(PointRef p, int c) {
    const int f = m_.bodies[p.body].frame;
    if (c < 0) return point_position(p);
    const Placement placement = relative_placement(f, c);
    return placement.origin + placement.rot.apply(anchor(p));
  }
  // b - a of cut i in the cut's frame (assigned once).
  V3 cut_vector(std::size_t i) {
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
  struct HingeAxes {
    V3 b;
    std::array<V3, 2> normals;
  };
  HingeAxes hinge_axes(const Cut& c) {
    auto constant = [&](const std::array<double, 3>& v) {
      return V3{{ctx_->constant(v[0]), ctx_->constant(v[1]), ctx_->constant(v[2])}};
    };
    const Rot ra = body_rotation(c.a.body), rb = body_rotation(c.b.body);
    return {rb.apply(constant(c.axis_b)), {ra.apply(constant(c.normals_a[0])), ra.apply(constant(c.normals_a[1]))}};
  }

  // Velocity and acceleration (the scheme's, ground at -g) of a point, in the components of the
  // frame c its body's frame descends from (-1: the ground), from the full pass.
  struct PointMotion {
    V3 velocity, acceleration;
  };
  PointMotion point_motion(PointRef p, int c) {
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
  struct RelativeMotion {
    V3 omega, velocity, alpha, acc;
  };
  // `with_qdd` false: at qdd = 0 (the velocity-product terms, Jdot qd).
  RelativeMotion relative_motion(int k, int c, bool with_qdd = true) {
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
  PointMotion relative_point_motion(PointRef p, int c, bool with_qdd = true) {
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
  std::vector<Expr> constraint_bias() {
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
  void relative_cut_rows(std::size_t ci, bool with_qdd, const std::string& prefix, int& row, std::vector<Expr>& rows) {
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
  std::vector<Expr> cut_accelerations() {
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

  // A point's absolute velocity and acceleration (the true one, gravity removed) in the
  // components of joint frame `to`, from its body frame's own components.
  V3 velocity_in(PointRef p, int to) {
    const int f = m_.bodies[p.body].frame;
    if (f < 0) return zero3();
    return change_frame(f, to, velocity_[f] + cross(omega_[f], anchor(p)));
  }
  V3 acceleration_in(PointRef p, int to) {
    const int f = m_.bodies[p.body].frame;
    const V3 g{{ctx_->constant(m_.gravity[0]), ctx_->constant(m_.gravity[1]), ctx_->constant(m_.gravity[2])}};
    const V3 gravity = change_frame(-1, to, g);
    if (f < 0) return zero3();
    const V3 r = anchor(p);
    return change_frame(f, to, full_acc_[f] + cross(full_alpha_[f], r) + cross(omega_[f], cross(omega_[f], r))) + gravity;
  }

  // Sensors in the components of their frame, each through the rotation relative to the frame
  // when that frame carries the point (the chassis frame and a wheel centre: the corner's joints
  // only); lengths in the frame of the two bodies' common ancestor, like the link forces.
  std::vector<Expr> sensor_values() {
    std::vector<Expr> values;
    int index = 0;
    for (const Sensor& s : m_.sensors) {
      ++index;
      const std::string name = "SENS" + std::to_string(index) + "_";
      V3 v;
      const int frame = m_.bodies[s.frame].frame;
      switch (s.type) {
        case Sensor::Type::AngularVelocity: {
          const int f = m_.bodies[s.a.body].frame;
          v = f < 0 ? zero3() : change_frame(f, frame, omega_[f]);
          break;
        }
        case Sensor::Type::Position:
          if (carries(frame, m_.bodies[s.a.body].frame)) v = point_in(s.a, frame);
          else v = body_rotation(s.frame).apply_transpose(point_position(s.a) - body_origin(s.frame));
          break;
        case Sensor::Type::Velocity: v = velocity_in(s.a, frame); break;
        case Sensor::Type::Acceleration: v = acceleration_in(s.a, frame); break;
        case Sensor::Type::Joint:
          v = V3{{ctx_->element(out_.q, s.joint), ctx_->element(out_.qd, s.joint), ctx_->element(out_.qdd, s.joint)}};
          break;
        case Sensor::Type::Length: {
          const int c = common_frame(m_.bodies[s.a.body].frame, m_.bodies[s.b.body].frame);
          const V3 d = assign(name + "D", 0, point_in(s.b, c) - point_in(s.a, c));
          const Expr length = all_->assign(name + "L", symbolic::sqrt(dot(d, d)));
          const Expr rate = dot(d, velocity_in(s.b, c) - velocity_in(s.a, c)) / length;
          const Expr extension = length - val(s.reference);
          v = V3{{s.compression ? -extension : extension, s.compression ? -rate : rate, ctx_->zero()}};
          break;
        }
      }
      v = assign(name, 0, v);
      for (int c : s.components) values.push_back(v[c]);
    }
    return values;
  }

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

}  // namespace

ModelLists build_model_lists(const Model& model, MassForm mass_form) {
  ModelLists lists;
  Generator(model, lists).run(mass_form);
  return lists;
}

std::vector<symbolic::ArrayId> tangent_arrays(const ModelLists& lists) {
  return {lists.q, lists.qd, lists.qdd, lists.inp, lists.p};
}

}  // namespace dydp::mbs
