#include "engine/linear/modes.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace dydp::engine {
namespace {

constexpr double kTwoPi = 6.283185307179586;

double frequency_of(std::complex<double> l) { return std::abs(l) / kTwoPi; }
double damping_of(std::complex<double> l) {
  const double a = std::abs(l);
  return a > 0 ? -l.real() / a : 0.0;
}

}  // namespace

std::vector<Mode> modes(const LinearModel& m, const std::vector<double>& nominals,
                        const std::vector<Eigen::MatrixXd>& dA) {
  const Eigen::Index n = m.A.rows();
  std::vector<Mode> out;
  if (n == 0) return out;
  Eigen::EigenSolver<Eigen::MatrixXd> eig(m.A, true);
  const Eigen::VectorXcd lambda = eig.eigenvalues();
  const Eigen::MatrixXcd V = eig.eigenvectors();
  // Left eigenvectors: the rows of V^-1 (w_i^H v_j = delta_ij, so no normalisation is left).
  const Eigen::MatrixXcd W = V.partialPivLu().inverse();
  std::vector<Eigen::MatrixXcd> dAc;
  for (const Eigen::MatrixXd& a : dA) dAc.push_back(a.cast<std::complex<double>>());
  for (Eigen::Index i = 0; i < n; ++i) {
    const std::complex<double> l = lambda[i];
    // One of each conjugate pair: the one with Im > 0 (reals are their own pair).
    if (l.imag() < -1e-12 * std::max(1.0, std::abs(l))) continue;
    Mode mode;
    mode.eigenvalue = {l.real(), std::fabs(l.imag()) <= 1e-12 * std::max(1.0, std::abs(l)) ? 0.0 : l.imag()};
    mode.frequency_hz = frequency_of(mode.eigenvalue);
    mode.damping_ratio = damping_of(mode.eigenvalue);
    std::vector<double> share(n);
    for (Eigen::Index k = 0; k < n; ++k) share[k] = std::norm(V(k, i) / nominals[k]);
    const double total = std::accumulate(share.begin(), share.end(), 0.0);
    std::vector<int> order(n);
    std::iota(order.begin(), order.end(), 0);
    std::sort(order.begin(), order.end(), [&](int a, int b) { return share[a] > share[b]; });
    double covered = 0.0;
    for (int k : order) {
      const double s = total > 0 ? share[k] / total : 0.0;
      if (mode.dominant.size() == 4 || covered >= 0.8 || (s < 0.05 && !mode.dominant.empty())) break;
      mode.dominant.push_back({m.states[k], s});
      covered += s;
    }
    for (const Eigen::MatrixXcd& a : dAc) {
      const std::complex<double> dl = (W.row(i) * a * V.col(i))(0, 0);
      ModeSensitivity s;
      s.eigenvalue = {dl.real(), mode.eigenvalue.imag() == 0.0 ? 0.0 : dl.imag()};
      const double mag = std::abs(l);
      if (mag > 0) {
        const double dmag = (std::conj(l) * dl).real() / mag;
        s.frequency_hz = dmag / kTwoPi;
        s.damping_ratio = -dl.real() / mag + l.real() * dmag / (mag * mag);
      }
      mode.sensitivity.push_back(s);
    }
    out.push_back(std::move(mode));
  }
  std::stable_sort(out.begin(), out.end(), [](const Mode& a, const Mode& b) { return a.frequency_hz < b.frequency_hz; });
  return out;
}

}  // namespace dydp::engine
