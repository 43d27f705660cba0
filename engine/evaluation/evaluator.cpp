#include "engine/evaluation/evaluator.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace dydp::engine {
namespace {

/// Calls a block function; an OutOfDomain it throws comes out naming the block.
template <class F>
void call_block(const Node& n, F&& f) {
  try {
    f();
  } catch (const OutOfDomain& e) {
    throw OutOfDomain{n.name + ": " + e.reason};
  }
}

}  // namespace

Evaluator::Evaluator(const Diagram& d, bool with_sensitivities)
    : d_(d), ns_(with_sensitivities ? static_cast<int>(d.sensitivities.size()) : 0),
      sig_(d.num_signals, 0.0), last_x_(d.num_states, 0.0) {
  size_t max_ports = 1;
  for (const Node& n : d.nodes) {
    pseed_offset_.push_back(static_cast<int>(pseed_.size()));
    const int np = static_cast<int>(n.p.size());
    for (int dir = 0; dir < ns_; ++dir)
      for (int j = 0; j < np; ++j) pseed_.push_back(d.parameter_seed(n, j, dir));
    u_offset_.push_back(static_cast<int>(u_.size()));
    for (int src : n.input_source) u_.push_back(sig_.data() + src);
    max_ports = std::max({max_ports, n.block->inputs().size(), n.block->outputs().size()});
    bool driven = false;
    for (int dir = 0; dir < ns_; ++dir)
      for (size_t j = 0; j < n.p.size(); ++j) driven = driven || d.parameter_seed(n, j, dir) != 0.0;
    driven_.push_back(driven);
  }
  du_.resize(max_ports);
  const size_t nn = d.nodes.size();
  time_only_.assign(nn, false);
  source_valid_.assign(nn, false);
  source_t_.assign(nn, 0.0);
  source_segment_.assign(nn, 0.0);
  zero_tangent_.assign(d.num_signals, false);
  for (size_t i = 0; i < nn; ++i) {
    const Node& n = d.nodes[i];
    time_only_[i] = n.block->inputs().empty() && n.block->num_states() == 0;
  }
  dy_.resize(max_ports);
  y_.resize(max_ports);
  ubar_.resize(max_ports);
  wy_.resize(max_ports);
  kept_outputs_.resize(d.output_steps.size());
  kept_derivatives_.resize(nn);
  kept_quadratures_.resize(nn);
}

Eval Evaluator::eval_for(const Node& n, int index, double t, const double* x) const {
  Eval e;
  e.t = t;
  e.segment_start = segment_start_;
  e.x = x ? x + n.state_offset : nullptr;
  e.u = u_.data() + u_offset_[index];
  e.p = p_override_.empty() ? n.p.data() : p_override_[index].data();
  return e;
}

void Evaluator::use_parameter_values(const double* scene_values) {
  if (p_override_.empty())
    for (const Node& n : d_.nodes) p_override_.push_back(n.p);
  bool changed = false;
  for (size_t i = 0; i < d_.nodes.size(); ++i) {
    const Node& n = d_.nodes[i];
    for (size_t j = 0; j < n.p.size(); ++j)
      if (n.p_scene[j] >= 0 && p_override_[i][j] != scene_values[n.p_scene[j]]) {
        p_override_[i][j] = scene_values[n.p_scene[j]];
        changed = true;
      }
  }
  if (changed) {
    valid_ = false;
    std::fill(source_valid_.begin(), source_valid_.end(), false);
  }
}

Seeds Evaluator::seeds_for(const Node& n, int index, int nd, ConstDirView dx, bool with_params) {
  const int ld = d_.num_signals;
  for (size_t k = 0; k < n.input_source.size(); ++k)
    du_[k] = {dsig_.data() + n.input_source[k], ld};
  Seeds s;
  s.directions = nd;
  s.x = dx.zero() || n.block->num_states() == 0 ? ConstDirView{}
                                                 : ConstDirView{dx.data + n.state_offset, dx.ld};
  s.u = du_.data();
  s.p = with_params && driven_[index]
            ? ConstDirView{pseed_.data() + pseed_offset_[index], static_cast<int>(n.p.size())}
            : ConstDirView{};
  return s;
}

