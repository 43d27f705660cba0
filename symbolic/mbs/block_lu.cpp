// Block-diagonal LU (see block_lu.hpp): components by union-find over rows and columns, each
// block factored with partial pivoting by Doolittle's elimination in place, then inverted.
#include "symbolic/mbs/block_lu.hpp"

#include <cmath>
#include <numeric>
#include <stdexcept>
#include <type_traits>
#include <utility>

namespace dydp::mbs {

void BlockLU::set_pattern(const Eigen::Matrix<char, Eigen::Dynamic, Eigen::Dynamic>& nonzero) {
  const int m = static_cast<int>(nonzero.rows());
  if (nonzero.cols() != m) throw std::invalid_argument("BlockLU: the pattern must be square");
  size_ = m;
  work_.assign(2 * std::max(1, m), 0.0);
  // nodes 0..m-1 rows, m..2m-1 columns
  std::vector<int> parent(2 * m);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  };
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j)
      if (nonzero(i, j)) parent[find(i)] = find(m + j);
  std::vector<int> block_of(2 * m, -1);
  blocks_.clear();
  for (int x = 0; x < 2 * m; ++x) {
    const int root = find(x);
    if (block_of[root] < 0) {
      block_of[root] = static_cast<int>(blocks_.size());
      blocks_.emplace_back();
    }
    Block& b = blocks_[block_of[root]];
    (x < m ? b.rows : b.cols).push_back(x < m ? x : x - m);
  }
  for (const Block& b : blocks_) {
    if (b.rows.size() == b.cols.size()) continue;
    // not decomposable into square blocks: one block (it is then singular, and LU says so)
    blocks_.assign(1, Block{});
    for (int i = 0; i < m; ++i) {
      blocks_[0].rows.push_back(i);
      blocks_[0].cols.push_back(i);
    }
    break;
  }
  for (Block& b : blocks_) {
    const std::size_t k = b.rows.size();
    b.lu.assign(k * k, 0.0);
    b.inverse.assign(k * k, 0.0);
    b.order.assign(k, 0);
    b.reciprocal.assign(k, 0.0);
  }
}

