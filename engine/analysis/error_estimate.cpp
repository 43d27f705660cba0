#include "engine/analysis/error_estimate.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <sstream>
#include <thread>

#include "engine/analysis/run.hpp"
#include "engine/framework/errors.hpp"

namespace dydp::engine {
namespace {

/// Order of a fixed-step scheme, 0 for an error-controlled one.
int fixed_order(const SolverSpec& s) {
  if (s.method == "rk4") return 4;
  if (s.method == "sdirk2") return 2;
  if (s.method == "rosw" && s.step > 0) return 2;
  return 0;
}

std::string percent(double e) {
  std::ostringstream out;
  out.precision(2);
  out << 100 * e << " %";
  return out.str();
}

}  // namespace

ShadowPlan shadow_plan(const SolverSpec& solver, const TimeSpec& time) {
  ShadowPlan plan;
  plan.solver = solver;
  const int order = fixed_order(solver);
  if (order > 0) {
    const double asked = solver.step > 0 ? solver.step : time.output_step / 10.0;
    // The step the run takes: each output interval in the fewest equal steps of at most the
    // one asked (a step above the output step is the output step).
    const double step = time.output_step / std::max(1.0, std::ceil(time.output_step / asked - 1e-9));
    // Half the step, not twice: a fixed step already near its limit (a damper's valve it can
    // barely follow) would fail at twice the step and leave the run without an estimate.
    plan.solver.step = step / 2;
    plan.divisor = (std::pow(2.0, order) - 1) / std::pow(2.0, order);
    plan.how = "shadow run at half the step (order " + std::to_string(order) + ")";
  } else {
    plan.solver.rtol = std::min(0.5, 4 * solver.rtol);
    plan.solver.atol = std::min(0.5, 4 * solver.atol);
    plan.divisor = 3.0;
    plan.how = "shadow run at 4 x rtol and atol";
  }
  return plan;
}

void estimate_from_shadow(RunResult& run, const RunResult& shadow, const ShadowPlan& plan) {
  ErrorEstimate& e = run.stats.error_estimate;
  const int nsig = run.num_signals();
  // an adjoint run's signals carry no sensitivities (its directions are the objectives' gradients')
  const int ns = run.signal_sensitivities ? static_cast<int>(run.sensitivity_names.size()) : 0;
  const int shadow_ns = shadow.signal_sensitivities ? static_cast<int>(shadow.sensitivity_names.size()) : 0;
  const size_t nt = std::min(run.t.size(), shadow.t.size());
  if (shadow.num_signals() != nsig || shadow_ns != ns || nt == 0) return;
  // column c: -1 the signal i itself, else direction c of signal i
  auto column = [&](const RunResult& r, size_t k, int d, int i) { return d < 0 ? r.value(k, i) : r.tangent(k, d, i); };
  e = ErrorEstimate{};
  for (int d = -1; d < ns; ++d)
    for (int i = 0; i < nsig; ++i) {
      double scale = 0.0, worst = 0.0;
      for (size_t k = 0; k < nt; ++k) {
        const double a = column(run, k, d, i);
        scale = std::max(scale, std::fabs(a));
        worst = std::max(worst, std::fabs(a - column(shadow, k, d, i)));
      }
      if (!(scale > 1e-12)) continue;
      const double err = worst / scale / plan.divisor;
      const std::string name =
          d < 0 ? run.signal_names[i] : "d(" + run.signal_names[i] + ")/d(" + run.sensitivity_names[d] + ")";
      double& slot = d < 0 ? e.signal_error : e.sensitivity_error;
      std::string& where = d < 0 ? e.worst_signal : e.worst_sensitivity;
      if (!(err <= slot)) {  // NaN as well
        slot = err;
        where = name;
      }
    }
  e.estimated = true;
  e.how = plan.how;
  e.cpu_seconds = shadow.stats.cpu_seconds;
  if (e.signal_error > kSignalTarget)
    run.stats.warnings.push_back("estimated error " + percent(e.signal_error) + " in " + e.worst_signal +
                                 " is above the 1 % target: tighten --rtol/--atol or take a smaller --step");
  if (ns > 0 && e.sensitivity_error > kSensitivityTarget)
    run.stats.warnings.push_back("estimated error " + percent(e.sensitivity_error) + " in " + e.worst_sensitivity +
                                 " is above the 5 % target: tighten --rtol/--atol or take a smaller --step");
}

RunResult run_with_error_estimate(const Diagram& d, Diagram& shadow, const RunOptions& options) {
  const ShadowPlan plan = shadow_plan(d.solver, d.time);
  shadow.solver = plan.solver;
  // The same start as the run (`initial: equilibrium`: the same scene, the same parameters).
  if (shadow.start.x.empty()) shadow.start = d.start;
  RunOptions quiet;
  quiet.sensitivities = options.sensitivities && !options.adjoint;  // adjoint: the signals alone
  quiet.difference_quotient_sensitivities = options.difference_quotient_sensitivities;
  RunResult shadow_result;
  std::string shadow_failure;
  std::thread second([&] {
    try {
      shadow_result = run(shadow, quiet);
    } catch (const std::exception& e) {
      shadow_failure = e.what();
    }
  });
  RunResult r;
  try {
    r = run(d, options);
  } catch (...) {
    second.join();
    throw;
  }
  second.join();
  if (shadow_failure.empty()) estimate_from_shadow(r, shadow_result, plan);
  else r.stats.warnings.push_back("no error estimate: its shadow run (" + plan.how + ") failed: " + shadow_failure);
  return r;
}

}  // namespace dydp::engine
