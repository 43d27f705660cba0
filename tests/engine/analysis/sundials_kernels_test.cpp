// engine/sundials_kernels: the compiled vector and matrix kernels give the library's own results
// bit for bit (the library's functions, called directly, are the reference), for the coefficient
// values the library treats apart (+-1, a == b, a == -b, 0), for results written over an
// operand, and for the fused operations' one-, two- and many-vector forms. And the kernels are
// in place: a vector cloned after the replacement carries them, and so does a matrix clone.
#include "engine/analysis/sundials_kernels.hpp"

#include <gtest/gtest.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunmatrix/sunmatrix_dense.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

namespace {

constexpr int kN = 37;  // odd: a vectorised loop's remainder is exercised too

struct Vectors {
  SUNContext ctx = nullptr;
  N_Vector plain = nullptr, fast = nullptr;
  std::mt19937 rng{11};
  Vectors() {
    SUNContext_Create(nullptr, &ctx);
    plain = N_VNew_Serial(kN, ctx);
    N_VEnableFusedOps_Serial(plain, SUNTRUE);
    fast = N_VClone(plain);
    dydp::engine::use_compiled_vector_kernels(fast);
  }
  ~Vectors() {
    N_VDestroy(plain);
    N_VDestroy(fast);
    SUNContext_Free(&ctx);
  }
  // a vector of kind `like` (plain: the library's ops; fast: the kernels) filled at random,
  // entries of mixed signs and magnitudes
  N_Vector make(N_Vector like) {
    N_Vector v = N_VClone(like);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int i = 0; i < kN; ++i) NV_Ith_S(v, i) = u(rng) * std::pow(10.0, 6.0 * u(rng));
    return v;
  }
  static void copy(N_Vector from, N_Vector to) { std::memcpy(NV_DATA_S(to), NV_DATA_S(from), sizeof(double) * kN); }
};

bool same_bits(N_Vector a, N_Vector b) { return std::memcmp(NV_DATA_S(a), NV_DATA_S(b), sizeof(double) * kN) == 0; }
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

const double kCoefficients[] = {1.0, -1.0, 0.0, 0.37, -0.37, 2.5, 1.0 / 3.0};

TEST(SundialsKernels, LinearSumAsTheLibraryForEveryCoefficientFormAndAliasing) {
  Vectors V;
  N_Vector x = V.make(V.plain), y = V.make(V.plain);
  N_Vector xf = V.make(V.fast), yf = V.make(V.fast);
  Vectors::copy(x, xf);
  Vectors::copy(y, yf);
  N_Vector z = N_VClone(V.plain), zf = N_VClone(V.fast);
  int differing_forms = 0;  // how many (a, b) make the c (x + y) form differ from a x + b y
  for (double a : kCoefficients) {
    for (double b : kCoefficients) {
      // z apart, z over y, z over x
      for (int where = 0; where < 3; ++where) {
        N_Vector px = N_VClone(V.plain), py = N_VClone(V.plain), fx = N_VClone(V.fast), fy = N_VClone(V.fast);
        Vectors::copy(x, px);
        Vectors::copy(y, py);
        Vectors::copy(x, fx);
        Vectors::copy(y, fy);
        N_Vector pz = where == 0 ? z : where == 1 ? py : px;
        N_Vector fz = where == 0 ? zf : where == 1 ? fy : fx;
        N_VLinearSum_Serial(a, px, b, py, pz);
        N_VLinearSum(a, fx, b, fy, fz);
        EXPECT_TRUE(same_bits(pz, fz)) << "a " << a << " b " << b << " where " << where;
        N_VDestroy(px);
        N_VDestroy(py);
        N_VDestroy(fx);
        N_VDestroy(fy);
      }
      if (a == b && a != 0.0 && std::fabs(a) != 1.0) {
        bool differs = false;
        for (int i = 0; i < kN; ++i)
          differs = differs || a * (NV_Ith_S(x, i) + NV_Ith_S(y, i)) != a * NV_Ith_S(x, i) + b * NV_Ith_S(y, i);
        differing_forms += differs ? 1 : 0;
      }
    }
  }
  // the special form matters: with the plain formula everywhere the results would differ
  EXPECT_GT(differing_forms, 0);
  for (N_Vector v : {x, y, xf, yf, z, zf}) N_VDestroy(v);
}

