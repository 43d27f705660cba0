// The output grid t0, t0 + h, ..., stop (the last point is stop exactly).
#pragma once

#include <cmath>
#include <vector>

#include "engine/diagram.hpp"

namespace dydp::engine {

inline std::vector<double> output_grid(const TimeSpec& time) {
  const double span = time.stop - time.start;
  const long n = std::max(1L, std::lround(std::ceil(span / time.output_step - 1e-9)));
  std::vector<double> t(n + 1);
  for (long k = 0; k <= n; ++k) t[k] = std::min(time.start + k * time.output_step, time.stop);
  t[n] = time.stop;
  return t;
}

}  // namespace dydp::engine
