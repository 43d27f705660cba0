// The frequency response of a linear model: H(j w) = C (j w I - A)^-1 b(j w) + d(j w) from one
// input to every output, where an input may come with its rate (a pad's height z and its
// zdot, both inputs of the diagram: b = B_z + j w B_zdot); and d|H|/dp from the model's
// derivatives, dH = C R dA R b + C R db + dC R b + dd, R = (j w I - A)^-1.
#pragma once

#include <complex>
#include <vector>

#include "engine/linear/linearization.hpp"

namespace dydp::engine {

struct FrequencyInput {
  int input = 0;      ///< column of B and D
  int rate = -1;      ///< column whose signal is the input's time derivative, or -1
};

struct FrequencyResponse {
  std::vector<double> frequency_hz;
  /// H[f][o]: output o at frequency f
  std::vector<std::vector<std::complex<double>>> H;
  /// dmagnitude[p][f][o]: d|H|/dp per parameter given
  std::vector<std::vector<std::vector<double>>> dmagnitude;
};

FrequencyResponse frequency_response(const LinearModel& m, FrequencyInput input, const std::vector<double>& frequency_hz,
                                     const std::vector<LinearModelDerivative>& derivatives = {});

/// The rms of |H| over the grid's band, per output: T = sqrt(int |H|^2 df / (f_last - f_first)),
/// the integral by the trapezoid rule on the grid, and dT/dp = int |H| d|H|/dp df / ((f_last -
/// f_first) T). For an output weighted by a filter.iso2631 block (its a_weighted) it is the
/// band's ISO 2631 weighted transmissibility: the weighted acceleration's rms per unit input
/// amplitude for an input whose amplitude spectrum is flat over the band.
struct BandRms {
  std::vector<double> value;                     ///< per output
  std::vector<std::vector<double>> sensitivity;  ///< [parameter][output]
};
BandRms band_rms(const FrequencyResponse& h);

/// n frequencies from lo to hi [Hz], log spaced (n >= 2).
std::vector<double> log_frequencies(double lo, double hi, int n);

}  // namespace dydp::engine