TEST(SundialsKernels, ElementwiseOperationsAndNormsAsTheLibrary) {
  Vectors V;
  N_Vector x = V.make(V.plain), w = V.make(V.plain);
  N_Vector xf = N_VClone(V.fast), wf = N_VClone(V.fast);
  Vectors::copy(x, xf);
  Vectors::copy(w, wf);
  N_Vector z = N_VClone(V.plain), zf = N_VClone(V.fast);
  for (double c : kCoefficients) {
    N_VScale_Serial(c, x, z);
    N_VScale(c, xf, zf);
    EXPECT_TRUE(same_bits(z, zf)) << "scale " << c;
    N_VAddConst_Serial(x, c, z);
    N_VAddConst(xf, c, zf);
    EXPECT_TRUE(same_bits(z, zf)) << "add constant " << c;
    N_VConst_Serial(c, z);
    N_VConst(c, zf);
    EXPECT_TRUE(same_bits(z, zf)) << "constant " << c;
  }
  N_VProd_Serial(x, w, z);
  N_VProd(xf, wf, zf);
  EXPECT_TRUE(same_bits(z, zf));
  N_VDiv_Serial(x, w, z);
  N_VDiv(xf, wf, zf);
  EXPECT_TRUE(same_bits(z, zf));
  N_VAbs_Serial(x, z);
  N_VAbs(xf, zf);
  EXPECT_TRUE(same_bits(z, zf));
  N_VInv_Serial(x, z);
  N_VInv(xf, zf);
  EXPECT_TRUE(same_bits(z, zf));
  EXPECT_TRUE(same_bits(N_VMaxNorm_Serial(x), N_VMaxNorm(xf)));
  EXPECT_TRUE(same_bits(N_VWSqrSumLocal_Serial(x, w), N_VWSqrSumLocal(xf, wf)));
  EXPECT_TRUE(same_bits(N_VWrmsNorm_Serial(x, w), N_VWrmsNorm(xf, wf)));
  EXPECT_GT(N_VWrmsNorm(xf, wf), 0.0);
  for (N_Vector v : {x, w, xf, wf, z, zf}) N_VDestroy(v);
}

TEST(SundialsKernels, FusedOperationsAsTheLibraryForOneTwoAndManyVectors) {
  Vectors V;
  const int most = 5;
  std::vector<N_Vector> X, Xf, Y, Yf;
  for (int i = 0; i < most; ++i) {
    X.push_back(V.make(V.plain));
    Xf.push_back(N_VClone(V.fast));
    Vectors::copy(X.back(), Xf.back());
    Y.push_back(V.make(V.plain));
    Yf.push_back(N_VClone(V.fast));
    Vectors::copy(Y.back(), Yf.back());
  }
  std::vector<double> c = {1.0, 0.5, -2.0, 0.5, 3.0};
  N_Vector z = N_VClone(V.plain), zf = N_VClone(V.fast);
  for (double c0 : {1.0, 0.5}) {
    c[0] = c0;
    for (int count = 1; count <= most; ++count) {
      // z apart
      ASSERT_EQ(N_VLinearCombination_Serial(count, c.data(), X.data(), z), 0);
      ASSERT_EQ(N_VLinearCombination(count, c.data(), Xf.data(), zf), 0);
      EXPECT_TRUE(same_bits(z, zf)) << "linear combination of " << count << ", c0 " << c0;
      // z the first vector: accumulated in place
      N_Vector p0 = N_VClone(V.plain), f0 = N_VClone(V.fast);
      Vectors::copy(X[0], p0);
      Vectors::copy(X[0], f0);
      std::vector<N_Vector> Xp = X, Xq = Xf;
      Xp[0] = p0;
      Xq[0] = f0;
      N_VLinearCombination_Serial(count, c.data(), Xp.data(), p0);
      N_VLinearCombination(count, c.data(), Xq.data(), f0);
      EXPECT_TRUE(same_bits(p0, f0)) << "in place, " << count << ", c0 " << c0;
      N_VDestroy(p0);
      N_VDestroy(f0);
      // Z_i = c_i x + Y_i, apart and over Y
      std::vector<N_Vector> Z, Zf;
      for (int i = 0; i < count; ++i) {
        Z.push_back(N_VClone(V.plain));
        Zf.push_back(N_VClone(V.fast));
      }
      N_VScaleAddMulti_Serial(count, c.data(), X[1], Y.data(), Z.data());
      N_VScaleAddMulti(count, c.data(), Xf[1], Yf.data(), Zf.data());
      for (int i = 0; i < count; ++i) EXPECT_TRUE(same_bits(Z[i], Zf[i])) << "scale-add " << count << " #" << i;
      for (int i = 0; i < count; ++i) {
        N_VDestroy(Z[i]);
        N_VDestroy(Zf[i]);
      }
    }
  }
  for (int i = 0; i < most; ++i)
    for (N_Vector v : {X[i], Xf[i], Y[i], Yf[i]}) N_VDestroy(v);
  N_VDestroy(z);
  N_VDestroy(zf);
}

