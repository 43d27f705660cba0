// Derivative-based global sensitivity measures (DGSM) from exact gradients over a parameter box:
// mean and variance of psi, nu_i = E[(dpsi/dp_i)^2], the bound nu_i gives on the total Sobol'
// index for a uniform range (Sobol' and Kucherenko 2009: S_Ti <= (b_i - a_i)^2 nu_i / (pi^2 D)),
// the local normalised sensitivity at the nominal point, and the ranking they give.
#pragma once

#include <string>
#include <vector>

namespace dydp::engine {

/// A screened parameter: uniform over [lower, upper], `nominal` its value in the scene.
struct ScreeningRange {
  std::string name;
  double lower = 0.0, upper = 1.0;
  double nominal = 0.0;
};

/// One objective at the sample points: psi[k] and gradient[k][i] = dpsi/dp_i at point k, and the
/// same at the nominal point.
struct ScreeningData {
  std::vector<double> psi;
  std::vector<std::vector<double>> gradient;
  double nominal_psi = 0.0;
  std::vector<double> nominal_gradient;
};

struct ParameterMeasure {
  double nu = 0.0;           ///< E[(dpsi/dp_i)^2] over the box
  double mean_gradient = 0.0;  ///< E[dpsi/dp_i]: the sign of the average effect
  /// (b_i - a_i)^2 nu_i as a share of the sum over all parameters: the ranking's weights, sum 1.
  double normalised = 0.0;
  /// Upper bound on the total Sobol' index S_Ti: (b_i - a_i)^2 nu_i / (pi^2 Var psi);
  /// infinite when Var psi is zero and nu_i is not.
  double total_index_bound = 0.0;
  /// (p_i / psi) dpsi/dp_i at the nominal point: % change of psi per % of p_i (0 when psi = 0).
  double local_normalised = 0.0;
  int rank = 0;              ///< 1: the largest bound
};

struct ScreeningEstimate {
  double mean = 0.0;
  double variance = 0.0;     ///< sample variance of psi (divided by N - 1; 0 for one sample)
  std::vector<ParameterMeasure> parameters;  ///< in the order of the ranges
  std::vector<int> ranking;  ///< parameter indices, largest bound first (ties: listed order)
};

/// The measures of one objective. Throws std::invalid_argument when the data's sizes disagree
/// with the ranges or there is no sample.
ScreeningEstimate estimate_screening(const std::vector<ScreeningRange>& ranges, const ScreeningData& data);

}  // namespace dydp::engine
