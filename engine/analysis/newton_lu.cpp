#include "engine/analysis/newton_lu.hpp"

#include <cmath>

namespace dydp::engine {

// The substitutable rows of column-major a: a unit diagonal and exactly one other nonzero, in a
// column whose row is not of that form itself (a chain x_a + c x_b, x_b + c' x_c keeps both).
void NewtonLU::find_substituted_rows(const double* a, int size) {
  const Eigen::Index n = size;
  substituted_.clear();
  partner_.clear();
  coefficient_.clear();
  kept_.clear();
  std::vector<int>& other = other_;
  other.assign(static_cast<std::size_t>(n), -1);  // -1 none yet, -2 more than one
  for (Eigen::Index j = 0; j < n; ++j) {
    const double* column = a + j * n;
    for (Eigen::Index i = 0; i < n; ++i) {
      if (i == j || column[i] == 0.0) continue;
      other[i] = other[i] == -1 ? static_cast<int>(j) : -2;
    }
  }
  std::vector<char>& candidate = candidate_;
  candidate.assign(static_cast<std::size_t>(n), 0);
  for (Eigen::Index i = 0; i < n; ++i) candidate[i] = other[i] >= 0 && a[i * n + i] == 1.0;
  place_.assign(static_cast<std::size_t>(n), -1);
  for (Eigen::Index i = 0; i < n; ++i) {
    if (candidate[i] && !candidate[other[i]]) {
      substituted_.push_back(static_cast<int>(i));
      partner_.push_back(other[i]);
      coefficient_.push_back(a[static_cast<Eigen::Index>(other[i]) * n + i]);
    } else {
      place_[i] = static_cast<int>(kept_.size());
      kept_.push_back(static_cast<int>(i));
    }
  }
}

bool NewtonLU::factor(const double* a, int n) {
  find_substituted_rows(a, n);
  const auto m = static_cast<Eigen::Index>(kept_.size());
  const auto ne = static_cast<Eigen::Index>(substituted_.size());
  // a(kept, kept) with x_i = b_i - c_i x_{p_i} substituted: column p_i gains -a(kept, i) c_i
  work_.resize(m, m);
  for (Eigen::Index k = 0; k < m; ++k) {
    const double* column = a + static_cast<Eigen::Index>(kept_[k]) * n;
    double* out = work_.data() + k * m;
    for (Eigen::Index r = 0; r < m; ++r) out[r] = column[kept_[r]];
  }
  coupling_.resize(m, ne);
  for (Eigen::Index e = 0; e < ne; ++e) {
    const double* column = a + static_cast<Eigen::Index>(substituted_[e]) * n;
    double* coupling = coupling_.data() + e * m;
    for (Eigen::Index r = 0; r < m; ++r) coupling[r] = column[kept_[r]];
    double* target = work_.data() + static_cast<Eigen::Index>(place_[partner_[e]]) * m;
    const double ce = coefficient_[e];
    for (Eigen::Index r = 0; r < m; ++r) target[r] -= coupling[r] * ce;
  }
  lu_.compute(work_);
  kept_rhs_.resize(m);
  permuted_.resize(m);
  const Eigen::MatrixXd& U = lu_.matrixLU();
  for (Eigen::Index k = 0; k < m; ++k) {
    if (U(k, k) == 0.0 || !std::isfinite(U(k, k))) {
      failed_column_ = kept_[k];
      return false;
    }
  }
  failed_column_ = -1;
  return true;
}

// The substituted rows' b moved into the kept rows; x = U^-1 L^-1 P b over the kept rows, each
// step one contiguous multiply-add over a column of the factors; then x_i from its partner.
void NewtonLU::solve(const double* b, double* x) const {
  const auto m = static_cast<Eigen::Index>(kept_.size());
  const auto ne = static_cast<Eigen::Index>(substituted_.size());
  const double* __restrict lu = lu_.matrixLU().data();
  const auto& to = lu_.permutationP().indices();  // (P y)[to[i]] = y[i]
  double* __restrict y = kept_rhs_.data();
  double* __restrict z = permuted_.data();
  for (Eigen::Index r = 0; r < m; ++r) y[r] = b[kept_[r]];
  for (Eigen::Index e = 0; e < ne; ++e) {
    const double be = b[substituted_[e]];
    if (be == 0.0) continue;
    const double* __restrict coupling = coupling_.data() + e * m;
    for (Eigen::Index r = 0; r < m; ++r) y[r] -= coupling[r] * be;
  }
  for (Eigen::Index i = 0; i < m; ++i) z[to[i]] = y[i];
  for (Eigen::Index j = 0; j < m; ++j) {  // L (unit diagonal)
    const double zj = z[j];
    if (zj == 0.0) continue;
    const double* __restrict below = lu + j * m + j + 1;
    double* __restrict rest = z + j + 1;
    for (Eigen::Index i = 0; i < m - j - 1; ++i) rest[i] -= below[i] * zj;
  }
  for (Eigen::Index j = m - 1; j >= 0; --j) {  // U
    const double* __restrict column = lu + j * m;
    const double zj = z[j] /= column[j];
    if (zj == 0.0) continue;
    for (Eigen::Index i = 0; i < j; ++i) z[i] -= column[i] * zj;
  }
  // x may be b: each substituted entry reads only its own b, before the kept ones are written
  for (Eigen::Index e = 0; e < ne; ++e) {
    const int i = substituted_[e];
    x[i] = b[i] - coefficient_[e] * z[place_[partner_[e]]];
  }
  for (Eigen::Index r = 0; r < m; ++r) x[kept_[r]] = z[r];
}

long NewtonLU::real_words() const {
  return static_cast<long>(2 * work_.size() + coupling_.size() + coefficient_.size());
}

long NewtonLU::integer_words() const {
  return static_cast<long>(work_.rows() + kept_.size() + 2 * substituted_.size() + place_.size());
}

}  // namespace dydp::engine