// The sensitivities' operations: arrays of vectors (X[i]) and arrays of arrays (X[j][i]).
TEST(SundialsKernels, VectorArrayOperationsAsTheLibrary) {
  Vectors V;
  const int count = 3, sums = 4;
  // X[j][i], Y[j][i] for j < sums, i < count, and the outputs
  std::vector<std::vector<N_Vector>> X(sums), Xf(sums), Y(sums), Yf(sums), Z(sums), Zf(sums);
  for (int j = 0; j < sums; ++j) {
    for (int i = 0; i < count; ++i) {
      X[j].push_back(V.make(V.plain));
      Xf[j].push_back(N_VClone(V.fast));
      Vectors::copy(X[j][i], Xf[j][i]);
      Y[j].push_back(V.make(V.plain));
      Yf[j].push_back(N_VClone(V.fast));
      Vectors::copy(Y[j][i], Yf[j][i]);
      Z[j].push_back(N_VClone(V.plain));
      Zf[j].push_back(N_VClone(V.fast));
    }
  }
  std::vector<N_Vector*> Xp, Xq, Yp, Yq, Zp, Zq;
  for (int j = 0; j < sums; ++j) {
    Xp.push_back(X[j].data());
    Xq.push_back(Xf[j].data());
    Yp.push_back(Y[j].data());
    Yq.push_back(Yf[j].data());
    Zp.push_back(Z[j].data());
    Zq.push_back(Zf[j].data());
  }
  const auto same_all = [&](int rows, int columns) {
    bool same = true;
    for (int j = 0; j < rows; ++j)
      for (int i = 0; i < columns; ++i) same = same && same_bits(Z[j][i], Zf[j][i]);
    return same;
  };
  std::vector<double> c = {0.5, 0.5, -2.0, 1.0};
  for (int n : {1, count}) {
    for (double a : kCoefficients) {
      ASSERT_EQ(N_VLinearSumVectorArray_Serial(n, a, Xp[0], 0.5, Yp[0], Zp[0]), 0);
      ASSERT_EQ(N_VLinearSumVectorArray(n, a, Xq[0], 0.5, Yq[0], Zq[0]), 0);
      EXPECT_TRUE(same_all(1, n)) << "linear sum array " << n << " a " << a;
      ASSERT_EQ(N_VConstVectorArray_Serial(n, a, Zp[0]), 0);
      ASSERT_EQ(N_VConstVectorArray(n, a, Zq[0]), 0);
      EXPECT_TRUE(same_all(1, n));
    }
    ASSERT_EQ(N_VScaleVectorArray_Serial(n, c.data(), Xp[0], Zp[0]), 0);
    ASSERT_EQ(N_VScaleVectorArray(n, c.data(), Xq[0], Zq[0]), 0);
    EXPECT_TRUE(same_all(1, n));
    std::vector<double> norm(n), norm_fast(n);
    ASSERT_EQ(N_VWrmsNormVectorArray_Serial(n, Xp[0], Yp[0], norm.data()), 0);
    ASSERT_EQ(N_VWrmsNormVectorArray(n, Xq[0], Yq[0], norm_fast.data()), 0);
    for (int i = 0; i < n; ++i) EXPECT_TRUE(same_bits(norm[i], norm_fast[i]));
    for (int s = 1; s <= sums; ++s) {
      ASSERT_EQ(N_VScaleAddMultiVectorArray_Serial(n, s, c.data(), Xp[0], Yp.data(), Zp.data()), 0);
      ASSERT_EQ(N_VScaleAddMultiVectorArray(n, s, c.data(), Xq[0], Yq.data(), Zq.data()), 0);
      EXPECT_TRUE(same_all(s, n)) << "scale-add array " << n << " x " << s;
      ASSERT_EQ(N_VLinearCombinationVectorArray_Serial(n, s, c.data(), Xp.data(), Zp[0]), 0);
      ASSERT_EQ(N_VLinearCombinationVectorArray(n, s, c.data(), Xq.data(), Zq[0]), 0);
      EXPECT_TRUE(same_all(1, n)) << "combination array " << n << " x " << s;
    }
  }
  for (int j = 0; j < sums; ++j)
    for (int i = 0; i < count; ++i)
      for (N_Vector v : {X[j][i], Xf[j][i], Y[j][i], Yf[j][i], Z[j][i], Zf[j][i]}) N_VDestroy(v);
}

