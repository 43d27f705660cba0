// The dense LU of a Newton matrix I - gamma J (CVODES' BDF, the Rosenbrock-W replay scheme).
//
// Rows of the form x_i + c x_j = b_i (a unit diagonal and one other entry: a state whose
// derivative is another state, the car's positions) are substituted out, x_i = b_i - c x_j, and
// only the other rows are factored, by Eigen's partial-pivoting LU (blocked and vectorised): 38 of
// the main job's 52 states, a third of the factorisation's work and a quarter of each solve's.
// Solves by plain column-oriented substitutions (Eigen's panelled triangular solves are slow at
// this size).
#pragma once

#include <Eigen/Dense>
#include <vector>

namespace dydp::engine {

class NewtonLU {
 public:
  // Factors the n x n column-major matrix a (leading dimension n). False at a zero or
  // non-finite pivot, whose column (0-based, of a) failed_column() then gives.
  bool factor(const double* a, int n);
  // x = A^-1 b for the last factored A; x may be b.
  void solve(const double* b, double* x) const;
  int failed_column() const { return failed_column_; }
  // The storage held (the factored rows only: the substituted ones are not factored).
  long real_words() const;
  long integer_words() const;

 private:
  void find_substituted_rows(const double* a, int n);

  int failed_column_ = -1;
  std::vector<int> other_;      // scratch of find_substituted_rows: a row's one off-diagonal column
  std::vector<char> candidate_;
  std::vector<int> substituted_, partner_, kept_;  // substituted_[e] = i, partner_[e] = j
  std::vector<double> coefficient_;                // c
  std::vector<int> place_;                         // row of a -> place among kept_ (-1: substituted)
  Eigen::MatrixXd coupling_;                       // a(kept, substituted): how b_i enters the kept rows
  Eigen::MatrixXd work_;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu_;
  mutable Eigen::VectorXd kept_rhs_, permuted_;    // scratch of solve()
};

}  // namespace dydp::engine
