// multibody: a generated multibody model (generated_models/) as a block. States: the independent
// coordinates u and velocities u_dot; dependent coordinates are solved by Newton-Raphson on the
// generated constraints at every evaluation. Inputs: one port per load of the model (force or
// torque in the load's declared frame, width 3 or the components declared; link force, width 1)
// and per driven joint three scalar ports NAME, NAME_rate, NAME_acc: its q, qd, qdd, imposed
// directly. Outputs: q, qd, qdd (all coordinates, model order) and one port per sensor.
// Positions and velocities (q, qd, the sensors that read no acceleration) read the states and
// the driven joints' NAME and NAME_rate only, so feedback through tyres or springs is no
// algebraic loop; qdd and the acceleration sensors read every input. Tangents go through the
// generated tangent functions and the partitioning's tangent (ReducedDynamics::tangent).
//
// Types: `multibody` with setting `model: NAME` (the model's parameter values and initial
// configuration), and `multibody.NAME` per model, whose block parameters are the model's
// symbolic parameters and the initial values `q0.<u>`, `qd0.<u>` of its independent coordinates
// (so scenes can make them sensitivity directions).
#include <algorithm>
#include <cmath>
#include <mutex>

#include "blocks/direction_plan.hpp"
#include "engine/framework/registry.hpp"
#include "generated_models/registry.hpp"
#include "symbolic/mbs/reduced_dynamics.hpp"

namespace dydp::blocks {
namespace {

using engine::Block;
using engine::DirView;
using engine::Eval;
using engine::Seeds;
using mbs::GeneratedModel;
using mbs::ReducedDynamics;
using Vector = Eigen::VectorXd;
using Matrix = Eigen::MatrixXd;

constexpr double kInf = std::numeric_limits<double>::infinity();

class Multibody : public Block {
 public:
  // `exposed`: block parameters are [model parameters, q0 of u, qd0 of u]; otherwise none.
  Multibody(const GeneratedModel& model, bool exposed)
      : g_(model), reduced_(model), exposed_(exposed), last_q_(Eigen::Map<const Vector>(model.initial_q, model.n)) {
    for (int i = 0, at = 0; i < g_.loads; at += g_.load_widths[i], ++i) {
      declare_input(g_.load_names[i], g_.load_widths[i], "N or N m");
      load_offsets_.push_back(at);
    }
    for (int i = 0; i < g_.driven_count; ++i) {
      // scalar ports, so that a steering source wires directly: NAME (q), NAME_rate, NAME_acc
      const std::string joint = g_.coordinate_names[g_.driven[i]];
      declare_input(joint, 1, "m or rad");
      declare_input(joint + "_rate", 1, "m/s or rad/s");
      declare_input(joint + "_acc", 1, "m/s^2 or rad/s^2");
    }
    // positions and velocities read the driven joints' q and qd; accelerations read everything
    std::vector<int> driven_motion;
    for (int i = 0; i < g_.driven_count; ++i) {
      driven_motion.push_back(g_.loads + 3 * i);
      driven_motion.push_back(g_.loads + 3 * i + 1);
    }
    declare_output("q", g_.n, "m or rad");
    declare_output("qd", g_.n, "m/s or rad/s");
    declare_output("qdd", g_.n, "m/s^2 or rad/s^2");
    set_output_reads(0, driven_motion);
    set_output_reads(1, driven_motion);
    int group_size[2] = {0, 0};
    for (int s = 0; s < g_.sensor_count; ++s) {
      declare_output(g_.sensor_ports[s], g_.sensor_widths[s], g_.sensor_units ? g_.sensor_units[s] : "");
      if (!g_.sensor_reads_acceleration[s]) set_output_reads(3 + s, driven_motion);
      const int group = g_.sensor_reads_acceleration[s] ? 1 : 0;
      if (group_port_[group] < 0) group_port_[group] = s;
      group_ports_[group].push_back({3 + s, group_size[group], g_.sensor_widths[s]});
      group_size[group] += g_.sensor_widths[s];
    }
    group_outputs_[0] = group_size[0];
    group_outputs_[1] = group_size[1];
    // Nominal magnitudes: a suspension's travel and a body's attitude, 0.01 m or rad, moving at
    // 0.1 m/s or rad/s (a scene's `nominal:` map sets others, e.g. for a wheel's spin angle).
    std::vector<std::string> states;
    std::vector<double> nominals;
    for (int j : reduced_.independent()) {
      states.push_back(std::string("q.") + g_.coordinate_names[j]);
      nominals.push_back(0.01);
    }
    for (int j : reduced_.independent()) {
      states.push_back(std::string("qd.") + g_.coordinate_names[j]);
      nominals.push_back(0.1);
    }
    declare_states(states, nominals);
  }

