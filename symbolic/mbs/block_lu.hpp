// LU factors of a square matrix that is block diagonal up to a permutation of its rows and
// columns: the dependent columns Jv of a car's constraint Jacobian, where each suspension corner
// and the steering loop close on their own. Each block is factored and solved on its own, so a
// solve costs the sum of the blocks' (k^3 / 3 + k^2 per right-hand side), not that of the whole.
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
  // Factors A (the pattern's size; entries outside the pattern are ignored).
  void compute(const Matrix& A);
  // x with A x = b, and y with A^T y = b (b: rows x right-hand sides).
  Matrix solve(const Matrix& b) const;
  Matrix transpose_solve(const Matrix& b) const;
  int blocks() const { return static_cast<int>(blocks_.size()); }
  int size() const { return size_; }

 private:
  struct Block {
    std::vector<int> rows, cols;
    Eigen::PartialPivLU<Matrix> lu;
    Matrix work;
  };
  std::vector<Block> blocks_;
  int size_ = 0;
};

}  // namespace dydp::mbs