void Evaluator::initial_state(double t0, double* x0) {
  if (!d_.start.x.empty()) {  // a start given from outside (`initial: equilibrium`)
    std::copy(d_.start.x.begin(), d_.start.x.end(), x0);
    return;
  }
  std::fill(x0, x0 + d_.num_states, 0.0);
  for (size_t i = 0; i < d_.nodes.size(); ++i) {
    const Node& n = d_.nodes[i];
    if (n.block->num_states() == 0) continue;
    n.block->initial_state(eval_for(n, static_cast<int>(i), t0, x0), x0 + n.state_offset);
  }
}

namespace {

/// The column of a start given from outside (Diagram::start) for sensitivity direction dir.
const double* start_derivative(const Diagram& d, int dir) {
  const auto& cols = d.start.parameters;
  const auto c = std::find(cols.begin(), cols.end(), d.sensitivities[dir]);
  if (c == cols.end())
    throw std::logic_error("the run's start state has no derivative for direction " +
                           d.parameters[d.sensitivities[dir]].name);
  return d.start.dx_dp.data() + static_cast<size_t>(c - cols.begin()) * d.num_states;
}

}  // namespace

void Evaluator::initial_state_tangent(double t0, const double* x0, DirView dx0) {
  for (int dir = 0; dir < ns_; ++dir)
    std::fill(dx0.data + dir * dx0.ld, dx0.data + dir * dx0.ld + d_.num_states, 0.0);
  if (ns_ == 0) return;
  if (!d_.start.x.empty()) {  // its dx0/dp, the column of each direction
    const int nx = d_.num_states;
    for (int dir = 0; dir < ns_; ++dir) {
      const double* from = start_derivative(d_, dir);
      std::copy(from, from + nx, dx0.data + dir * dx0.ld);
    }
    return;
  }
  dsig_.assign(static_cast<size_t>(d_.num_signals) * ns_, 0.0);
  for (size_t i = 0; i < d_.nodes.size(); ++i) {
    const Node& n = d_.nodes[i];
    if (n.block->num_states() == 0) continue;
    const Seeds s = seeds_for(n, static_cast<int>(i), ns_, {}, true);
    n.block->initial_state_tangent(eval_for(n, static_cast<int>(i), t0, x0), s,
                                   {dx0.data + n.state_offset, dx0.ld});
  }
}

void Evaluator::outputs(double t, const double* x) {
  const int nx = d_.num_states;
  if (valid_ && t == last_t_ && (nx == 0 || std::memcmp(x, last_x_.data(), nx * sizeof(double)) == 0))
    return;
  valid_ = false;  // until every block has written its outputs: a block that refuses the point
                   // leaves the signals half new, which must not pass for the last point's
  for (const OutputStep& step : d_.output_steps) {
    const int i = step.node;
    const Node& n = d_.nodes[i];
    // Sources (no inputs, no states) depend on time alone: the Newton iterations of a step
    // evaluate them at the same time again and again.
    if (time_only_[i] && source_valid_[i] && source_t_[i] == t && source_segment_[i] == segment_start_)
      continue;
    for (size_t k = 0; k < n.output_offset.size(); ++k) y_[k] = sig_.data() + n.output_offset[k];
    Eval e = eval_for(n, i, t, x);
    e.ready = step.ready.data();
    e.inputs_ready = step.inputs_ready;
    call_block(n, [&] { n.block->outputs(e, y_.data()); });
    if (time_only_[i]) source_valid_[i] = true, source_t_[i] = t, source_segment_[i] = segment_start_;
    for (const auto& [offset, value] : held_values_)
      for (int k : step.outputs)
        if (offset >= n.output_offset[k] && offset < n.output_offset[k] + n.block->outputs()[k].width) sig_[offset] = value;
  }
  valid_ = true;
  ++value_pass_;
  last_t_ = t;
  if (nx) std::memcpy(last_x_.data(), x, nx * sizeof(double));
}

void Evaluator::derivatives(double t, const double* x, double* xdot) {
  outputs(t, x);
  for (size_t i = 0; i < d_.nodes.size(); ++i) {
    const Node& n = d_.nodes[i];
    if (n.block->num_states() == 0) continue;
    call_block(n, [&] { n.block->derivatives(eval_for(n, static_cast<int>(i), t, x), xdot + n.state_offset); });
  }
}

void Evaluator::quadratures(double t, const double* x, double* qdot) {
  outputs(t, x);
  for (size_t i = 0; i < d_.nodes.size(); ++i) {
    const Node& n = d_.nodes[i];
    if (n.block->num_quadratures() == 0) continue;
    call_block(n, [&] { n.block->quadratures(eval_for(n, static_cast<int>(i), t, x), qdot + n.quad_offset); });
  }
}