  void initial_state(const Eval& e, double* x0) const override {
    {
      // a new run: Newton-Raphson starts again from the model's assembly configuration, so the
      // mechanism is assembled in the same branch every run
      std::lock_guard<std::mutex> lock(mutex_);
      last_q_ = Eigen::Map<const Vector>(g_.initial_q, g_.n);
      result_.dynamics_current = false;
      have_kinematics_ = have_dynamics_ = false;
    }
    const int nu = reduced_.nu();
    for (int i = 0; i < nu; ++i) {
      x0[i] = exposed_ ? e.p[g_.parameters + i] : g_.initial_q[reduced_.independent()[i]];
      x0[nu + i] = exposed_ ? e.p[g_.parameters + nu + i] : 0.0;
    }
  }
  void initial_state_tangent(const Eval&, const Seeds& s, DirView dx0) const override {
    const int nu = reduced_.nu();
    for (int d = 0; d < s.directions; ++d)
      for (int i = 0; i < 2 * nu; ++i) dx0(i, d) = exposed_ ? s.p(g_.parameters + i, d) : 0.0;
  }

  void outputs(const Eval& e, double* const* y) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    const ReducedDynamics::Result& r = solve(e, needs_dynamics(e));
    const int n = g_.n;
    if (output_ready(e, 0)) std::copy_n(r.q.data(), n, y[0]);
    if (output_ready(e, 1)) std::copy_n(r.qd.data(), n, y[1]);
    if (output_ready(e, 2)) std::copy_n(r.qdd.data(), n, y[2]);
    if (g_.sensor_count == 0) return;
    const double* lam = r.lam.size() ? r.lam.data() : zero_;  // (solve filled work_.in)
    std::vector<double>& out = work_.out;
    for (int group = 0; group < 2; ++group) {
      if (!sensor_group_ready(e, group)) continue;
      out.resize(std::max(1, group_outputs_[group]));
      if (group == 0 && kinematic_sensor_values_.point == kinematic_point_ &&
          kinematic_sensor_values_.values.size() == out.size()) {
        out = kinematic_sensor_values_.values;
      } else {
        (group ? g_.sensors_acceleration : g_.sensors_kinematic)(r.q.data(), r.qd.data(), r.qdd.data(), lam,
                                                                  work_.in.data(), parameters(e), out.data());
        if (group == 0) {
          kinematic_sensor_values_.point = kinematic_point_;
          kinematic_sensor_values_.values = out;
        }
      }
      for (const GroupPort& port : group_ports_[group]) std::copy_n(out.data() + port.offset, port.width, y[port.output]);
    }
  }

