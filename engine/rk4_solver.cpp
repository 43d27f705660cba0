#include "engine/rk4_solver.hpp"

#include <algorithm>
#include <cmath>

#include "engine/cpu_clock.hpp"
#include "engine/errors.hpp"
#include "engine/timeline.hpp"
#include "engine/recorder.hpp"

namespace dydp::engine {
namespace {

/// States, quadratures and their sensitivities, advanced together stage by stage.
struct Rk4State {
  std::vector<double> x, q, dx, dq;  // dx: d-major, ld nx; dq: d-major, ld nq
};

}  // namespace

RunResult run_rk4(const Diagram& d, const RunOptions& options) {
  const int nx = d.num_states, nq = d.num_quadratures;
  const int ns = options.sensitivities ? static_cast<int>(d.sensitivities.size()) : 0;
  const double t0 = d.time.start;
  const double h_max = d.solver.step > 0 ? d.solver.step : d.time.output_step / 10.0;

  Evaluator ev(d, ns > 0);
  RunResult result;
  Recorder recorder(d, ns, result, options);
  RunStats& st = result.stats;
  const CpuClock clock;

  Rk4State s;
  s.x.assign(std::max(nx, 1), 0.0);
  s.q.assign(std::max(nq, 1), 0.0);
  s.dx.assign(static_cast<size_t>(nx) * ns, 0.0);
  s.dq.assign(static_cast<size_t>(nq) * ns, 0.0);
  ev.set_segment_start(t0);
  ev.initial_state(t0, s.x.data());
  if (ns > 0) ev.initial_state_tangent(t0, s.x.data(), {s.dx.data(), nx});

  // k = f(t, x), dk = f_x dx + f_p: one value and one tangent pass per stage.
  std::vector<double> kx[4], kq[4], kdx[4], kdq[4];
  for (int i = 0; i < 4; ++i) {
    kx[i].assign(std::max(nx, 1), 0.0);
    kq[i].assign(std::max(nq, 1), 0.0);
    kdx[i].assign(s.dx.size(), 0.0);
    kdq[i].assign(s.dq.size(), 0.0);
  }
  Rk4State stage = s;
  auto evaluate = [&](double t, const Rk4State& at, int i) {
    try {
      ev.derivatives(t, at.x.data(), kx[i].data());
      if (nq > 0) ev.quadratures(t, at.x.data(), kq[i].data());
      ++st.rhs_evals;
      const std::string bad = ev.find_nonfinite(kx[i].data());
      if (!bad.empty())
        throw SolverError(t, bad.substr(0, bad.find(':')),
                          bad.substr(bad.find(':') + 2) + " (rk4 step " + std::to_string(h_max) +
                              " s: unstable or too large for this scene?)");
      if (ns > 0) {
        ev.tangents(t, at.x.data(), ns, {at.dx.data(), nx}, true, {kdx[i].data(), nx},
                    {kdq[i].data(), nq});
        ++st.sens_rhs_evals;
      }
    } catch (const OutOfDomain& e) {
      throw domain_failure(t, e);
    }
  };
  auto axpy = [](std::vector<double>& out, const std::vector<double>& base, double a,
                 const std::vector<double>& k) {
    for (size_t i = 0; i < out.size(); ++i) out[i] = base[i] + a * k[i];
  };

  auto record = [&](double t) {
    if (ns > 0) ev.tangents(t, s.x.data(), ns, {s.dx.data(), nx}, true, {}, {});
    else ev.outputs(t, s.x.data());
    recorder.record(t, s.x.data(), ev);
  };
  record(t0);

  const Timeline timeline(d);

  double t = t0;
  for (double target : timeline.events) {
    const long n = fixed_steps(t, target, h_max);
    const double h = (target - t) / n;
    for (long step = 0; step < n; ++step) {
      const double tn = t + step * h;
      evaluate(tn, s, 0);
      axpy(stage.x, s.x, h / 2, kx[0]);
      axpy(stage.dx, s.dx, h / 2, kdx[0]);
      evaluate(tn + h / 2, stage, 1);
      axpy(stage.x, s.x, h / 2, kx[1]);
      axpy(stage.dx, s.dx, h / 2, kdx[1]);
      evaluate(tn + h / 2, stage, 2);
      axpy(stage.x, s.x, h, kx[2]);
      axpy(stage.dx, s.dx, h, kdx[2]);
      evaluate(tn + h, stage, 3);
      auto combine = [h](std::vector<double>& y, const std::vector<double>* k) {
        for (size_t i = 0; i < y.size(); ++i)
          y[i] += h / 6 * (k[0][i] + 2 * k[1][i] + 2 * k[2][i] + k[3][i]);
      };
      combine(s.x, kx);
      combine(s.q, kq);
      combine(s.dx, kdx);
      combine(s.dq, kdq);
      ++st.steps;
    }
    t = target;
    if (timeline.is_output(target)) record(target);
    if (timeline.is_break(target)) ev.set_segment_start(target);
  }
  recorder.finish(s.q.data(), {s.dq.data(), std::max(nq, 1)});
  result.final_state.assign(s.x.begin(), s.x.begin() + nx);

  st.step = h_max;
  finish_stats(st, "rk4", clock.seconds(), d.time);
  return result;
}

}  // namespace dydp::engine
