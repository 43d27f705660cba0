#include "engine/analysis/step_driver.hpp"

#include <algorithm>

#include "engine/analysis/cpu_clock.hpp"
#include "engine/analysis/recorder.hpp"
#include "engine/analysis/timeline.hpp"

namespace dydp::engine {

void Stepper::prepare_record(const MarchState& s, Evaluator& ev, int ns) {
  if (ns > 0) ev.tangents(s.t, s.x.data(), ns, {s.S.data(), static_cast<int>(s.x.size())}, true, {}, {});
  else ev.outputs(s.t, s.x.data());
}

void FixedStepper::advance(MarchState& s, double target) {
  const double t = s.t;
  const long n = fixed_steps(t, target, h_max_);
  const double h = (target - t) / n;
  for (long k = 0; k < n; ++k) {
    s.t = t + k * h;
    step(s, h);
  }
}

double scene_fixed_step(const Diagram& d) { return d.solver.step > 0 ? d.solver.step : d.time.output_step / 10.0; }

RunResult march(const Diagram& d, const RunOptions& options, const std::string& method, const StepperFactory& make) {
  const int nx = d.num_states, nq = d.num_quadratures;
  const int ns = options.sensitivities ? static_cast<int>(d.sensitivities.size()) : 0;
  const double t0 = d.time.start;

  Evaluator ev(d, ns > 0);
  RunResult result;
  Recorder recorder(d, ns, result, options);
  RunStats& st = result.stats;
  const CpuClock clock;
  const std::unique_ptr<Stepper> stepper = make(ev, ns, st);

  MarchState s;
  s.t = t0;
  s.x.setZero(std::max(nx, 1));
  ev.set_segment_start(t0);
  ev.initial_state(t0, s.x.data());
  s.x.conservativeResize(nx);
  s.q.setZero(std::max(nq, 1));
  s.S.setZero(nx, ns);
  s.Sq.setZero(std::max(nq, 1), ns);
  if (ns > 0) ev.initial_state_tangent(t0, s.x.data(), {s.S.data(), nx});
  stepper->begin(s);

  auto record = [&] {
    stepper->prepare_record(s, ev, ns);
    recorder.record(s.t, s.x.data(), ev);
  };
  record();

  const Timeline timeline(d);
  for (double target : timeline.events) {
    stepper->advance(s, target);
    s.t = target;
    if (timeline.is_output(target)) record();
    if (timeline.is_break(target)) {
      ev.set_segment_start(target);
      stepper->begin(s);
    }
  }
  recorder.finish(s.q.data(), {s.Sq.data(), static_cast<int>(s.Sq.rows())});
  result.final_state.assign(s.x.data(), s.x.data() + nx);

  st.step = stepper->reported_step();
  finish_stats(st, method, clock.seconds(), d.time);
  return result;
}

}  // namespace dydp::engine
