#include "fmi/fmu_model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "engine/framework/errors.hpp"
#include "engine/studies/initial_equilibrium.hpp"

namespace dydp::fmi {

using engine::ConstDirView;
using engine::DirView;

FmuModel::FmuModel(const std::string& fmu_file) {
  const Exposure e = read_exposure(fmu_file);
  diagram_ = std::make_unique<engine::Diagram>(engine::load_scene(e.scene_file));
  table_ = build_variables(*diagram_, e);  // sets the diagram's sensitivities: the parameter knowns
  ev_ = std::make_unique<engine::Evaluator>(*diagram_, true);
  inputs_.resize(table_.input_offsets.size());
  for (const Variable& v : table_.variables)
    if (v.role == Role::input) inputs_[v.index] = v.start;
  x_.assign(num_states(), 0.0);
  sens_.assign(static_cast<size_t>(num_states()) * num_sensitivities(), 0.0);
  stop_ = diagram_->time.stop;
  refresh();
  start(diagram_->time.start, diagram_->time.stop);
}

void FmuModel::refresh() {
  held_.clear();
  for (size_t j = 0; j < inputs_.size(); ++j) held_.emplace_back(table_.input_offsets[j], inputs_[j]);
  ev_->hold_signals(held_);  // also drops the evaluator's caches (parameters may have changed)
  output_sens_valid_ = false;
  ++changes_;
}

void FmuModel::start(double t0, double stop) {
  t_ = t0;
  stop_ = stop;
  set_segment_start(t0);
  // `initial: equilibrium`: the static equilibrium at t0 with the inputs held at the importer's
  // values and the parameters as it set them (the blocks' initial states otherwise).
  engine::start_at_equilibrium(*diagram_, t0, held_);
  std::vector<double> x0(std::max(diagram_->num_states, 1), 0.0);
  ev_->initial_state(t0, x0.data());
  std::fill(x_.begin(), x_.end(), 0.0);
  std::copy(x0.begin(), x0.begin() + diagram_->num_states, x_.begin());
  // The sensitivities of that start: the blocks' initial states' tangents, or the equilibrium's
  // dx/dp (Diagram::start); the integrals start at zero whatever the parameters.
  std::fill(sens_.begin(), sens_.end(), 0.0);
  const int nx = diagram_->num_states, n = num_states();
  if (num_sensitivities() > 0 && nx > 0) {
    std::vector<double> dx0(static_cast<size_t>(nx) * diagram_->sensitivities.size(), 0.0);
    ev_->initial_state_tangent(t0, x0.data(), DirView{dx0.data(), nx});
    for (int dir = 0; dir < num_sensitivities(); ++dir)
      std::copy_n(dx0.data() + static_cast<size_t>(dir) * nx, nx, sens_.data() + static_cast<size_t>(dir) * n);
  }
  output_sens_valid_ = false;
  ++changes_;
}

void FmuModel::set_time(double t) {
  t_ = t;
  output_sens_valid_ = false;
}

void FmuModel::move_to(double t, const double* x) {
  t_ = t;
  std::copy(x, x + num_states(), x_.begin());
  output_sens_valid_ = false;
}

void FmuModel::move_sensitivities(const double* s) {
  std::copy(s, s + sens_.size(), sens_.begin());
  output_sens_valid_ = false;
}

void FmuModel::set_segment_start(double t) {
  segment_start_ = t;
  ev_->set_segment_start(t);
  output_sens_valid_ = false;
}

void FmuModel::set_states(const double* x) {
  std::copy(x, x + num_states(), x_.begin());
  output_sens_valid_ = false;
  ++changes_;
}

void FmuModel::hold_input_tangents(int nd) {
  ev_->set_signal_seeds(table_.input_offsets, std::vector<double>(inputs_.size() * nd, 0.0));
}

void FmuModel::sensitivity_derivatives(const double* s, double* sdot) {
  const int nx = diagram_->num_states, nq = diagram_->num_quadratures, n = num_states(), ns = num_sensitivities();
  std::fill(sdot, sdot + static_cast<size_t>(n) * ns, 0.0);
  if (ns == 0 || n == 0) return;
  // Both views step by the FMU's state vector: a direction's block states, then its integrals.
  hold_input_tangents(ns);
  ev_->tangents(t_, x_.data(), ns, ConstDirView{s, n}, true, DirView{nx ? sdot : nullptr, n},
                DirView{nq ? sdot + nx : nullptr, n});
  ev_->set_signal_seeds({}, {});
}

double FmuModel::sensitivity_value(const Variable& v) {
  const Variable& out = table_.variables[v.index];
  const int n = num_states();
  const double* s = sens_.data() + static_cast<size_t>(v.direction) * n;
  if (out.role == Role::output_objective) {  // from its integrals' sensitivities
    const engine::Node& node = diagram_->nodes[out.index];
    double dpsi = 0.0;
    objective_value(out.index, s + diagram_->num_states + node.quad_offset, &dpsi);
    return dpsi;
  }
  // Signals: one output tangent pass along the states' sensitivities for every output, kept
  // until the time or the state moves.
  if (!output_sens_valid_) {
    const int ns = num_sensitivities();
    hold_input_tangents(ns);
    ev_->tangents(t_, x_.data(), ns, ConstDirView{sens_.data(), n}, true, DirView{}, DirView{});
    ev_->set_signal_seeds({}, {});
    output_sens_ = ev_->signal_tangents();
    output_sens_valid_ = true;
  }
  return output_sens_[static_cast<size_t>(v.direction) * diagram_->num_signals + out.index];
}

void FmuModel::set_value(const Variable& v, double value) {
  if (v.role == Role::input) {
    inputs_[v.index] = value;
  } else if (v.role == Role::parameter) {
    diagram_->set_parameter(v.index, value);
  } else {
    throw std::invalid_argument(v.name + " is not an input or a parameter");
  }
  refresh();
}

double FmuModel::objective_value(int node, const double* dq, double* dpsi) {
  const engine::Node& n = diagram_->nodes[node];
  engine::ObjectiveSamples samples;
  samples.t_start = diagram_->time.start;
  samples.t_stop = stop_;
  samples.directions = dq ? 1 : 0;
  double unused = 0.0;
  return n.objective->objective(n.p.data(), x_.data() + diagram_->num_states + n.quad_offset,
                                ConstDirView{dq, n.block->num_quadratures()}, samples, dpsi ? dpsi : &unused);
}

double FmuModel::value(const Variable& v) {
  switch (v.role) {
    case Role::time: return t_;
    case Role::parameter: return diagram_->parameters[v.index].value;
    case Role::input: return inputs_[v.index];
    case Role::state: return x_[v.index];
    case Role::derivative: {
      std::vector<double> xdot(std::max(num_states(), 1));
      derivatives(xdot.data());
      return xdot[v.index];
    }
    case Role::output_signal:
      ev_->outputs(t_, x_.data());
      return ev_->signals()[v.index];
    case Role::output_objective: return objective_value(v.index, nullptr, nullptr);
    case Role::event_indicator: return t_ - table_.breakpoints[v.index];
    case Role::output_sensitivity: return sensitivity_value(v);
  }
  return std::numeric_limits<double>::quiet_NaN();
}

void FmuModel::derivatives(double* xdot) {
  const int nx = diagram_->num_states;
  if (nx > 0) ev_->derivatives(t_, x_.data(), xdot);
  if (diagram_->num_quadratures > 0) ev_->quadratures(t_, x_.data(), xdot + nx);
}

void FmuModel::event_indicators(double* z) const {
  for (size_t k = 0; k < table_.breakpoints.size(); ++k) z[k] = t_ - table_.breakpoints[k];
}

double FmuModel::next_breakpoint(double t) const {
  for (double tb : table_.breakpoints)
    if (tb > t) return tb;
  return std::numeric_limits<double>::infinity();
}

void FmuModel::directional_derivative(const std::vector<const Variable*>& unknowns,
                                      const std::vector<const Variable*>& knowns, const double* seed,
                                      double* sensitivity) {
  const int nx = diagram_->num_states, nq = diagram_->num_quadratures;
  // The seeds of the known side: states (block states and integrals), inputs, parameters.
  std::vector<double> dx(std::max(nx, 1), 0.0), dq(std::max(nq, 1), 0.0), du(inputs_.size(), 0.0);
  const std::vector<int>& directions = diagram_->sensitivities;  // the differentiable knowns among them
  std::vector<double> dp(directions.size(), 0.0);
  bool any_p = false;
  for (size_t j = 0; j < knowns.size(); ++j) {
    const Variable& k = *knowns[j];
    if (k.role == Role::state) {
      (k.index < nx ? dx[k.index] : dq[k.index - nx]) += seed[j];
    } else if (k.role == Role::input) {
      du[k.index] += seed[j];
    } else if (k.role == Role::parameter) {
      const auto it = std::find(directions.begin(), directions.end(), k.index);
      if (std::find(table_.differentiable.begin(), table_.differentiable.end(), k.index) == table_.differentiable.end() ||
          it == directions.end())
        throw std::invalid_argument(k.name + " drives a block parameter its block cannot differentiate");
      dp[it - directions.begin()] += seed[j];
      any_p = true;
    } else {
      throw std::invalid_argument(k.name + " is not a known of a partial derivative (a state, an input or a parameter)");
    }
  }
  for (const Variable* u : unknowns)
    if (u->role != Role::derivative && u->role != Role::output_signal && u->role != Role::output_objective)
      throw std::invalid_argument(u->name + " is not an unknown of a partial derivative (a derivative or an output" +
                                  (u->role == Role::output_sensitivity ? "; a sensitivity's derivatives are not given)" : ")"));

  // One tangent pass along (dx, du); the parameters' columns from a pass with their seeds.
  const int ns = static_cast<int>(directions.size());
  const int ld = diagram_->num_signals;
  std::vector<double> dxdot(std::max(nx, 1), 0.0), dqdot(std::max(nq, 1), 0.0);
  ev_->set_signal_seeds(table_.input_offsets, du);
  ev_->tangents(t_, x_.data(), 1, ConstDirView{dx.data(), nx}, false, DirView{dxdot.data(), nx},
                DirView{nq ? dqdot.data() : nullptr, nq});
  std::vector<double> dsig(ev_->signal_tangents().begin(), ev_->signal_tangents().begin() + ld);
  if (any_p) {
    std::vector<double> dxdot_p(static_cast<size_t>(std::max(nx, 1)) * ns, 0.0), dqdot_p(static_cast<size_t>(std::max(nq, 1)) * ns, 0.0);
    ev_->set_signal_seeds(table_.input_offsets, std::vector<double>(inputs_.size() * ns, 0.0));
    ev_->tangents(t_, x_.data(), ns, ConstDirView{}, true, DirView{dxdot_p.data(), nx},
                  DirView{nq ? dqdot_p.data() : nullptr, nq});
    const std::vector<double>& ds = ev_->signal_tangents();
    for (int c = 0; c < ns; ++c) {
      if (dp[c] == 0.0) continue;
      for (int i = 0; i < nx; ++i) dxdot[i] += dp[c] * dxdot_p[static_cast<size_t>(c) * nx + i];
      for (int i = 0; i < nq; ++i) dqdot[i] += dp[c] * dqdot_p[static_cast<size_t>(c) * nq + i];
      for (int i = 0; i < ld; ++i) dsig[i] += dp[c] * ds[static_cast<size_t>(c) * ld + i];
    }
  }
  ev_->set_signal_seeds({}, {});
  for (size_t i = 0; i < unknowns.size(); ++i) {
    const Variable& u = *unknowns[i];
    if (u.role == Role::derivative) {
      sensitivity[i] = u.index < nx ? dxdot[u.index] : dqdot[u.index - nx];
    } else if (u.role == Role::output_signal) {
      sensitivity[i] = dsig[u.index];
    } else {
      const engine::Node& n = diagram_->nodes[u.index];
      objective_value(u.index, dq.data() + n.quad_offset, &sensitivity[i]);
    }
  }
}

void FmuModel::adjoint_derivative(const std::vector<const Variable*>& unknowns, const std::vector<const Variable*>& knowns,
                                  const double* seed, double* sensitivity) {
  // w^T J column by column: one tangent pass per known, the unknowns' rows weighted by w.
  std::vector<double> column(unknowns.size());
  for (size_t j = 0; j < knowns.size(); ++j) {
    const double one = 1.0;
    directional_derivative(unknowns, {knowns[j]}, &one, column.data());
    double s = 0.0;
    for (size_t i = 0; i < unknowns.size(); ++i) s += seed[i] * column[i];
    sensitivity[j] = s;
  }
}

void FmuModel::state_jacobian(double* jac) {
  const int nx = diagram_->num_states, nq = diagram_->num_quadratures, n = num_states();
  std::fill(jac, jac + static_cast<size_t>(n) * n, 0.0);
  if (nx == 0) return;
  std::vector<double> eye(static_cast<size_t>(nx) * nx, 0.0), dxdot(static_cast<size_t>(nx) * nx, 0.0),
      dqdot(static_cast<size_t>(std::max(nq, 1)) * nx, 0.0);
  for (int i = 0; i < nx; ++i) eye[static_cast<size_t>(i) * nx + i] = 1.0;
  ev_->set_signal_seeds(table_.input_offsets, std::vector<double>(inputs_.size() * nx, 0.0));
  ev_->tangents(t_, x_.data(), nx, ConstDirView{eye.data(), nx}, false, DirView{dxdot.data(), nx},
                DirView{nq ? dqdot.data() : nullptr, nq});
  ev_->set_signal_seeds({}, {});
  for (int c = 0; c < nx; ++c) {
    for (int r = 0; r < nx; ++r) jac[static_cast<size_t>(c) * n + r] = dxdot[static_cast<size_t>(c) * nx + r];
    for (int r = 0; r < nq; ++r) jac[static_cast<size_t>(c) * n + nx + r] = dqdot[static_cast<size_t>(c) * nq + r];
  }
}

ModelSnapshot FmuModel::snapshot() const {
  ModelSnapshot s{t_, segment_start_, x_, inputs_, {}, sens_};
  for (const auto& p : diagram_->parameters) s.parameters.push_back(p.value);
  return s;
}

void FmuModel::restore(const ModelSnapshot& s) {
  if (s.states.size() != x_.size() || s.inputs.size() != inputs_.size() ||
      s.parameters.size() != diagram_->parameters.size() || s.sensitivities.size() != sens_.size())
    throw std::invalid_argument("an FMU state of another model");
  for (size_t i = 0; i < s.parameters.size(); ++i)
    if (diagram_->parameters[i].value != s.parameters[i]) diagram_->set_parameter(static_cast<int>(i), s.parameters[i], false);
  t_ = s.time;
  x_ = s.states;
  inputs_ = s.inputs;
  sens_ = s.sensitivities;
  set_segment_start(s.segment_start);
  refresh();
}

}  // namespace dydp::fmi