  void outputs_tangent(const Eval& e, const Seeds& s, const DirView* dy) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    const bool dynamics = needs_dynamics(e);
    const ReducedDynamics::Result& r = solve(e, dynamics);
    const Matrix &dq = work_.dq, &dqd = work_.dqd, &dqdd = work_.dqdd, &dinp = work_.dinp, &dp = work_.dp;
    tangent(e, s, r, dynamics);
    const int n = g_.n, nd = s.directions;
    const bool motion = output_ready(e, 0), acceleration = output_ready(e, 2);
    for (int d = 0; d < nd; ++d)
      for (int i = 0; i < n; ++i) {
        if (motion) dy[0](i, d) = dq(i, d);
        if (motion) dy[1](i, d) = dqd(i, d);
        if (acceleration) dy[2](i, d) = dqdd(i, d);
      }
    if (g_.sensor_count == 0 || nd == 0) return;
    const double* lam = r.lam.size() ? r.lam.data() : zero_;
    std::vector<double>&out = work_.out, &dout = work_.dout;
    for (int group = 0; group < 2; ++group) {
      if (!sensor_group_ready(e, group)) continue;
      const int ns = group_outputs_[group];
      out.resize(std::max(1, ns));
      dout.resize(static_cast<std::size_t>(std::max(1, ns)) * nd);
      // the kinematic group depends on what the kinematic tangent does (q, qd, the driven
      // joints' motion, p): kept with it, and reused while it is
      KeptSensors& kept = kinematic_sensor_tangent_;
      if (group == 0 && kept.point == kinematic_point_ && same(kept.dq, dq) && same(kept.dqd, dqd) &&
          same(kept.dp, dp) && kept.values.size() == dout.size()) {
        dout = kept.values;
      } else {
        const auto sensors = group ? g_.sensors_acceleration_tangent : g_.sensors_kinematic_tangent;
        Work& w = work_;
        // the directions with nonzero seeds, as in tangent(); the positions' group reads no qdd,
        // so directions seeded on one load entry share a pass there (the accelerations' group
        // reads their dqdd, which differ)
        if (group == 0) w.plan.build({&dq, &dqd, &dinp, &dp}, nd, 2, g_.load_inputs);
        else w.plan.build({&dq, &dqd, &dqdd, &dinp, &dp}, nd);
        if (w.plan.whole()) {
          sensors(r.q.data(), r.qd.data(), r.qdd.data(), lam, w.in.data(), parameters(e), nd, dq.data(), dqd.data(),
                  dqdd.data(), dinp.data(), dp.data(), out.data(), dout.data());
        } else {
          const int np = w.plan.passes();
          w.plan.gather(dq, w.c_dq), w.plan.gather(dqd, w.c_dqd), w.plan.gather(dqdd, w.c_dqdd);
          w.plan.gather(dinp, w.c_dinp), w.plan.gather(dp, w.c_dp);
          w.c_dout.resize(static_cast<std::size_t>(std::max(1, ns)) * std::max(1, np));
          if (np > 0)
            sensors(r.q.data(), r.qd.data(), r.qdd.data(), lam, w.in.data(), parameters(e), np, w.c_dq.data(),
                    w.c_dqd.data(), w.c_dqdd.data(), w.c_dinp.data(), w.c_dp.data(), out.data(), w.c_dout.data());
          w.plan.scatter(w.c_dout.data(), ns, ns, dout.data(), ns);
        }
        if (group == 0) kept.assign(kinematic_point_, dq, dqd, dp, dout);
      }
      for (int d = 0; d < nd; ++d) {
        const double* from = dout.data() + static_cast<std::size_t>(d) * ns;
        for (const GroupPort& port : group_ports_[group])
          std::copy_n(from + port.offset, port.width, &dy[port.output](0, d));
      }
    }
  }

