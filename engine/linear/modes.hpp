// The modes of a linear model: eigenvalues of A with their natural frequencies, damping ratios,
// the states that dominate their shapes and their sensitivities to the scene's parameters,
// d(lambda)/dp = w^H (dA/dp) v / (w^H v) (w, v the left and right eigenvectors).
#pragma once

#include <complex>
#include <string>
#include <utility>
#include <vector>

#include "engine/linear/linearization.hpp"

namespace dydp::engine {

struct ModeSensitivity {
  std::complex<double> eigenvalue;
  double frequency_hz = 0.0;
  double damping_ratio = 0.0;
};

struct Mode {
  std::complex<double> eigenvalue;  ///< the one of a conjugate pair with Im >= 0
  double frequency_hz = 0.0;        ///< |lambda| / (2 pi): the undamped natural frequency
  double damping_ratio = 0.0;       ///< -Re(lambda) / |lambda| (1 for a real, decaying one)
  /// The states that take the largest part in the mode, by participation factor |v_i w_i|
  /// normalised to a sum of 1: at most four, largest first, together at least 80 % or down to 5 %.
  std::vector<std::pair<std::string, double>> dominant;
  std::vector<ModeSensitivity> sensitivity;  ///< one per parameter given, in their order
};

/// The modes of A, sorted by frequency, one per conjugate pair. dA: dA/dp per parameter (may be
/// empty).
std::vector<Mode> modes(const LinearModel& m, const std::vector<Eigen::MatrixXd>& dA = {});

}  // namespace dydp::engine
