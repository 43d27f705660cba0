// The CVODES Newton solver (engine/dense_lu_solver): solves a dense system as Eigen's
// full-pivoting LU does (an independent factorisation), needs no pivoting-free matrix, and
// reports a singular matrix as SUNDIALS' dense solver does (a recoverable factorisation
// failure naming the column), so CVODES retries with a smaller step. Solves in place too.
#include "engine/analysis/dense_lu_solver.hpp"

#include <gtest/gtest.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <Eigen/Dense>
#include <random>

namespace {

// The solver on matrix A with right-hand side b: SUNDIALS' matrix and vectors, freed at the end.
struct System {
  SUNContext ctx = nullptr;
  SUNMatrix M = nullptr;
  N_Vector x = nullptr, rhs = nullptr;
  SUNLinearSolver S = nullptr;
  System(const Eigen::MatrixXd& A, const Eigen::VectorXd& b) {
    const auto n = static_cast<int>(A.rows());
    SUNContext_Create(nullptr, &ctx);
    M = SUNDenseMatrix(n, n, ctx);
    Eigen::Map<Eigen::MatrixXd>(SM_DATA_D(M), n, n) = A;
    x = N_VNew_Serial(n, ctx);
    rhs = N_VNew_Serial(n, ctx);
    Eigen::Map<Eigen::VectorXd>(NV_DATA_S(rhs), n) = b;
    S = dydp::engine::make_dense_lu_solver(ctx);
  }
  ~System() {
    SUNLinSolFree(S);
    N_VDestroy(x);
    N_VDestroy(rhs);
    SUNMatDestroy(M);
    SUNContext_Free(&ctx);
  }
};

TEST(DenseLuSolver, SolvesLikeAnIndependentFactorisation) {
  const int n = 52;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = u(rng);
  A(0, 0) = 0.0;  // needs a row exchange at the first column
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) b[i] = u(rng);

  System sys(A, b);
  SUNMatrix M = sys.M;
  N_Vector x = sys.x, rhs = sys.rhs;
  SUNLinearSolver S = sys.S;
  EXPECT_EQ(SUNLinSolGetType(S), SUNLINEARSOLVER_DIRECT);
  ASSERT_EQ(SUNLinSolInitialize(S), SUNLS_SUCCESS);
  ASSERT_EQ(SUNLinSolSetup(S, M), SUNLS_SUCCESS);
  ASSERT_EQ(SUNLinSolSolve(S, M, x, rhs, 0.0), SUNLS_SUCCESS);
  const Eigen::VectorXd expected = A.fullPivLu().solve(b);
  const Eigen::Map<const Eigen::VectorXd> got(NV_DATA_S(x), n);
  EXPECT_LT((got - expected).cwiseAbs().maxCoeff(), 1e-11 * expected.cwiseAbs().maxCoeff());
  EXPECT_LT((A * got - b).cwiseAbs().maxCoeff(), 1e-12);

  // in place (x is b), for a right-hand side whose first entries are zero (substitution skips
  // zero entries)
  Eigen::VectorXd b2 = b;
  b2.head(10).setZero();
  Eigen::Map<Eigen::VectorXd>(NV_DATA_S(rhs), n) = b2;
  ASSERT_EQ(SUNLinSolSolve(S, M, rhs, rhs, 0.0), SUNLS_SUCCESS);
  const Eigen::VectorXd expected2 = A.fullPivLu().solve(b2);
  const Eigen::Map<const Eigen::VectorXd> got2(NV_DATA_S(rhs), n);
  EXPECT_LT((got2 - expected2).cwiseAbs().maxCoeff(), 1e-11 * expected2.cwiseAbs().maxCoeff());

  // a zero column: singular, reported at that column (1-based)
  Eigen::Map<Eigen::MatrixXd>(SM_DATA_D(M), n, n).col(7).setZero();
  EXPECT_EQ(SUNLinSolSetup(S, M), SUNLS_LUFACT_FAIL);
  EXPECT_GT(SUNLinSolLastFlag(S), 0);
  EXPECT_GT(SUNLS_LUFACT_FAIL, 0) << "a positive flag is recoverable for CVODES";
}

// The Newton matrix of a second-order system, I - gamma J with J = [0 I; K C] over positions and
// velocities plus states of first order: the position rows are x_i - gamma x_j = b_i. They are
// substituted out (the factored system is the other rows only, seen in the solver's size) and the
// solution is that of an independent factorisation of the whole matrix; rows of that form whose
// partner has it too (a chain x_a - g x_b, x_b - g x_c) are kept; a singular kept system is
// reported at a column of the whole matrix.
TEST(DenseLuSolver, SubstitutesRowsOfTheFormXiPlusCXj) {
  const int positions = 6, first_order = 5, n = 2 * positions + first_order + 2;
  const double gamma = 0.013;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(n, n);
  for (int i = 0; i < positions; ++i) A(i, positions + i) = -gamma;  // x_i' = v_i
  for (int i = positions; i < n - 2; ++i)
    for (int j = 0; j < n - 2; ++j) A(i, j) -= gamma * 1e3 * u(rng);
  // a chain: x_{n-2}' = x_{n-1}, x_{n-1}' = x_0
  A(n - 2, n - 1) = -gamma;
  A(n - 1, 0) = -gamma;
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) b[i] = u(rng);

  System sys(A, b);
  SUNMatrix M = sys.M;
  N_Vector x = sys.x, rhs = sys.rhs;
  SUNLinearSolver S = sys.S;
  ASSERT_EQ(SUNLinSolInitialize(S), SUNLS_SUCCESS);
  ASSERT_EQ(SUNLinSolSetup(S, M), SUNLS_SUCCESS);
  long real_words = 0, integer_words = 0;
  ASSERT_EQ(SUNLinSolSpace(S, &real_words, &integer_words), SUNLS_SUCCESS);
  // the six positions; the chain's rows are kept: each one's partner has the form itself
  // (x_{n-2} reads x_{n-1}, x_{n-1} reads x_0)
  const int eliminated = positions, kept = n - eliminated;
  EXPECT_EQ(real_words, 2L * kept * kept + static_cast<long>(kept) * eliminated + eliminated);
  ASSERT_EQ(SUNLinSolSolve(S, M, x, rhs, 0.0), SUNLS_SUCCESS);
  const Eigen::VectorXd expected = A.fullPivLu().solve(b);
  const Eigen::Map<const Eigen::VectorXd> got(NV_DATA_S(x), n);
  EXPECT_LT((got - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());
  EXPECT_LT((A * got - b).cwiseAbs().maxCoeff(), 1e-12);

  // in place
  ASSERT_EQ(SUNLinSolSolve(S, M, rhs, rhs, 0.0), SUNLS_SUCCESS);
  const Eigen::Map<const Eigen::VectorXd> got_in_place(NV_DATA_S(rhs), n);
  EXPECT_LT((got_in_place - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());

  // a zero velocity column in the kept rows and in the position row that reads it: singular
  Eigen::Map<Eigen::MatrixXd> whole(SM_DATA_D(M), n, n);
  whole.col(positions + 2).setZero();
  EXPECT_EQ(SUNLinSolSetup(S, M), SUNLS_LUFACT_FAIL);
  EXPECT_GT(SUNLinSolLastFlag(S), 0);
  EXPECT_LE(SUNLinSolLastFlag(S), n);
}

}  // namespace
