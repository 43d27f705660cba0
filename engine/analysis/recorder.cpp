#include "engine/analysis/recorder.hpp"

#include <cmath>

#include "engine/framework/errors.hpp"

namespace dydp::engine {

Recorder::Recorder(const Diagram& d, int directions, RunResult& result, const RunOptions& options)
    : d_(d), ns_(directions), result_(result), options_(options), samples_(d.objectives.size()) {
  for (const LoggedSignal& s : d.logged) result_.signal_names.push_back(s.name);
  for (int dir = 0; dir < ns_; ++dir)
    result_.sensitivity_names.push_back(d.parameters[d.sensitivities[dir]].name);
}

void Recorder::record(double t, const double* x, Evaluator& ev) {
  for (int i = 0; i < d_.num_states; ++i)
    if (!std::isfinite(x[i])) {
      for (const Node& n : d_.nodes)
        if (i >= n.state_offset && i < n.state_offset + n.block->num_states())
          throw SolverError(t, n.name, "state " + n.block->state_names()[i - n.state_offset] +
                                           " is not finite");
    }
  const std::string bad = ev.find_nonfinite(nullptr);
  if (!bad.empty()) throw SolverError(t, bad.substr(0, bad.find(':')), bad.substr(bad.find(':') + 2));

  const auto& sig = ev.signals();
  const auto& dsig = ev.signal_tangents();
  const int nsig = d_.num_signals;
  // Sensitivities that overflowed (an unstable explicit step on a stiff scene) stop the run too.
  for (const LoggedSignal& s : d_.logged)
    for (int dir = 0; dir < ns_; ++dir)
      if (!std::isfinite(dsig[dir * nsig + s.offset]))
        throw SolverError(t, s.name.substr(0, s.name.find('.')),
                          "sensitivity of " + s.name + " is not finite: the sensitivities diverged (step too large for "
                          "a stiff scene?)");
  result_.t.push_back(t);
  for (const LoggedSignal& s : d_.logged) result_.values.push_back(sig[s.offset]);
  for (int dir = 0; dir < ns_; ++dir)
    for (const LoggedSignal& s : d_.logged) result_.tangents.push_back(dsig[dir * nsig + s.offset]);

  for (size_t o = 0; o < d_.objectives.size(); ++o) {
    const Node& n = d_.nodes[d_.objectives[o]];
    if (!n.objective->needs_samples()) continue;
    const int src = n.input_source[0];
    const int w = n.block->inputs()[0].width;
    Sampled& s = samples_[o];
    s.t.push_back(t);
    for (int c = 0; c < w; ++c) s.u.push_back(sig[src + c]);
    for (int dir = 0; dir < ns_; ++dir)
      for (int c = 0; c < w; ++c) s.du.push_back(dsig[dir * nsig + src + c]);
  }
  if (options_.on_sample) options_.on_sample(result_);
  if (options_.progress) options_.progress(t);
}

void Recorder::finish(const double* q, ConstDirView dq) {
  for (size_t o = 0; o < d_.objectives.size(); ++o) {
    const Node& n = d_.nodes[d_.objectives[o]];
    ObjectiveSamples s;
    s.t_start = d_.time.start;
    s.t_stop = d_.time.stop;
    s.directions = ns_;
    s.width = n.block->inputs().empty() ? 0 : n.block->inputs()[0].width;
    s.t = &samples_[o].t;
    s.u = &samples_[o].u;
    s.du = &samples_[o].du;
    ObjectiveResult r;
    r.name = n.name;
    r.unit = d_.objective_unit(n);
    r.sensitivity.assign(ns_, 0.0);
    const ConstDirView dq_node = dq.zero() ? ConstDirView{} : ConstDirView{dq.data + n.quad_offset, dq.ld};
    r.value = n.objective->objective(n.p.data(), q + n.quad_offset, dq_node, s, r.sensitivity.data());
    if (!std::isfinite(r.value))
      throw SolverError(d_.time.stop, n.name, "objective value is not finite");
    for (size_t k = 0; k < r.sensitivity.size(); ++k)
      if (!std::isfinite(r.sensitivity[k]))
        throw SolverError(d_.time.stop, n.name, "objective sensitivity is not finite (direction " + std::to_string(k) +
                                                    "): the sensitivities diverged; a smaller step or an implicit method?");
    result_.objectives.push_back(std::move(r));
  }
}

}  // namespace dydp::engine