void Evaluator::tangents(double t, const double* x, int nd, ConstDirView dx, bool with_params,
                         DirView dxdot, DirView dqdot) {
  outputs(t, x);
  const int ld = d_.num_signals;
  dsig_.resize(static_cast<size_t>(ld) * nd);
  // Tangents are linear in the seeds: the outputs of a step whose seeds are all zero (no state
  // seeds, no parameter seeds, the inputs they read from outputs with zero tangents) have zero
  // tangents, and the block is not called. Sources in a Jacobian pass are the common case.
  for (const OutputStep& step : d_.output_steps) {
    const int i = step.node;
    const Node& n = d_.nodes[i];
    const Seeds s = seeds_for(n, i, nd, dx, with_params);
    bool zero = s.x.zero() && s.p.zero();
    for (int k : step.reads) zero = zero && zero_tangent_[n.input_source[k]];
    for (size_t k = 0; k < n.output_offset.size(); ++k) dy_[k] = {dsig_.data() + n.output_offset[k], ld};
    for (int k : step.outputs) zero_tangent_[n.output_offset[k]] = zero;
    if (zero) {
      const auto& ports = n.block->outputs();
      for (int k : step.outputs)
        for (int d = 0; d < nd; ++d) std::fill_n(dy_[k].data + d * ld, ports[k].width, 0.0);
    } else {
      Eval e = eval_for(n, i, t, x);
      e.ready = step.ready.data();
      e.inputs_ready = step.inputs_ready;
      call_block(n, [&] { n.block->outputs_tangent(e, s, dy_.data()); });
    }
    if (num_seeded_ > 0) seed_signals(n, step, nd);
  }
  for (size_t i = 0; i < d_.nodes.size(); ++i) {
    const Node& n = d_.nodes[i];
    const bool states = dxdot.data && n.block->num_states() > 0;
    const bool quads = dqdot.data && n.block->num_quadratures() > 0;
    if (!states && !quads) continue;
    const int idx = static_cast<int>(i);
    const Eval e = eval_for(n, idx, t, x);
    const Seeds s = seeds_for(n, idx, nd, dx, with_params);
    call_block(n, [&] {
      if (states) n.block->derivatives_tangent(e, s, {dxdot.data + n.state_offset, dxdot.ld});
      if (quads) n.block->quadratures_tangent(e, s, {dqdot.data + n.quad_offset, dqdot.ld});
    });
  }
}

Adjoint Evaluator::adjoint_for(const Node& n, int index, int nm, DirView ax, DirView ap) {
  const int ld = d_.num_signals;
  for (size_t k = 0; k < n.input_source.size(); ++k) ubar_[k] = {sbar_.data() + n.input_source[k], ld};
  Adjoint a;
  a.directions = nm;
  if (ax.data && n.block->num_states() > 0) a.x = {ax.data + n.state_offset, ax.ld};
  a.u = ubar_.data();
  if (ap.data && driven_[index]) {
    a.p_columns = ns_;
    a.p_seeds = {pseed_.data() + pseed_offset_[index], static_cast<int>(n.p.size())};
    a.p = ap;
  }
  return a;
}

const LocalJacobian& Evaluator::kept_jacobian(KeptJacobian& kept, const Node& n, int index, BlockFunction fn,
                                              const Eval& e) {
  if (kept.pass != value_pass_) {
    const std::vector<bool> all_inputs(n.block->inputs().size(), true);
    const ConstDirView p_seeds{pseed_.data() + pseed_offset_[index], static_cast<int>(n.p.size())};
    kept.J = local_jacobian(*n.block, fn, e, true, all_inputs, driven_[index] ? ns_ : 0, p_seeds);
    kept.pass = value_pass_;
  }
  return kept.J;
}

namespace {

/// Whether rows [first, first + rows) of a weight view are zero in all nm directions.
bool zero_weights(ConstDirView w, int first, int rows, int nm) {
  if (w.zero()) return true;
  for (int m = 0; m < nm; ++m)
    for (int r = 0; r < rows; ++r)
      if (w.data[m * w.ld + first + r] != 0.0) return false;
  return true;
}

}  // namespace

