// The times a run must stop at: the output grid t0, t0 + h, ..., stop, and the blocks'
// breakpoints, merged; what the solvers march over.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "engine/analysis/run_result.hpp"
#include "engine/framework/diagram.hpp"

namespace dydp::engine {

/// t0, t0 + h, ..., stop (the last point is stop exactly).
inline std::vector<double> output_grid(const TimeSpec& time) {
  const double span = time.stop - time.start;
  const long n = std::max(1L, std::lround(std::ceil(span / time.output_step - 1e-9)));
  std::vector<double> t(n + 1);
  for (long k = 0; k <= n; ++k) t[k] = std::min(time.start + k * time.output_step, time.stop);
  t[n] = time.stop;
  return t;
}

struct Timeline {
  explicit Timeline(const Diagram& d)
      : outputs(output_grid(d.time)), breaks(d.breakpoints(d.time.start, d.time.stop)) {
    events.assign(outputs.begin() + 1, outputs.end());
    events.insert(events.end(), breaks.begin(), breaks.end());
    std::sort(events.begin(), events.end());
    events.erase(std::unique(events.begin(), events.end()), events.end());
  }
  bool is_output(double t) const { return std::binary_search(outputs.begin(), outputs.end(), t); }
  bool is_break(double t) const { return std::binary_search(breaks.begin(), breaks.end(), t); }

  std::vector<double> outputs;  ///< including t0
  std::vector<double> breaks;   ///< in (t0, stop]
  std::vector<double> events;   ///< outputs after t0 and breaks, sorted, unique
};

/// Equal steps of at most h_max from t to target: their number.
inline long fixed_steps(double t, double target, double h_max) {
  return std::max(1L, std::lround(std::ceil((target - t) / h_max - 1e-9)));
}

/// Method, CPU time and real-time factor, when a run ends.
inline void finish_stats(RunStats& st, const std::string& method, double cpu_seconds, const TimeSpec& time) {
  st.method = method;
  st.cpu_seconds = cpu_seconds;
  st.simulated_seconds = time.stop - time.start;
  st.realtime_factor = cpu_seconds > 0 ? st.simulated_seconds / cpu_seconds : 0.0;
}

}  // namespace dydp::engine