TEST(SundialsKernels, ClonesCarryTheKernels) {
  Vectors V;
  N_Vector clone = N_VClone(V.fast);
  EXPECT_NE(V.plain->ops->nvlinearsum, V.fast->ops->nvlinearsum);
  EXPECT_EQ(clone->ops->nvlinearsum, V.fast->ops->nvlinearsum);
  EXPECT_EQ(clone->ops->nvscaleaddmulti, V.fast->ops->nvscaleaddmulti);
  N_VDestroy(clone);

  SUNMatrix plain = SUNDenseMatrix(kN, kN, V.ctx), fast = SUNDenseMatrix(kN, kN, V.ctx);
  dydp::engine::use_compiled_matrix_kernels(fast);
  SUNMatrix fast_clone = SUNMatClone(fast);
  EXPECT_EQ(fast_clone->ops->scaleaddi, fast->ops->scaleaddi);
  EXPECT_NE(plain->ops->scaleaddi, fast->ops->scaleaddi);
  SUNMatDestroy(fast_clone);
  SUNMatDestroy(plain);
  SUNMatDestroy(fast);
}

TEST(SundialsKernels, MatrixOperationsAsTheLibrary) {
  Vectors V;
  SUNMatrix a = SUNDenseMatrix(kN, kN, V.ctx), b = SUNDenseMatrix(kN, kN, V.ctx);
  SUNMatrix af = SUNDenseMatrix(kN, kN, V.ctx);
  dydp::engine::use_compiled_matrix_kernels(af);
  SUNMatrix bf = SUNMatClone(af);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int k = 0; k < kN * kN; ++k) SM_DATA_D(a)[k] = SM_DATA_D(af)[k] = u(V.rng) * 1e3;
  const auto same = [](SUNMatrix p, SUNMatrix q) {
    return std::memcmp(SM_DATA_D(p), SM_DATA_D(q), sizeof(double) * kN * kN) == 0;
  };
  ASSERT_EQ(SUNMatCopy_Dense(a, b), SUNMAT_SUCCESS);
  ASSERT_EQ(SUNMatCopy(af, bf), SUNMAT_SUCCESS);
  EXPECT_TRUE(same(b, bf));
  ASSERT_EQ(SUNMatScaleAddI_Dense(-0.0123, b), SUNMAT_SUCCESS);
  ASSERT_EQ(SUNMatScaleAddI(-0.0123, bf), SUNMAT_SUCCESS);
  EXPECT_TRUE(same(b, bf));
  EXPECT_FALSE(same(a, bf));  // the operation did something
  ASSERT_EQ(SUNMatZero(bf), SUNMAT_SUCCESS);
  for (int k = 0; k < kN * kN; ++k) EXPECT_EQ(SM_DATA_D(bf)[k], 0.0);
  SUNMatrix wrong = SUNDenseMatrix(kN, kN + 1, V.ctx);
  EXPECT_NE(SUNMatCopy(af, wrong), SUNMAT_SUCCESS);
  for (SUNMatrix m : {a, b, af, bf, wrong}) SUNMatDestroy(m);
}

}  // namespace