namespace {

// the block loops unrolled whole when k is known at compile time
#define DYDP_UNROLL _Pragma("GCC unroll 8")

// Doolittle's elimination with partial pivoting of a k x k column-major block in place, the
// exchanges composed into one order and the pivots' reciprocals kept, and the substitution
// through the factors. K > 0 fixes k at compile time (the loops unroll and the substitution's
// vector stays in registers: a corner's blocks have four to six columns); K = 0 reads it at run
// time.
template <int K>
bool factor_block(double* __restrict a, int* __restrict order, double* __restrict reciprocal, int k_run) {
  const int k = K > 0 ? K : k_run;
  bool regular = true;
  DYDP_UNROLL
  for (int i = 0; i < k; ++i) order[i] = i;
  DYDP_UNROLL
  for (int j = 0; j < k; ++j) {
    int p = j;
    double largest = std::abs(a[j * k + j]);
    DYDP_UNROLL
    for (int i = j + 1; i < k; ++i) {
      const double v = std::abs(a[j * k + i]);
      p = v > largest ? i : p;
      largest = v > largest ? v : largest;
    }
    if (p != j) {
      DYDP_UNROLL
      for (int c = 0; c < k; ++c) std::swap(a[c * k + j], a[c * k + p]);
      std::swap(order[j], order[p]);
    }
    const double d = a[j * k + j];
    const double r = 1.0 / d;
    reciprocal[j] = r;
    if (d == 0.0 || !std::isfinite(d)) {
      regular = false;
      continue;
    }
    DYDP_UNROLL
    for (int i = j + 1; i < k; ++i) a[j * k + i] *= r;
    DYDP_UNROLL
    for (int c = j + 1; c < k; ++c) {
      const double f = a[c * k + j];
      DYDP_UNROLL
      for (int i = j + 1; i < k; ++i) a[c * k + i] -= a[j * k + i] * f;
    }
  }
  return regular;
}

// x := (P A_block)^-1 x, x holding the right-hand side in the factors' order (row i of the
// block's right-hand side at x[j] where order[j] = i)
template <int K>
inline void substitute_in_place(const double* __restrict a, const double* __restrict reciprocal, double* __restrict x,
                                int k_run) {
  const int k = K > 0 ? K : k_run;
  DYDP_UNROLL
  for (int j = 0; j < k; ++j)  // L y = P b
    DYDP_UNROLL
    for (int i = j + 1; i < k; ++i) x[i] -= a[j * k + i] * x[j];
  DYDP_UNROLL
  for (int j = k - 1; j >= 0; --j) {  // U x = y
    x[j] *= reciprocal[j];
    DYDP_UNROLL
    for (int i = 0; i < j; ++i) x[i] -= a[j * k + i] * x[j];
  }
}

// The same on z in memory, through a local copy when k is known (it stays in registers)
template <int K>
void substitute_block(const double* __restrict a, const double* __restrict reciprocal, double* __restrict z, int k_run) {
  if constexpr (K > 0) {
    double x[K];
    DYDP_UNROLL
    for (int i = 0; i < K; ++i) x[i] = z[i];
    substitute_in_place<K>(a, reciprocal, x, K);
    DYDP_UNROLL
    for (int i = 0; i < K; ++i) z[i] = x[i];
  } else {
    substitute_in_place<K>(a, reciprocal, z, k_run);
  }
}

// The block's inverse, row-major: column c is the substitution of the unit vector e_c, whose
// 1 is, in the factors' order, where order[i] = c. When k is known the K columns are
// substituted together, independent chains of multiply-adds; otherwise one by one in `column`
// (k entries).
template <int K>
void invert_block(const double* __restrict a, const int* __restrict order, const double* __restrict reciprocal,
                  double* __restrict inverse, double* __restrict column, int k_run) {
  if constexpr (K > 0) {
    double x[K][K];  // x[c]: column c
    DYDP_UNROLL
    for (int c = 0; c < K; ++c)
      DYDP_UNROLL
      for (int i = 0; i < K; ++i) x[c][i] = order[i] == c ? 1.0 : 0.0;
    DYDP_UNROLL
    for (int c = 0; c < K; ++c) substitute_in_place<K>(a, reciprocal, x[c], K);
    DYDP_UNROLL
    for (int i = 0; i < K; ++i)
      DYDP_UNROLL
      for (int c = 0; c < K; ++c) inverse[i * K + c] = x[c][i];
  } else {
    const int k = k_run;
    for (int c = 0; c < k; ++c) {
      for (int i = 0; i < k; ++i) column[i] = order[i] == c ? 1.0 : 0.0;
      substitute_in_place<K>(a, reciprocal, column, k);
      for (int i = 0; i < k; ++i) inverse[i * k + c] = column[i];
    }
  }
}

// f(std::integral_constant<int, K>) with K = k for k of one to six, K = 0 (size read at run
// time) above
template <typename F>
decltype(auto) with_block_size(int k, F f) {
  switch (k) {
    case 1: return f(std::integral_constant<int, 1>{});
    case 2: return f(std::integral_constant<int, 2>{});
    case 3: return f(std::integral_constant<int, 3>{});
    case 4: return f(std::integral_constant<int, 4>{});
    case 5: return f(std::integral_constant<int, 5>{});
    case 6: return f(std::integral_constant<int, 6>{});
    default: return f(std::integral_constant<int, 0>{});
  }
}

}  // namespace

bool BlockLU::factor(Block& b) {
  const int k = static_cast<int>(b.rows.size());
  return with_block_size(k, [&](auto K) {
    return factor_block<decltype(K)::value>(b.lu.data(), b.order.data(), b.reciprocal.data(), k);
  });
}

void BlockLU::apply_factors(const Block& b, double* z) {
  const int k = static_cast<int>(b.rows.size());
  with_block_size(k, [&](auto K) { substitute_block<decltype(K)::value>(b.lu.data(), b.reciprocal.data(), z, k); });
}

void BlockLU::invert() {
  // The inverse (row-major) from the factors, all of a block's columns at once: a block is
  // solved for many right-hand sides per factorisation (the sedan: 14 columns of Ju, then the
  // tangents' directions), k^2 independent multiply-adds each instead of two substitutions.
  for (Block& b : blocks_) {
    const int k = static_cast<int>(b.rows.size());
    with_block_size(k, [&](auto K) {
      invert_block<decltype(K)::value>(b.lu.data(), b.order.data(), b.reciprocal.data(), b.inverse.data(), work_.data(), k);
    });
  }
  inverted_ = true;
}

bool BlockLU::compute(const Matrix& A) {
  std::vector<int> all(size_);
  std::iota(all.begin(), all.end(), 0);
  const bool regular = compute(A, all);
  if (regular) invert();
  return regular;
}

template <typename Fill>
bool BlockLU::compute_from(Fill fill, const std::vector<int>& cols) {
  if (static_cast<int>(cols.size()) != size_) throw std::invalid_argument("BlockLU: size differs from the pattern");
  bool regular = true;
  inverted_ = false;
  std::size_t first = 0;
  for (Block& b : blocks_) {
    fill(b, first);
    first += b.lu.size();
    regular = factor(b) && regular;
  }
  return regular;
}

