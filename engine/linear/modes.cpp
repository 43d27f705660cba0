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

/// Balancing (Parlett and Reinsch, as LAPACK's gebal does before its eigensolver): a diagonal
/// D of powers of two such that D^-1 A D has rows and columns of like norms. The diagram's
/// Jacobian spans 14 decades (oil columns against filter states), and without it the
/// Hessenberg-QR eigenvalues of the slow modes lose every digit.
Eigen::VectorXd balance(const Eigen::MatrixXd& A) {
  const Eigen::Index n = A.rows();
  Eigen::VectorXd d = Eigen::VectorXd::Ones(n);
  Eigen::MatrixXd B = A;
  for (bool changed = true; changed;) {
    changed = false;
    for (Eigen::Index i = 0; i < n; ++i) {
      const double c = B.col(i).lpNorm<1>() - std::fabs(B(i, i));
      const double r = B.row(i).lpNorm<1>() - std::fabs(B(i, i));
      if (c == 0.0 || r == 0.0) continue;
      double f = 1.0, cs = c;
      while (cs < r / 2) cs *= 2, f *= 2;
      while (cs >= r * 2) cs /= 2, f /= 2;
      if ((cs + r / f) < 0.95 * (c + r)) {
        d[i] *= f;
        B.col(i) *= f;
        B.row(i) /= f;
        changed = true;
      }
    }
  }
  return d;
}

}  // namespace

std::vector<Mode> modes(const LinearModel& m, const std::vector<Eigen::MatrixXd>& dA) {
  const Eigen::Index n = m.A.rows();
  std::vector<Mode> out;
  if (n == 0) return out;
  // Eigenvectors of the balanced B = D^-1 A D, then V = D V_B; the left ones from B^T apart
  // (u^T B = lambda u^T, so the row u^T D^-1 for A), each scaled to w^H v = 1. Not the rows of
  // V^-1: the free coordinates' zero eigenvalues are defective (a position and its rate), which
  // makes V ill-conditioned and its inverse's rows wrong for every mode.
  const Eigen::VectorXd D = balance(m.A);
  const Eigen::MatrixXd B = D.cwiseInverse().asDiagonal() * m.A * D.asDiagonal();
  Eigen::EigenSolver<Eigen::MatrixXd> eig(B, true), left(B.transpose(), true);
  const Eigen::VectorXcd lambda = eig.eigenvalues();
  const Eigen::MatrixXcd V = D.cast<std::complex<double>>().asDiagonal() * eig.eigenvectors();
  Eigen::MatrixXcd W(n, n);  // row i: w_i^H
  for (Eigen::Index i = 0; i < n; ++i) {
    Eigen::Index j = 0;
    (left.eigenvalues().array() - lambda[i]).abs().minCoeff(&j);
    const Eigen::RowVectorXcd u = left.eigenvectors().col(j).transpose() * D.cwiseInverse().cast<std::complex<double>>().asDiagonal();
    const std::complex<double> s = (u * V.col(i))(0, 0);
    W.row(i) = u / s;
  }
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
    // Participation factors |v_k w_k| (Perez-Arriaga et al. 1982): unit-free, and zero for states
    // that only watch the mode (a filter on the body's acceleration), whose left-eigenvector
    // components vanish.
    for (Eigen::Index k = 0; k < n; ++k) share[k] = std::abs(V(k, i) * W(i, k));
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
