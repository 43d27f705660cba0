// Linear interpolation in a sampled signal, held constant outside its samples: the recorded
// inputs' (blocks/time_series.hpp) and the comparison of a replay with its recording
// (engine/studies/recording_validation.hpp).
#pragma once

#include <algorithm>
#include <vector>

namespace dydp::engine {

/// y at x, from samples (t, y) with t increasing; y.front() before t.front(), y.back() after
/// t.back().
inline double interpolate_linear(const std::vector<double>& t, const std::vector<double>& y, double x) {
  if (x <= t.front()) return y.front();
  if (x >= t.back()) return y.back();
  const size_t k = std::upper_bound(t.begin(), t.end(), x) - t.begin();  // segment [k - 1, k]
  const double w = (x - t[k - 1]) / (t[k] - t[k - 1]);
  return (1 - w) * y[k - 1] + w * y[k];
}

}  // namespace dydp::engine
