// Block-diagonal LU against Eigen's dense LU on permuted block matrices, and the block structure
// the sedan's loops give Jv (four corners, each closed on its own).
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "generated_models/registry.hpp"
#include "symbolic/mbs/block_lu.hpp"

namespace dydp::mbs {
namespace {

using Matrix = Eigen::MatrixXd;
using Pattern = Eigen::Matrix<char, Eigen::Dynamic, Eigen::Dynamic>;

TEST(BlockLU, SolvesPermutedBlockMatricesLikeADenseLU) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const std::vector<int> sizes{4, 1, 5, 3};
  const int m = std::accumulate(sizes.begin(), sizes.end(), 0);
  Matrix A = Matrix::Zero(m, m);
  int at = 0;
  for (int k : sizes) {
    A.block(at, at, k, k) = Matrix::NullaryExpr(k, k, [&] { return u(rng); }) + 3.0 * Matrix::Identity(k, k);
    at += k;
  }
  std::vector<int> rows(m), cols(m);
  std::iota(rows.begin(), rows.end(), 0);
  std::iota(cols.begin(), cols.end(), 0);
  std::shuffle(rows.begin(), rows.end(), rng);
  std::shuffle(cols.begin(), cols.end(), rng);
  Matrix P(m, m);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) P(i, j) = A(rows[i], cols[j]);
  BlockLU lu;
  lu.set_pattern(P.cwiseAbs().unaryExpr([](double x) { return x != 0.0; }).cast<char>());
  EXPECT_EQ(lu.blocks(), 4);
  lu.compute(P);
  const Matrix b = Matrix::NullaryExpr(m, 3, [&] { return u(rng); });
  const Eigen::PartialPivLU<Matrix> dense(P);
  EXPECT_LT((lu.solve(b) - dense.solve(b)).cwiseAbs().maxCoeff(), 1e-12);
  const Matrix dense_transposed = P.transpose().partialPivLu().solve(b);
  EXPECT_LT((lu.transpose_solve(b) - dense_transposed).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(BlockLU, PivotsOnZeroDiagonalsAndSolvesInPlace) {
  // two blocks whose leading entries are zero: elimination without row exchanges would divide
  // by zero; solved in place (x given as b), as the partitioning does
  Matrix A = Matrix::Zero(5, 5);
  A.block(0, 0, 3, 3) << 0.0, 2.0, 1.0,  //
      4.0, 0.0, -1.0,                    //
      1.0, 1e-3, 0.0;
  A.block(3, 3, 2, 2) << 0.0, 3.0,  //
      -2.0, 0.5;
  BlockLU lu;
  lu.set_pattern(A.unaryExpr([](double x) { return x != 0.0; }).cast<char>());
  ASSERT_EQ(lu.blocks(), 2);
  ASSERT_TRUE(lu.compute(A));
  const Eigen::PartialPivLU<Matrix> dense(A);
  Matrix b(5, 2);
  b << 1.0, -2.0, 0.5, 3.0, -1.0, 0.25, 2.0, 1.0, -0.5, 4.0;
  Matrix x = b;
  lu.solve(x.data(), 5, 2, x.data(), 5);
  EXPECT_LT((x - dense.solve(b)).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((A * x - b).cwiseAbs().maxCoeff(), 1e-12);
  Matrix y = b;
  lu.transpose_solve(y.data(), 5, 2, y.data(), 5);
  EXPECT_LT((A.transpose() * y - b).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(BlockLU, ReportsASingularBlock) {
  Matrix A = Matrix::Identity(4, 4);
  A(2, 3) = A(3, 2) = 1.0;
  A(2, 2) = A(3, 3) = 1.0;  // the block {2, 3} is [[1, 1], [1, 1]]
  BlockLU lu;
  lu.set_pattern(A.unaryExpr([](double x) { return x != 0.0; }).cast<char>());
  EXPECT_EQ(lu.blocks(), 3);
  EXPECT_FALSE(lu.compute(A));
  A(3, 3) = 2.0;
  EXPECT_TRUE(lu.compute(A));
}

TEST(BlockLU, NonSquareComponentsFallBackToOneBlock) {
  Pattern p = Pattern::Zero(3, 3);
  p(0, 0) = p(1, 0) = p(2, 1) = p(2, 2) = 1;  // rows {0, 1} read column 0 only
  BlockLU lu;
  lu.set_pattern(p);
  EXPECT_EQ(lu.blocks(), 1);
}

TEST(BlockLU, TheSedansLoopsCloseCornerByCorner) {
  const GeneratedModel& g = *generated::find_model("sedan");
  std::vector<int> kind(g.n, 1);
  for (int i = 0; i < g.independent_count; ++i) kind[g.independent[i]] = 0;
  for (int i = 0; i < g.driven_count; ++i) kind[g.driven[i]] = 2;
  std::vector<int> v;
  for (int j = 0; j < g.n; ++j)
    if (kind[j] == 1) v.push_back(j);
  ASSERT_EQ(static_cast<int>(v.size()), g.m);
  Pattern p(g.m, g.m);
  for (int i = 0; i < g.m; ++i)
    for (int k = 0; k < g.m; ++k) p(i, k) = g.jacobian_nonzero[i * g.n + v[k]] != 0;
  BlockLU lu;
  lu.set_pattern(p);
  EXPECT_EQ(lu.blocks(), 4) << "front corners (ball joint and tie rod), rear corners (ball joint and two links)";
  // the chassis' six coordinates (free body) move no cut: their columns of J are zero
  for (int i = 0; i < g.m; ++i)
    for (int j = 0; j < 6; ++j) EXPECT_EQ(g.jacobian_nonzero[i * g.n + j], 0) << i << ", " << j;
}

}  // namespace
}  // namespace dydp::mbs