  void derivatives(const Eval& e, double* xdot) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    const ReducedDynamics::Result& r = solve(e, true);
    const int nu = reduced_.nu();
    for (int i = 0; i < nu; ++i) {
      xdot[i] = e.x[nu + i];
      xdot[nu + i] = r.udd[i];
    }
  }

  void derivatives_tangent(const Eval& e, const Seeds& s, DirView dxdot) const override {
    std::lock_guard<std::mutex> lock(mutex_);
    const ReducedDynamics::Result& r = solve(e, true);
    tangent(e, s, r, true);
    const Matrix& dqdd = work_.dqdd;
    const int nu = reduced_.nu();
    for (int d = 0; d < s.directions; ++d)
      for (int i = 0; i < nu; ++i) {
        dxdot(i, d) = s.x(nu + i, d);
        dxdot(nu + i, d) = dqdd(reduced_.independent()[i], d);
      }
  }

 private:
  static bool same(const Matrix& a, const Matrix& b) { return a.rows() == b.rows() && a.cols() == b.cols() && a == b; }
  // Whether this call sets the group's sensor ports (0: positions and velocities, 1: reads
  // qdd): the ports of a group read the same inputs, so one port answers for all.
  bool sensor_group_ready(const Eval& e, int group) const {
    return group_port_[group] >= 0 && output_ready(e, 3 + group_port_[group]);
  }

  const double* parameters(const Eval& e) const {
    return exposed_ && g_.parameters ? e.p : (g_.parameters ? g_.parameter_values : zero_);
  }

  // The model's input array: load components, then q, qd, qdd of each driven joint, from the
  // ports that are ready (the others zero: no output read in this call depends on them; a
  // driven joint not yet commanded sits at its assembly position).
  void fill_inputs(const Eval& e, Vector& in) const {
    in.setZero(std::max(1, g_.inputs));
    for (int k = 0; k < g_.loads; ++k)
      if (e.input_ready(k))
        for (int i = 0, at = load_offset(k); i < g_.load_widths[k]; ++i) in[at + i] = e.u[k][i];
    for (int i = 0; i < g_.driven_count; ++i)
      for (int j = 0; j < 3; ++j) {
        const int port = g_.loads + 3 * i + j;
        in[g_.load_inputs + 3 * i + j] = e.input_ready(port) ? e.u[port][0] : (j == 0 ? g_.initial_q[g_.driven[i]] : 0.0);
      }
  }
  int load_offset(int k) const { return load_offsets_[k]; }

  // Whether this output call sets an output that reads accelerations (qdd, acceleration
  // sensors); the call for positions and velocities comes first, before the loads are known.
  bool needs_dynamics(const Eval& e) const {
    if (output_ready(e, 2)) return true;
    return sensor_group_ready(e, 1);
  }

  // The partitioned dynamics at (x, inputs, p) in two halves, each reused while its own
  // arguments are unchanged: kinematics (x, the driven joints' q and qd, p), and with `dynamics`
  // the accelerations and multipliers (also the loads and driven accelerations). A value pass
  // asks for positions first and for accelerations once the loads are known: one solve each.
  // Called with mutex_ held; fills work_.in.
  const ReducedDynamics::Result& solve(const Eval& e, bool dynamics) const {
    const int nu = reduced_.nu();
    Vector& in = work_.in;
    fill_inputs(e, in);
    const double* p = parameters(e);
    Vector& kinematic = work_.kinematic;
    kinematic.resize(2 * nu + 2 * g_.driven_count + g_.parameters);
    for (int i = 0; i < 2 * nu; ++i) kinematic[i] = e.x[i];
    for (int i = 0; i < g_.driven_count; ++i) {
      kinematic[2 * nu + 2 * i] = in[g_.load_inputs + 3 * i];
      kinematic[2 * nu + 2 * i + 1] = in[g_.load_inputs + 3 * i + 1];
    }
    for (int i = 0; i < g_.parameters; ++i) kinematic[2 * nu + 2 * g_.driven_count + i] = p[i];
    if (!(have_kinematics_ && kinematic == kinematic_key_)) {
      have_kinematics_ = have_dynamics_ = false;
      ++point_;
      ++kinematic_point_;
      try {
        try {
          // from the last solution moved along its B: within O(|du|^2) of this one
          if (result_.dynamics_current) reduced_.predict(result_, e.x, guess_);
          else guess_ = last_q_;
          reduced_.solve_kinematics(e.x, e.x + nu, in.data(), p, guess_, result_);
        } catch (const std::runtime_error&) {
          // the last solution may be far away (a new run of the same diagram): from the model's
          // initial configuration
          reduced_.solve_kinematics(e.x, e.x + nu, in.data(), p, Eigen::Map<const Vector>(g_.initial_q, g_.n),
                                    result_);
        }
      } catch (const std::runtime_error& failure) {
        // a trial state the constraints cannot be closed at: the solver retries a smaller step
        throw engine::OutOfDomain{failure.what()};
      }
      last_q_ = result_.q;
      kinematic_key_ = kinematic;
      have_kinematics_ = true;
    }
    if (!dynamics || (have_dynamics_ && in == dynamic_key_)) return result_;
    have_dynamics_ = false;
    ++point_;
    try {
      reduced_.solve_dynamics(in.data(), p, result_);
    } catch (const std::runtime_error& failure) {
      throw engine::OutOfDomain{failure.what()};
    }
    if (!result_.qdd.allFinite()) throw engine::OutOfDomain{"multibody: non-finite accelerations"};
    dynamic_key_ = in;
    have_dynamics_ = true;
    return result_;
  }

  // Tangents of q, qd and, with `dynamics`, qdd. A tangent pass asks twice for the same full
  // tangent (the acceleration outputs, then the state derivatives): the last one is reused
  // for the same point and the same seeds.
  // Called with mutex_ held, after solve(e, ...) (work_.in): sets work_'s seeds and dq, dqd,
  // dqdd.
  void tangent(const Eval& e, const Seeds& s, const ReducedDynamics::Result& r, bool dynamics) const {
    const int nu = reduced_.nu(), nd = s.directions;
    Matrix &du = work_.du, &dud = work_.dud, &dinp = work_.dinp, &dp = work_.dp;
    Matrix &dq = work_.dq, &dqd = work_.dqd, &dqdd = work_.dqdd;
    du.resize(nu, std::max(nd, 1));
    dud.resize(nu, std::max(nd, 1));
    dinp.setZero(std::max(1, g_.inputs), std::max(nd, 1));
    dp.setZero(std::max(1, g_.parameters), std::max(nd, 1));
    for (int d = 0; d < nd; ++d) {
      for (int i = 0; i < nu; ++i) {
        du(i, d) = s.x(i, d);
        dud(i, d) = s.x(nu + i, d);
      }
      for (int k = 0; k < g_.loads; ++k)
        if (e.input_ready(k))
          for (int i = 0, at = load_offset(k); i < g_.load_widths[k]; ++i) dinp(at + i, d) = s.u[k](i, d);
      for (int i = 0; i < g_.driven_count; ++i)
        for (int j = 0; j < 3; ++j) {
          const int port = g_.loads + 3 * i + j;
          if (e.input_ready(port)) dinp(g_.load_inputs + 3 * i + j, d) = s.u[port](0, d);
        }
      if (exposed_)
        for (int i = 0; i < g_.parameters; ++i) dp(i, d) = s.p(i, d);
    }
    const Vector& in = work_.in;
    if (dynamics && full_tangent_.point == point_ && same(full_tangent_.du, du) && same(full_tangent_.dud, dud) &&
        same(full_tangent_.dinp, dinp) && same(full_tangent_.dp, dp)) {
      dq = full_tangent_.dq, dqd = full_tangent_.dqd, dqdd = full_tangent_.dqdd;
      return;
    }
    // Positions and velocities read the driven joints' q and qd seeds, not the loads'.
    Matrix& driven = work_.driven;
    driven.setZero(std::max(1, 2 * g_.driven_count), std::max(nd, 1));
    for (int i = 0; i < g_.driven_count; ++i)
      for (int j = 0; j < 2; ++j) driven.row(2 * i + j) = dinp.row(g_.load_inputs + 3 * i + j);
    if (kinematic_tangent_.point == kinematic_point_ && same(kinematic_tangent_.du, du) &&
        same(kinematic_tangent_.dud, dud) && same(kinematic_tangent_.dinp, driven) &&
        same(kinematic_tangent_.dp, dp)) {
      dq = kinematic_tangent_.dq, dqd = kinematic_tangent_.dqd;
    } else {
      // Directions whose seeds are all zero (in a Jacobian pass, the states of blocks that do not
      // reach the car) have zero tangents: the partitioning and the generated tangents run on
      // the others only.
      Work& w = work_;
      w.plan.build({&du, &dud, &driven, &dp}, nd);
      if (w.plan.whole()) {
        reduced_.tangent_kinematics(r, in.data(), parameters(e), nd, du.data(), dud.data(), dinp.data(), dp.data(),
                                    dq, dqd);
      } else {
        w.plan.gather(du, w.c_du), w.plan.gather(dud, w.c_dud), w.plan.gather(dinp, w.c_dinp);
        w.plan.gather(dp, w.c_dp);
        if (w.plan.passes() > 0)
          reduced_.tangent_kinematics(r, in.data(), parameters(e), w.plan.passes(), w.c_du.data(), w.c_dud.data(),
                                      w.c_dinp.data(), w.c_dp.data(), w.c_dq, w.c_dqd);
        w.plan.scatter(w.c_dq, g_.n, dq), w.plan.scatter(w.c_dqd, g_.n, dqd);
      }
      kinematic_tangent_.assign(kinematic_point_, du, dud, driven, dp, dq, dqd, nullptr);
    }
    if (!dynamics) {
      dqdd.setZero(g_.n, std::max(nd, 1));  // not read: no acceleration output in this call
      return;
    }
    // Directions seeded on one load entry only (dq = dqd = 0 for them) share a pass per entry.
    Work& w = work_;
    w.plan.build({&du, &dud, &dinp, &dp}, nd, 2, g_.load_inputs);
    if (w.plan.whole()) {
      reduced_.tangent_dynamics(r, in.data(), parameters(e), nd, dinp.data(), dp.data(), dq, dqd, dqdd);
    } else {
      w.plan.gather(dinp, w.c_dinp), w.plan.gather(dp, w.c_dp), w.plan.gather(dq, w.c_dq);
      w.plan.gather(dqd, w.c_dqd);
      if (w.plan.passes() > 0)
        reduced_.tangent_dynamics(r, in.data(), parameters(e), w.plan.passes(), w.c_dinp.data(), w.c_dp.data(),
                                  w.c_dq, w.c_dqd, w.c_dqdd);
      w.plan.scatter(w.c_dqdd, g_.n, dqdd);
    }
    full_tangent_.assign(point_, du, dud, dinp, dp, dq, dqd, &dqdd);
  }

  /// A tangent kept for the next call at the same point with the same seeds.
  struct KeptTangent {
    long point = -1;
    Matrix du, dud, dinp, dp;  ///< seeds
    Matrix dq, dqd, dqdd;      ///< result
    // (member by member: a matrix of the same size keeps its storage)
    void assign(long at, const Matrix& du_, const Matrix& dud_, const Matrix& dinp_, const Matrix& dp_,
                const Matrix& dq_, const Matrix& dqd_, const Matrix* dqdd_) {
      point = at, du = du_, dud = dud_, dinp = dinp_, dp = dp_, dq = dq_, dqd = dqd_;
      if (dqdd_) dqdd = *dqdd_;
      else dqdd.resize(0, 0);
    }
  };
  /// The kinematic sensors (values, or derivatives for the kept dq, dqd, dp) at a kinematic
  /// point: an output pass sets them in its first call and again in its last.
  struct KeptSensors {
    long point = -1;
    Matrix dq, dqd, dp;
    std::vector<double> values;
    void assign(long at, const Matrix& dq_, const Matrix& dqd_, const Matrix& dp_, const std::vector<double>& v) {
      point = at, dq = dq_, dqd = dqd_, dp = dp_, values = v;
    }
  };

  const GeneratedModel& g_;
  std::vector<int> load_offsets_;  ///< each load's first entry in the model's input array
  /// The sensor ports by group (1: they read qdd): each port's output index, its first entry
  /// among the group's outputs, its width.
  struct GroupPort {
    int output, offset, width;
  };
  std::vector<GroupPort> group_ports_[2];
  int group_outputs_[2] = {0, 0};
  int group_port_[2] = {-1, -1};  ///< a sensor port of each group (-1: none)
  ReducedDynamics reduced_;
  bool exposed_;
  const double zero_[1] = {0.0};
  mutable std::mutex mutex_;
  mutable Vector last_q_, guess_, kinematic_key_, dynamic_key_;
  mutable ReducedDynamics::Result result_;
  mutable bool have_kinematics_ = false, have_dynamics_ = false;
  mutable long point_ = 0;            ///< changes whenever result_ does
  mutable long kinematic_point_ = 0;  ///< changes whenever result_'s kinematics do
  mutable KeptTangent kinematic_tangent_, full_tangent_;
  mutable KeptSensors kinematic_sensor_values_, kinematic_sensor_tangent_;
  /// Storage of one call (under mutex_), sized at the first and reused: the right-hand side's
  /// path allocates nothing once the sizes are known.
  struct Work {
    Vector in, kinematic;
    Matrix du, dud, dinp, dp, driven, dq, dqd, dqdd;
    std::vector<double> out, dout;
    // the passes a call's directions need (DirectionPlan), and the seeds and tangents of those
    DirectionPlan plan;
    Matrix c_du, c_dud, c_dinp, c_dp, c_dq, c_dqd, c_dqdd;
    std::vector<double> c_dout;
  };
  mutable Work work_;
};

