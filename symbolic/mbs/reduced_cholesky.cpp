// Cholesky factor by rows (see reduced_cholesky.hpp): L(i, j) = (A(i, j) - L(i, :j) . L(j, :j)) / L(j, j).
#include "symbolic/mbs/reduced_cholesky.hpp"

#include <cmath>

namespace dydp::mbs {

bool ReducedCholesky::compute(const Eigen::Ref<const Matrix>& A) {
  n_ = static_cast<int>(A.rows());
  if (n_ > kSmall) {
    large_.compute(A);  // (which takes a NaN pivot for a positive one)
    return large_.info() == Eigen::Success && large_.matrixLLT().diagonal().allFinite();
  }
  const int n = n_;
  l_.resize(static_cast<std::size_t>(n) * n);
  double* __restrict l = l_.data();
  for (int j = 0; j < n; ++j) {
    const double* lj = l + j * n;
    double d = A(j, j);
    for (int k = 0; k < j; ++k) d -= lj[k] * lj[k];
    if (!(d > 0.0) || !std::isfinite(d)) return false;
    const double root = std::sqrt(d);
    l[j * n + j] = root;
    for (int i = j + 1; i < n; ++i) {
      const double* li = l + i * n;
      double s = A(i, j);
      for (int k = 0; k < j; ++k) s -= li[k] * lj[k];
      l[i * n + j] = s / root;  // divided, not multiplied by 1 / root: the rounding of a library LLT
    }
  }
  return true;
}

void ReducedCholesky::solve_in_place(double* x, Eigen::Index ld, Eigen::Index nrhs) const {
  if (n_ > kSmall) {
    Eigen::Map<Matrix, 0, Eigen::OuterStride<>> b(x, n_, nrhs, Eigen::OuterStride<>(ld));
    b = large_.solve(b).eval();
    return;
  }
  const int n = n_;
  const double* __restrict l = l_.data();
  if (nrhs >= 2) {
    // Several right-hand sides: by rows of a row-major copy, each step an axpy over the
    // right-hand sides (vectorised), in the order of operations of one column's substitution
    // below, so the same results bit for bit.
    const Eigen::Index m = nrhs;
    rows_.resize(static_cast<std::size_t>(n * m));
    double* __restrict t = rows_.data();
    for (Eigen::Index c = 0; c < m; ++c)
      for (int i = 0; i < n; ++i) t[i * m + c] = x[c * ld + i];
    for (int i = 0; i < n; ++i) {  // L Y = B
      double* __restrict ti = t + i * m;
      for (int k = 0; k < i; ++k) {
        const double f = l[i * n + k];
        const double* __restrict tk = t + k * m;
        for (Eigen::Index c = 0; c < m; ++c) ti[c] -= f * tk[c];
      }
      const double d = l[i * n + i];
      for (Eigen::Index c = 0; c < m; ++c) ti[c] /= d;
    }
    for (int i = n - 1; i >= 0; --i) {  // L^T X = Y
      double* __restrict ti = t + i * m;
      for (int k = i + 1; k < n; ++k) {
        const double f = l[k * n + i];
        const double* __restrict tk = t + k * m;
        for (Eigen::Index c = 0; c < m; ++c) ti[c] -= f * tk[c];
      }
      const double d = l[i * n + i];
      for (Eigen::Index c = 0; c < m; ++c) ti[c] /= d;
    }
    for (Eigen::Index c = 0; c < m; ++c)
      for (int i = 0; i < n; ++i) x[c * ld + i] = t[i * m + c];
    return;
  }
  for (Eigen::Index c = 0; c < nrhs; ++c) {
    double* __restrict y = x + c * ld;
    for (int i = 0; i < n; ++i) {  // L y = b
      const double* li = l + i * n;
      double s = y[i];
      for (int k = 0; k < i; ++k) s -= li[k] * y[k];
      y[i] = s / l[i * n + i];
    }
    for (int i = n - 1; i >= 0; --i) {  // L^T x = y
      double s = y[i];
      for (int k = i + 1; k < n; ++k) s -= l[k * n + i] * y[k];
      y[i] = s / l[i * n + i];
    }
  }
}

}  // namespace dydp::mbs
