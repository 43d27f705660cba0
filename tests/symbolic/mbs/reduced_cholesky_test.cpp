// ReducedCholesky against an independent factorisation (Eigen's LDLT) on random symmetric
// positive definite matrices, for a car's size (plain loops) and past kSmall (Eigen's LLT):
// solutions of several right-hand sides agree, and a matrix that is not positive definite is
// refused.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "symbolic/mbs/reduced_cholesky.hpp"

namespace {

using dydp::mbs::ReducedCholesky;
using Matrix = Eigen::MatrixXd;

Matrix random_spd(int n, unsigned seed) {
  std::srand(seed);
  const Matrix a = Matrix::Random(n, n);
  return a * a.transpose() + n * Matrix::Identity(n, n);
}

double relative_difference(const Matrix& x, const Matrix& y) { return (x - y).norm() / y.norm(); }

TEST(ReducedCholesky, SolvesLikeAnIndependentFactorisationBelowAndAboveTheSmallSize) {
  for (const int n : {1, 3, 14, ReducedCholesky::kSmall, ReducedCholesky::kSmall + 9}) {
    const Matrix a = random_spd(n, 7u + static_cast<unsigned>(n));
    ReducedCholesky c;
    ASSERT_TRUE(c.compute(a)) << n;
    EXPECT_EQ(c.size(), n);
    Matrix x = Matrix::Random(n, 5);
    const Matrix expected = a.ldlt().solve(x);
    c.solve_in_place(x);
    EXPECT_LT(relative_difference(x, expected), 1e-12) << n;
    if (n <= ReducedCholesky::kSmall) {  // several right-hand sides as each alone, bit for bit
      const Matrix b = Matrix::Random(n, 5);
      Matrix together = b;
      c.solve_in_place(together);
      for (int j = 0; j < 5; ++j) {
        Eigen::VectorXd alone = b.col(j);
        c.solve_in_place(alone);
        EXPECT_EQ((alone - together.col(j)).cwiseAbs().maxCoeff(), 0.0) << n << ", column " << j;
      }
    }
    Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
    const Eigen::VectorXd v_expected = a.ldlt().solve(v);
    c.solve_in_place(v);
    EXPECT_LT((v - v_expected).norm() / v_expected.norm(), 1e-12) << n;
    // a column inside a larger array (leading dimension n + 2)
    Matrix padded = Matrix::Zero(n + 2, 2);
    padded.topRows(n) = Matrix::Ones(n, 2);
    c.solve_in_place(padded.data(), n + 2, 2);
    EXPECT_LT(relative_difference(padded.topRows(n), a.ldlt().solve(Matrix::Ones(n, 2))), 1e-12) << n;
    EXPECT_EQ(padded.bottomRows(2).norm(), 0.0) << "rows past the matrix are not touched";
  }
}

TEST(ReducedCholesky, RefusesAMatrixThatIsNotPositiveDefinite) {
  for (const int n : {4, ReducedCholesky::kSmall + 4}) {
    Matrix a = random_spd(n, 3u);
    a(n - 1, n - 1) = -1.0;  // its last pivot is negative
    ReducedCholesky c;
    EXPECT_FALSE(c.compute(a)) << n;
    a(n - 1, n - 1) = std::numeric_limits<double>::quiet_NaN();
    EXPECT_FALSE(c.compute(a)) << n;
  }
}

}  // namespace
