#include "engine/analysis/step_limiters.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "engine/analysis/tolerances.hpp"

namespace dydp::engine {

void StepLimiters::add_step(const double* local_errors, const double* weights) {
  const int n = static_cast<int>(count_.size());
  if (n == 0) return;
  int worst = 0;
  double largest = -1.0;
  for (int i = 0; i < n; ++i) {
    const double e = std::fabs(local_errors[i] * weights[i]);
    if (e > largest) largest = e, worst = i;
  }
  ++count_[worst];
  ++steps_;
}

std::vector<LimitingState> StepLimiters::ranking(const Diagram& d, int most) const {
  std::vector<int> order(count_.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return count_[a] > count_[b]; });
  std::vector<LimitingState> out;
  for (int i : order) {
    if (static_cast<int>(out.size()) == most || count_[i] == 0) break;
    out.push_back({state_label(d, i), count_[i], static_cast<double>(count_[i]) / steps_});
  }
  return out;
}

}  // namespace dydp::engine
