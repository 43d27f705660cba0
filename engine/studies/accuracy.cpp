#include "engine/studies/accuracy.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/analysis/run.hpp"
#include "engine/framework/errors.hpp"
#include "engine/studies/initial_equilibrium.hpp"

namespace dydp::engine {
namespace {

/// |a - b| / scale; infinite when a is not finite (so that a NaN never reads as "no error").
double rel(double a, double b, double scale) {
  const double e = std::fabs(a - b) / std::max(scale, 1e-300);
  return std::isfinite(e) ? e : std::numeric_limits<double>::infinity();
}

/// Fills the error fields of row from run r against the reference.
void measure(const RunResult& r, const RunResult& ref, AccuracyRow& row) {
  const int nsig = ref.num_signals(), ns = static_cast<int>(ref.sensitivity_names.size());
  const int nt = static_cast<int>(std::min(r.t.size(), ref.t.size()));
  for (int i = 0; i < nsig; ++i) {
    double scale = 0;
    for (int k = 0; k < nt; ++k) scale = std::max(scale, std::fabs(ref.value(k, i)));
    for (int k = 0; k < nt; ++k) row.signal_error = std::max(row.signal_error, rel(r.value(k, i), ref.value(k, i), scale));
    for (int d = 0; d < ns; ++d) {
      double dscale = 0;
      for (int k = 0; k < nt; ++k) dscale = std::max(dscale, std::fabs(ref.tangent(k, d, i)));
      for (int k = 0; k < nt; ++k)
        row.signal_sensitivity_error =
            std::max(row.signal_sensitivity_error, rel(r.tangent(k, d, i), ref.tangent(k, d, i), dscale));
    }
  }
  for (size_t o = 0; o < ref.objectives.size(); ++o) {
    const auto &a = r.objectives[o], &b = ref.objectives[o];
    row.objective_error = std::max(row.objective_error, rel(a.value, b.value, std::fabs(b.value)));
    for (int d = 0; d < ns; ++d)
      row.sensitivity_error = std::max(row.sensitivity_error,
                                       rel(a.sensitivity[d], b.sensitivity[d], std::fabs(b.sensitivity[d])));
  }
}

}  // namespace

AccuracyReport accuracy_study(Diagram& d, const AccuracySpec& spec,
                              const std::function<void(const AccuracyRow&)>& progress) {
  const SolverSpec saved = d.solver;
  const double atol_ratio = saved.atol / saved.rtol;
  // The reference and the ladder at each method's own highest order (a scene's max_order, set
  // for its tolerance, would slow a reference at rtol 1e-10 many times); the given setting keeps it.
  auto set_cvodes = [&](const std::string& method, double rtol) {
    d.solver = saved;
    d.solver.method = method;
    d.solver.rtol = rtol;
    d.solver.atol = rtol * atol_ratio;
    d.solver.max_order = 0;
  };

  AccuracyReport report;
  report.reference_rtol = spec.reference_rtol;
  set_cvodes("bdf", spec.reference_rtol);
  const RunResult ref = run_from_initial(d);
  report.reference_stats = ref.stats;
  set_cvodes("bdf", spec.reference_rtol / 10);
  {
    AccuracyRow check;
    measure(run_from_initial(d), ref, check);
    report.reference_check = std::max({check.signal_error, check.objective_error,
                                       check.sensitivity_error, check.signal_sensitivity_error});
  }

  auto attempt = [&](const std::string& method, double setting) {
    AccuracyRow row;
    row.method = method;
    row.setting = setting;
    try {
      const RunResult r = run_from_initial(d);
      row.stats = r.stats;
      measure(r, ref, row);
      row.ok = true;
    } catch (const SolverError& e) {
      row.failure = e.what();
    }
    if (progress) progress(row);
    report.rows.push_back(row);
  };
  for (const std::string& method : spec.methods) {
    if (method == "bdf" || method == "adams") {
      for (double rtol : spec.rtols) {
        set_cvodes(method, rtol);
        attempt(method, rtol);
      }
    } else {
      for (double f : spec.step_fractions) {
        d.solver = saved;
        d.solver.method = method;
        d.solver.step = f * d.time.output_step;
        attempt(method, d.solver.step);
      }
    }
  }
  if (spec.given_setting) {
    d.solver = saved;
    const bool cvodes = saved.method == "bdf" || saved.method == "adams";
    const std::string order = cvodes && saved.max_order > 0 ? " order <= " + std::to_string(saved.max_order) : "";
    attempt(saved.method + order + " (given)", cvodes ? saved.rtol : (saved.step > 0 ? saved.step : d.time.output_step / 10));
  }
  d.solver = saved;
  return report;
}

const AccuracyRow* cheapest_for(const AccuracyReport& r, double target) {
  const AccuracyRow* best = nullptr;
  for (const AccuracyRow& row : r.rows) {
    if (!row.ok) continue;
    const double err = std::max({row.signal_error, row.objective_error, row.sensitivity_error});
    if (err <= target && (!best || row.stats.cpu_seconds < best->stats.cpu_seconds)) best = &row;
  }
  return best;
}

}  // namespace dydp::engine
