// The Cholesky factor of the reduced mass matrix B^T M B. A car's is small (the sedan's 14 x 14)
// and factored and solved at every right-hand side and tangent: there plain loops over a
// row-major factor cost a fraction of a general library call. Beyond kSmall columns (a deep
// chain without constraints) Eigen's blocked LLT is faster, and is used.
#pragma once

#include <Eigen/Dense>
#include <vector>

namespace dydp::mbs {

class ReducedCholesky {
 public:
  using Matrix = Eigen::MatrixXd;
  static constexpr int kSmall = 32;

  // Factors the symmetric positive definite A (its lower triangle is read). False when A is not
  // positive definite (a pivot not positive, or not finite).
  bool compute(const Eigen::Ref<const Matrix>& A);
  // x := A^-1 x for `nrhs` columns of length size(), column-major with leading dimension ld.
  void solve_in_place(double* x, Eigen::Index ld, Eigen::Index nrhs) const;
  template <typename Derived>
  void solve_in_place(Eigen::PlainObjectBase<Derived>& x) const {
    solve_in_place(x.data(), x.rows(), x.cols());
  }
  int size() const { return n_; }

 private:
  int n_ = 0;
  std::vector<double> l_;         // n x n row-major, lower triangle: the factor L (small sizes)
  Eigen::LLT<Matrix> large_;
  mutable std::vector<double> rows_;  // several right-hand sides by rows (solve_in_place)
};

}  // namespace dydp::mbs
