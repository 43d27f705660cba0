#include "engine/studies/screening.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>

namespace dydp::engine {

ScreeningEstimate estimate_screening(const std::vector<ScreeningRange>& ranges, const ScreeningData& data) {
  const size_t P = ranges.size(), N = data.psi.size();
  if (N == 0) throw std::invalid_argument("screening: no sample");
  if (data.gradient.size() != N) throw std::invalid_argument("screening: one gradient per sample needed");
  for (const auto& g : data.gradient)
    if (g.size() != P) throw std::invalid_argument("screening: one derivative per parameter needed");
  if (data.nominal_gradient.size() != P) throw std::invalid_argument("screening: nominal gradient size");

  ScreeningEstimate e;
  e.mean = std::accumulate(data.psi.begin(), data.psi.end(), 0.0) / static_cast<double>(N);
  double squares = 0.0;
  for (double psi : data.psi) squares += (psi - e.mean) * (psi - e.mean);
  e.variance = N > 1 ? squares / static_cast<double>(N - 1) : 0.0;

  e.parameters.resize(P);
  double weight_sum = 0.0;
  std::vector<double> weight(P);
  for (size_t i = 0; i < P; ++i) {
    ParameterMeasure& m = e.parameters[i];
    double sum = 0.0, sum_squares = 0.0;
    for (size_t k = 0; k < N; ++k) {
      sum += data.gradient[k][i];
      sum_squares += data.gradient[k][i] * data.gradient[k][i];
    }
    m.mean_gradient = sum / static_cast<double>(N);
    m.nu = sum_squares / static_cast<double>(N);
    const double width = ranges[i].upper - ranges[i].lower;
    weight[i] = width * width * m.nu;
    weight_sum += weight[i];
    // Poincare's inequality on [a, b]: Var_i <= (b - a)^2 / pi^2 E[(df/dx_i)^2] bounds the
    // total partial variance of x_i (Sobol' and Kucherenko 2009, Theorem 1).
    m.total_index_bound = e.variance > 0 ? weight[i] / (std::numbers::pi * std::numbers::pi * e.variance)
                          : (weight[i] > 0 ? INFINITY : 0.0);
    m.local_normalised = data.nominal_psi != 0
                             ? ranges[i].nominal / data.nominal_psi * data.nominal_gradient[i] : 0.0;
  }
  for (size_t i = 0; i < P; ++i) e.parameters[i].normalised = weight_sum > 0 ? weight[i] / weight_sum : 0.0;

  e.ranking.resize(P);
  std::iota(e.ranking.begin(), e.ranking.end(), 0);
  std::stable_sort(e.ranking.begin(), e.ranking.end(), [&](int a, int b) { return weight[a] > weight[b]; });
  for (size_t r = 0; r < P; ++r) e.parameters[e.ranking[r]].rank = static_cast<int>(r) + 1;
  return e;
}

}  // namespace dydp::engine
