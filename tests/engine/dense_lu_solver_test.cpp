// The CVODES Newton solver (engine/dense_lu_solver): solves a dense system as Eigen's
// full-pivoting LU does (an independent factorisation), needs no pivoting-free matrix, and
// reports a singular matrix as SUNDIALS' dense solver does (a recoverable factorisation
// failure naming the column), so CVODES retries with a smaller step. Solves in place too.
#include "engine/dense_lu_solver.hpp"

#include <gtest/gtest.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <Eigen/Dense>
#include <random>

namespace {

struct Fixture {
  SUNContext ctx = nullptr;
  Fixture() { SUNContext_Create(nullptr, &ctx); }
  ~Fixture() { SUNContext_Free(&ctx); }
};

TEST(DenseLuSolver, SolvesLikeAnIndependentFactorisation) {
  Fixture f;
  const int n = 52;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) A(i, j) = u(rng);
  A(0, 0) = 0.0;  // needs a row exchange at the first column
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) b[i] = u(rng);

  SUNMatrix M = SUNDenseMatrix(n, n, f.ctx);
  Eigen::Map<Eigen::MatrixXd>(SM_DATA_D(M), n, n) = A;
  N_Vector x = N_VNew_Serial(n, f.ctx), rhs = N_VNew_Serial(n, f.ctx);
  Eigen::Map<Eigen::VectorXd>(NV_DATA_S(rhs), n) = b;
  SUNLinearSolver S = dydp::engine::make_dense_lu_solver(f.ctx, n);
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
  SUNLinSolFree(S);
  N_VDestroy(x);
  N_VDestroy(rhs);
  SUNMatDestroy(M);
}

}  // namespace