std::vector<engine::ParamSpec> exposed_parameters(const GeneratedModel& g) {
  std::vector<engine::ParamSpec> specs;
  for (int i = 0; i < g.parameters; ++i)
    specs.push_back({g.parameter_names[i], g.parameter_units[i], g.parameter_values[i], false, -kInf, kInf, "model parameter"});
  ReducedDynamics reduced(g);
  for (int j : reduced.independent())
    specs.push_back({std::string("q0.") + g.coordinate_names[j], "m or rad", g.initial_q[j], false, -kInf, kInf,
                     "initial value of an independent coordinate"});
  for (int j : reduced.independent())
    specs.push_back({std::string("qd0.") + g.coordinate_names[j], "m/s or rad/s", 0.0, false, -kInf, kInf,
                     "initial velocity of an independent coordinate"});
  return specs;
}

// Registers `multibody` and one `multibody.NAME` per generated model.
struct Registration {
  Registration() {
    engine::Registry::global().add(
        {"multibody", "mechanics", "A generated multibody model (setting model: NAME), with its default parameters.",
         {},
         {{"model", "name of a generated model (generated_models/NAME.mbs.yaml)", "", true}},
         [](const engine::BlockSettings& s) -> std::unique_ptr<Block> {
           const std::string name = s.text("model");
           const GeneratedModel* g = generated::find_model(name);
           if (!g) s.fail("model", "no generated model named '" + name + "'");
           return std::make_unique<Multibody>(*g, false);
         }});
    for (const GeneratedModel* g : generated::all_models()) {
      engine::Registry::global().add(
          {std::string("multibody.") + g->name, "mechanics",
           std::string("The generated multibody model ") + g->name + ", its parameters and initial state exposed.",
           exposed_parameters(*g),
           {},
           [g](const engine::BlockSettings&) -> std::unique_ptr<Block> { return std::make_unique<Multibody>(*g, true); }});
    }
  }
};
const Registration registration;

}  // namespace
}  // namespace dydp::blocks
