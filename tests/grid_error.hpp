// The error of a sampled signal against a reference on the same grid: the largest difference,
// relative to the reference's largest magnitude.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

namespace dydp::test {

inline double grid_error(const std::vector<double>& values, const std::vector<double>& reference) {
  double worst = 0, scale = 0;
  for (std::size_t k = 0; k < values.size(); ++k) {
    worst = std::max(worst, std::fabs(values[k] - reference[k]));
    scale = std::max(scale, std::fabs(reference[k]));
  }
  return worst / scale;
}

}  // namespace dydp::test