bool BlockLU::compute(const Matrix& A, const std::vector<int>& cols) {
  if (A.rows() != size_) throw std::invalid_argument("BlockLU: size differs from the pattern");
  return compute_from(
      [&A, &cols](Block& b, std::size_t) {
        const int k = static_cast<int>(b.rows.size());
        for (int c = 0; c < k; ++c)
          for (int i = 0; i < k; ++i) b.lu[c * k + i] = A(b.rows[i], cols[b.cols[c]]);
      },
      cols);
}

bool BlockLU::compute_rows(const double* a, Eigen::Index ld, const std::vector<int>& cols) {
  return compute_from(
      [&](Block& b, std::size_t first) {
        if (first == 0 && (ld != gather_ld_ || cols != gather_cols_)) {  // (cols' size checked by now)
          gather_.clear();
          for (const Block& each : blocks_) {
            const int k = static_cast<int>(each.rows.size());
            for (int c = 0; c < k; ++c)
              for (int i = 0; i < k; ++i) gather_.push_back(each.rows[i] * ld + cols[each.cols[c]]);
          }
          gather_ld_ = ld;
          gather_cols_ = cols;
        }
        const Eigen::Index* from = gather_.data() + first;
        for (std::size_t t = 0; t < b.lu.size(); ++t) b.lu[t] = a[from[t]];
      },
      cols);
}

template <bool kTransposed>
void BlockLU::apply_inverses(const double* rhs, Eigen::Index ldb, Eigen::Index nrhs, double* x,
                             Eigen::Index ldx) const {
  double* __restrict t = work_.data();
  for (Eigen::Index c = 0; c < nrhs; ++c) {
    const double* bc = rhs + c * ldb;
    for (int i = 0; i < size_; ++i) t[i] = bc[i];
    double* xc = x + c * ldx;
    for (const Block& b : blocks_) {
      const int k = static_cast<int>(b.rows.size());
      const double* __restrict inv = b.inverse.data();
      // A^-1 takes the block's rows to its columns; A^-T its columns to its rows, the inverse
      // read by columns
      const int* __restrict from = kTransposed ? b.cols.data() : b.rows.data();
      const int* __restrict to = kTransposed ? b.rows.data() : b.cols.data();
      double* __restrict z = t + size_;
      bool zero = true;
      for (int j = 0; j < k; ++j) zero = (z[j] = t[from[j]]) == 0.0 && zero;
      if (zero) {  // a right-hand side that does not reach this block (another loop's column)
        for (int i = 0; i < k; ++i) xc[to[i]] = 0.0;
        continue;
      }
      for (int i = 0; i < k; ++i) {
        double sum = 0.0;
        for (int j = 0; j < k; ++j) sum += (kTransposed ? inv[j * k + i] : inv[i * k + j]) * z[j];
        xc[to[i]] = sum;
      }
    }
  }
}

void BlockLU::solve(const double* rhs, Eigen::Index ldb, Eigen::Index nrhs, double* x, Eigen::Index ldx) const {
  if (inverted_) apply_inverses<false>(rhs, ldb, nrhs, x, ldx);
  else substitute(rhs, ldb, nrhs, x, ldx);
}

void BlockLU::substitute(const double* rhs, Eigen::Index ldb, Eigen::Index nrhs, double* x, Eigen::Index ldx) const {
  double* __restrict t = work_.data();
  for (Eigen::Index c = 0; c < nrhs; ++c) {
    const double* bc = rhs + c * ldb;
    for (int i = 0; i < size_; ++i) t[i] = bc[i];
    double* xc = x + c * ldx;
    for (const Block& b : blocks_) {
      const int k = static_cast<int>(b.rows.size());
      double* z = t + size_;
      for (int i = 0; i < k; ++i) z[i] = t[b.rows[b.order[i]]];  // in the factors' order
      apply_factors(b, z);
      for (int i = 0; i < k; ++i) xc[b.cols[i]] = z[i];
    }
  }
}

void BlockLU::transpose_solve(const double* rhs, Eigen::Index ldb, Eigen::Index nrhs, double* x,
                              Eigen::Index ldx) const {
  if (!inverted_) throw std::logic_error("BlockLU: transpose_solve before invert");
  apply_inverses<true>(rhs, ldb, nrhs, x, ldx);
}

BlockLU::Matrix BlockLU::solve(const Matrix& b) const {
  Matrix x(size_, b.cols());
  solve(b.data(), b.rows(), b.cols(), x.data(), size_);
  return x;
}

BlockLU::Matrix BlockLU::transpose_solve(const Matrix& b) const {
  Matrix x(size_, b.cols());
  transpose_solve(b.data(), b.rows(), b.cols(), x.data(), size_);
  return x;
}

}  // namespace dydp::mbs
