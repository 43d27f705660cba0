// LU factors of a square matrix that is block diagonal up to a permutation of its rows and
// columns: the dependent columns Jv of a car's constraint Jacobian, where each suspension corner
// and the steering loop close on their own. Each block is factored and solved on its own, so a
// solve costs the sum of the blocks' (k^3 / 3 + k^2 per right-hand side), not that of the whole.
// The blocks are small (a corner's four to six coordinates): each is factored by plain loops
// and inverted explicitly (a factorisation serves 15 to 30 right-hand sides), into storage
// sized once by set_pattern, so compute and solve allocate nothing.
#pragma once

#include <Eigen/Dense>
#include <vector>

namespace dydp::mbs {

class BlockLU {
 public:
  using Matrix = Eigen::MatrixXd;

  // The blocks from the structural pattern (nonzero(i, j) != 0: entry (i, j) may be nonzero),
  // the connected components of rows and columns; one block when they are not all square.
  void set_pattern(const Eigen::Matrix<char, Eigen::Dynamic, Eigen::Dynamic>& nonzero);
  // Factors and inverts A (the pattern's size; entries outside the pattern are ignored), or
  // factors only the square matrix made of the columns `cols` of A. False when a block is
  // singular.
  bool compute(const Matrix& A);
  bool compute(const Matrix& A, const std::vector<int>& cols);
  // The same from a row-major array: A(i, j) at a[i * ld + j] (a generated Jacobian as written).
  bool compute_rows(const double* a, Eigen::Index ld, const std::vector<int>& cols);
  // x with A x = b, and y with A^T y = b, for b of the pattern's rows and `nrhs` columns
  // (column-major, leading dimensions ldb and ldx); x may be b.
  // The blocks' inverses from the factors. Before invert(), solve substitutes through the
  // factors (cheaper for one right-hand side, as in a Newton iteration); after it, multiplies by
  // the inverses. transpose_solve needs them.
  void invert();
  void solve(const double* b, Eigen::Index ldb, Eigen::Index nrhs, double* x, Eigen::Index ldx) const;
  void transpose_solve(const double* b, Eigen::Index ldb, Eigen::Index nrhs, double* x, Eigen::Index ldx) const;
  Matrix solve(const Matrix& b) const;
  Matrix transpose_solve(const Matrix& b) const;
  int blocks() const { return static_cast<int>(blocks_.size()); }
  // The rows and the columns of block b (indices into the pattern).
  const std::vector<int>& block_rows(int b) const { return blocks_[b].rows; }
  const std::vector<int>& block_cols(int b) const { return blocks_[b].cols; }
  // Block b's inverse after invert(): k x k row-major, x[block_cols[i]] = sum over j of
  // inverse[i * k + j] * b[block_rows[j]].
  const double* block_inverse(int b) const { return blocks_[b].inverse.data(); }
  int size() const { return size_; }

 private:
  struct Block {
    std::vector<int> rows, cols;
    std::vector<double> lu;   // k x k, column-major: unit lower and upper factors of P A_block
    std::vector<int> order;   // the row exchanges composed: row i of P A_block is row order[i] of A_block
    std::vector<double> reciprocal;  // 1 / U(i, i)
    std::vector<double> inverse;  // k x k, row-major: block column c of x = sum over block rows
  };
  bool factor(Block& b);
  // Checks cols' size, then fill(block, first) sets each block's lu (first: the offset of its
  // entries among all blocks') and the block is factored.
  template <typename Fill>
  bool compute_from(Fill fill, const std::vector<int>& cols);
  // z := A_block^-1 b through L and U, z holding b in the factors' order (z[i] = b[order[i]])
  static void apply_factors(const Block& b, double* z);
  void substitute(const double* b, Eigen::Index ldb, Eigen::Index nrhs, double* x, Eigen::Index ldx) const;
  // x = A^-1 b, or A^-T b (kTransposed), from the blocks' inverses
  template <bool kTransposed>
  void apply_inverses(const double* b, Eigen::Index ldb, Eigen::Index nrhs, double* x, Eigen::Index ldx) const;
  bool inverted_ = false;
  std::vector<Block> blocks_;
  // compute_rows' reads: block by block, entry t of its lu at a[gather_[start + t]], for the
  // leading dimension and columns it was last called with (a Newton iteration calls it with the
  // same ones every time)
  std::vector<Eigen::Index> gather_;
  Eigen::Index gather_ld_ = -1;
  std::vector<int> gather_cols_;
  int size_ = 0;
  mutable std::vector<double> work_;  // a right-hand side gathered whole (x may be b), then a block's part
};

}  // namespace dydp::mbs
