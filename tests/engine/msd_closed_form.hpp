// Closed-form response of m x'' + c x' + k x = A sin(w t) from x(0) = x0, x'(0) = v0
// (underdamped), written for any scalar type so that complex-step differentiation gives its
// exact parameter derivatives: the independent oracle for the engine's sensitivities.
#pragma once

#include <cmath>
#include <complex>
#include <functional>
#include <vector>

namespace dydp::test {

template <class T>
struct MsdParams {
  T m, k, c;
  double amplitude, omega, x0, v0;
};

/// x(t): steady-state particular solution plus the decaying homogeneous one.
template <class T>
T msd_position(const MsdParams<T>& p, double t) {
  using std::cos, std::exp, std::sin, std::sqrt;
  const double w = p.omega;
  const T D = p.k - p.m * w * w, E = p.c * w, den = D * D + E * E;
  // x_p = A (D sin wt - E cos wt) / (D^2 + E^2)
  const T xp = p.amplitude * (D * std::sin(w * t) - E * std::cos(w * t)) / den;
  const T xp0 = -p.amplitude * E / den, vp0 = p.amplitude * D * w / den;
  const T alpha = p.c / (2.0 * p.m);
  const T beta = sqrt(p.k / p.m - alpha * alpha);
  const T c1 = p.x0 - xp0;
  const T c2 = (p.v0 - vp0 + alpha * c1) / beta;
  return xp + exp(-alpha * t) * (c1 * cos(beta * t) + c2 * sin(beta * t));
}

/// d/d(parameter j) of f by complex step: Im f(p + i h e_j) / h, exact to rounding.
inline double complex_step(const std::function<std::complex<double>(const MsdParams<std::complex<double>>&)>& f,
                           const MsdParams<double>& p, int j) {
  const double h = 1e-30;
  MsdParams<std::complex<double>> z{p.m, p.k, p.c, p.amplitude, p.omega, p.x0, p.v0};
  if (j == 0) z.m += std::complex<double>(0, h);
  if (j == 1) z.k += std::complex<double>(0, h);
  if (j == 2) z.c += std::complex<double>(0, h);
  return f(z).imag() / h;
}

/// integral of f over [a, b] by composite 5-point Gauss-Legendre: exact to rounding for the
/// smooth closed form with enough panels.
template <class T, class F>
T gauss_legendre(F f, double a, double b, int panels) {
  static const double x[5] = {0.0, 0.5384693101056831, -0.5384693101056831, 0.9061798459386640,
                              -0.9061798459386640};
  static const double w[5] = {0.5688888888888889, 0.4786286704993665, 0.4786286704993665,
                              0.2369268850561891, 0.2369268850561891};
  const double h = (b - a) / panels;
  T sum = T(0);
  for (int k = 0; k < panels; ++k) {
    const double mid = a + (k + 0.5) * h;
    for (int i = 0; i < 5; ++i) sum += w[i] * f(mid + 0.5 * h * x[i]);
  }
  return sum * (0.5 * h);
}

}  // namespace dydp::test