void Evaluator::adjoint(double t, const double* x, int nm, ConstDirView lambda, ConstDirView wq, DirView ax,
                        DirView ap) {
  outputs(t, x);
  const int ld = d_.num_signals;
  sbar_.assign(static_cast<size_t>(ld) * nm, 0.0);
  // The states' and integrals' readers first: they read signals the output steps computed.
  for (size_t i = 0; i < d_.nodes.size(); ++i) {
    const Node& n = d_.nodes[i];
    const int nx = n.block->num_states(), nq = n.block->num_quadratures();
    const bool states = nx > 0 && !zero_weights(lambda, n.state_offset, nx, nm);
    const bool quads = nq > 0 && !zero_weights(wq, n.quad_offset, nq, nm);
    if (!states && !quads) continue;
    const int idx = static_cast<int>(i);
    const Eval e = eval_for(n, idx, t, x);
    const Adjoint a = adjoint_for(n, idx, nm, ax, ap);
    const ConstDirView wx{states ? lambda.data + n.state_offset : nullptr, lambda.ld};
    const ConstDirView wqn{quads ? wq.data + n.quad_offset : nullptr, wq.ld};
    call_block(n, [&] {
      if (!n.block->adjoint_from_tangent()) {
        if (states) n.block->derivatives_adjoint(e, wx, a);
        if (quads) n.block->quadratures_adjoint(e, wqn, a);
        return;
      }
      if (states)
        add_transpose_product(*n.block, kept_jacobian(kept_derivatives_[i], n, idx, BlockFunction::derivatives, e),
                              [&](int r, int m) { return wx(r, m); }, a);
      if (quads)
        add_transpose_product(*n.block, kept_jacobian(kept_quadratures_[i], n, idx, BlockFunction::quadratures, e),
                              [&](int r, int m) { return wqn(r, m); }, a);
    });
  }
  // Then the output steps backwards: every reader of a step's outputs comes after it in the
  // forward order, so their adjoints are complete when the step is reached.
  for (auto step = d_.output_steps.rbegin(); step != d_.output_steps.rend(); ++step) {
    const int i = step->node;
    const Node& n = d_.nodes[i];
    const auto& ports = n.block->outputs();
    bool any = false;
    for (size_t k = 0; k < ports.size(); ++k) wy_[k] = {};
    for (int k : step->outputs) {
      const int offset = n.output_offset[k];
      if (num_seeded_ > 0)  // a cut wire: its adjoint stops here
        for (int w = 0; w < ports[k].width; ++w)
          if (seeded_[offset + w] >= 0)
            for (int m = 0; m < nm; ++m) sbar_[static_cast<size_t>(m) * ld + offset + w] = 0.0;
      if (zero_weights({sbar_.data(), ld}, offset, ports[k].width, nm)) continue;
      wy_[k] = {sbar_.data() + offset, ld};
      any = true;
    }
    if (!any) continue;
    Eval e = eval_for(n, i, t, x);
    e.ready = step->ready.data();
    e.inputs_ready = step->inputs_ready;
    const Adjoint a = adjoint_for(n, i, nm, ax, ap);
    const size_t at = static_cast<size_t>(d_.output_steps.rend() - step - 1);
    call_block(n, [&] {
      if (!n.block->adjoint_from_tangent()) return n.block->outputs_adjoint(e, wy_.data(), a);
      add_transpose_product(*n.block, kept_jacobian(kept_outputs_[at], n, i, BlockFunction::outputs, e),
                            output_weights(*n.block, wy_.data()), a);
    });
  }
}

void Evaluator::initial_state_adjoint(double t0, const double* x0, int nm, ConstDirView w, DirView ap) {
  if (ns_ == 0 || w.zero() || !ap.data) return;
  if (!d_.start.x.empty()) {  // a start given from outside: w^T of its dx0/dp columns
    const int nx = d_.num_states;
    for (int dir = 0; dir < ns_; ++dir) {
      const double* column = start_derivative(d_, dir);
      for (int m = 0; m < nm; ++m) {
        double sum = 0.0;
        for (int i = 0; i < nx; ++i) sum += w.data[m * w.ld + i] * column[i];
        ap.data[m * ap.ld + dir] += sum;
      }
    }
    return;
  }
  sbar_.assign(static_cast<size_t>(d_.num_signals) * nm, 0.0);
  for (size_t i = 0; i < d_.nodes.size(); ++i) {
    const Node& n = d_.nodes[i];
    const int nx = n.block->num_states();
    if (nx == 0 || !driven_[i] || zero_weights(w, n.state_offset, nx, nm)) continue;
    const int idx = static_cast<int>(i);
    const Adjoint a = adjoint_for(n, idx, nm, {}, ap);
    n.block->initial_state_adjoint(eval_for(n, idx, t0, x0), {w.data + n.state_offset, w.ld}, a);
  }
}

