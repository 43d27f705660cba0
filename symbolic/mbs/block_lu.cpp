// Block-diagonal LU (see block_lu.hpp): components by union-find over rows and columns.
#include "symbolic/mbs/block_lu.hpp"

#include <numeric>
#include <stdexcept>

namespace dydp::mbs {

void BlockLU::set_pattern(const Eigen::Matrix<char, Eigen::Dynamic, Eigen::Dynamic>& nonzero) {
  const int m = static_cast<int>(nonzero.rows());
  if (nonzero.cols() != m) throw std::invalid_argument("BlockLU: the pattern must be square");
  size_ = m;
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
}

void BlockLU::compute(const Matrix& A) {
  if (A.rows() != size_ || A.cols() != size_) throw std::invalid_argument("BlockLU: size differs from the pattern");
  for (Block& b : blocks_) {
    const int k = static_cast<int>(b.rows.size());
    b.work.resize(k, k);
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j) b.work(i, j) = A(b.rows[i], b.cols[j]);
    b.lu.compute(b.work);
  }
}

BlockLU::Matrix BlockLU::solve(const Matrix& rhs) const {
  Matrix x(size_, rhs.cols());
  for (const Block& b : blocks_) {
    const int k = static_cast<int>(b.rows.size());
    Matrix part(k, rhs.cols());
    for (int i = 0; i < k; ++i) part.row(i) = rhs.row(b.rows[i]);
    const Matrix y = b.lu.solve(part);
    for (int i = 0; i < k; ++i) x.row(b.cols[i]) = y.row(i);
  }
  return x;
}

BlockLU::Matrix BlockLU::transpose_solve(const Matrix& rhs) const {
  Matrix x(size_, rhs.cols());
  for (const Block& b : blocks_) {
    const int k = static_cast<int>(b.rows.size());
    Eigen::VectorXd part(k);
    for (Eigen::Index c = 0; c < rhs.cols(); ++c) {
      for (int i = 0; i < k; ++i) part[i] = rhs(b.cols[i], c);
      const Eigen::VectorXd y = b.lu.transpose().solve(part);
      for (int i = 0; i < k; ++i) x(b.rows[i], c) = y[i];
    }
  }
  return x;
}

}  // namespace dydp::mbs