void Evaluator::hold_signals(std::vector<std::pair<int, double>> values) {
  held_values_ = std::move(values);
  valid_ = false;
  std::fill(source_valid_.begin(), source_valid_.end(), false);
}

void Evaluator::set_signal_seeds(std::vector<int> offsets, std::vector<double> seeds) {
  seeded_.assign(d_.num_signals, -1);
  num_seeded_ = static_cast<int>(offsets.size());
  for (int j = 0; j < num_seeded_; ++j) seeded_.at(offsets[j]) = j;
  signal_seeds_ = std::move(seeds);
}

void Evaluator::seed_signals(const Node& n, const OutputStep& step, int nd) {
  const int ld = d_.num_signals;
  if (signal_seeds_.size() != static_cast<size_t>(num_seeded_) * nd)
    throw std::logic_error("Evaluator: signal seeds for another number of directions");
  const auto& ports = n.block->outputs();
  for (int k : step.outputs) {
    const int offset = n.output_offset[k];
    for (int w = 0; w < ports[k].width; ++w) {
      const int j = seeded_[offset + w];
      if (j < 0) continue;
      zero_tangent_[offset] = false;
      for (int d = 0; d < nd; ++d) dsig_[static_cast<size_t>(d) * ld + offset + w] = signal_seeds_[d * num_seeded_ + j];
    }
  }
}

bool Evaluator::local_jacobians(double t, const double* x, double* jac, int ld) {
  outputs(t, x);
  local_ranges_.clear();
  local_nodes_.clear();
  for (size_t i = 0; i < d_.nodes.size(); ++i) {
    const Node& n = d_.nodes[i];
    if (n.block->num_states() == 0) continue;
    const Eval e = eval_for(n, static_cast<int>(i), t, x);
    double* block = jac + static_cast<size_t>(n.state_offset) * ld + n.state_offset;
    bool provided = false;
    call_block(n, [&] { provided = n.block->local_jacobian(e, {block, ld}); });
    if (!provided) continue;
    local_ranges_.push_back({n.state_offset, n.block->num_states()});
    local_nodes_.push_back(static_cast<int>(i));
  }
  return !local_nodes_.empty();
}

void Evaluator::local_derivatives(double t, const double* x, double* xdot) {
  for (int i : local_nodes_) {
    const Node& n = d_.nodes[i];
    call_block(n, [&] { n.block->derivatives(eval_for(n, i, t, x), xdot + n.state_offset); });
  }
}

void Evaluator::local_jacobians_held(double t, const double* x, double* jac, int ld) {
  for (int i : local_nodes_) {
    const Node& n = d_.nodes[i];
    double* block = jac + static_cast<size_t>(n.state_offset) * ld + n.state_offset;
    call_block(n, [&] { n.block->local_jacobian(eval_for(n, i, t, x), {block, ld}); });
  }
}

void Evaluator::local_derivatives_tangent(double t, const double* x, int nd, ConstDirView dx, bool with_params,
                                          DirView dxdot) {
  for (int i : local_nodes_) {
    const Node& n = d_.nodes[i];
    const Eval e = eval_for(n, i, t, x);
    const Seeds s = seeds_for(n, i, nd, dx, with_params);
    call_block(n, [&] { n.block->derivatives_tangent(e, s, {dxdot.data + n.state_offset, dxdot.ld}); });
  }
}

bool Evaluator::all_finite(const double* xdot) const {
  // One sum decides the common case; an overflow to inf merely sends us to the full scan.
  double sum = 0.0;
  for (double v : sig_) sum += v * 0.0;
  for (int i = 0; i < d_.num_states; ++i) sum += xdot[i] * 0.0;
  return sum == 0.0;
}

std::string Evaluator::find_nonfinite(const double* xdot) const {
  for (const Node& n : d_.nodes) {
    const auto& ports = n.block->outputs();
    for (size_t k = 0; k < ports.size(); ++k)
      for (int c = 0; c < ports[k].width; ++c)
        if (!std::isfinite(sig_[n.output_offset[k] + c]))
          return n.name + ": output " + ports[k].name + " is not finite";
    if (xdot)
      for (int c = 0; c < n.block->num_states(); ++c)
        if (!std::isfinite(xdot[n.state_offset + c]))
          return n.name + ": derivative of state " + n.block->state_names()[c] + " is not finite";
  }
  return {};
}

}  // namespace dydp::engine
