#include "engine/analysis/sundials_kernels.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <nvector/nvector_serial.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <vector>

namespace dydp::engine {
namespace {

double* data(N_Vector v) { return NV_DATA_S(v); }
sunindextype length(N_Vector v) { return NV_LENGTH_S(v); }

// z = a x + b y. The library's special forms give the same values as the plain formula wherever
// a or b is +-1 (products with +-1 are exact); only a == b and a == -b are computed differently,
// as c (x + y) and c (x - y).
void linear_sum(double a, N_Vector x, double b, N_Vector y, N_Vector z) {
  const sunindextype n = length(x);
  const double* xd = data(x);
  const double* yd = data(y);
  double* zd = data(z);
  if (a == b) {
    for (sunindextype i = 0; i < n; ++i) zd[i] = a * (xd[i] + yd[i]);
  } else if (a == -b) {
    for (sunindextype i = 0; i < n; ++i) zd[i] = a * (xd[i] - yd[i]);
  } else {
    for (sunindextype i = 0; i < n; ++i) zd[i] = a * xd[i] + b * yd[i];
  }
}

void constant(double c, N_Vector z) {
  double* zd = data(z);
  std::fill(zd, zd + length(z), c);
}

void scale(double c, N_Vector x, N_Vector z) {
  const sunindextype n = length(x);
  const double* xd = data(x);
  double* zd = data(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = c * xd[i];
}

void product(N_Vector x, N_Vector y, N_Vector z) {
  const sunindextype n = length(x);
  const double* xd = data(x);
  const double* yd = data(y);
  double* zd = data(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = xd[i] * yd[i];
}

void quotient(N_Vector x, N_Vector y, N_Vector z) {
  const sunindextype n = length(x);
  const double* xd = data(x);
  const double* yd = data(y);
  double* zd = data(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = xd[i] / yd[i];
}

void absolute(N_Vector x, N_Vector z) {
  const sunindextype n = length(x);
  const double* xd = data(x);
  double* zd = data(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = std::fabs(xd[i]);
}

void inverse(N_Vector x, N_Vector z) {
  const sunindextype n = length(x);
  const double* xd = data(x);
  double* zd = data(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = 1.0 / xd[i];
}

void add_constant(N_Vector x, double b, N_Vector z) {
  const sunindextype n = length(x);
  const double* xd = data(x);
  double* zd = data(z);
  for (sunindextype i = 0; i < n; ++i) zd[i] = xd[i] + b;
}

double max_norm(N_Vector x) {
  const sunindextype n = length(x);
  const double* xd = data(x);
  double m = 0.0;
  for (sunindextype i = 0; i < n; ++i)
    if (std::fabs(xd[i]) > m) m = std::fabs(xd[i]);
  return m;
}

// sum (x_i w_i)^2, summed in index order
double weighted_square_sum(N_Vector x, N_Vector w) {
  const sunindextype n = length(x);
  const double* xd = data(x);
  const double* wd = data(w);
  double sum = 0.0;
  for (sunindextype i = 0; i < n; ++i) {
    const double p = xd[i] * wd[i];
    sum += p * p;
  }
  return sum;
}

double weighted_rms_norm(N_Vector x, N_Vector w) {
  const double mean = weighted_square_sum(x, w) / static_cast<double>(length(x));
  return mean <= 0.0 ? 0.0 : std::sqrt(mean);
}

// z = sum c_i X_i, vector by vector as the library does (one vector: a scale; two: a linear sum;
// z among the X_i: accumulated in place).
int linear_combination(int count, double* c, N_Vector* X, N_Vector z) {
  if (count < 1) return -1;
  if (count == 1) {
    scale(c[0], X[0], z);
    return 0;
  }
  if (count == 2) {
    linear_sum(c[0], X[0], c[1], X[1], z);
    return 0;
  }
  const sunindextype n = length(z);
  double* zd = data(z);
  if (X[0] == z) {
    if (c[0] != 1.0)
      for (sunindextype j = 0; j < n; ++j) zd[j] *= c[0];
  } else {
    const double* xd = data(X[0]);
    for (sunindextype j = 0; j < n; ++j) zd[j] = c[0] * xd[j];
  }
  for (int i = 1; i < count; ++i) {
    const double* xd = data(X[i]);
    const double ci = c[i];
    for (sunindextype j = 0; j < n; ++j) zd[j] += ci * xd[j];
  }
  return 0;
}

// Z_i = a_i x + Y_i
int scale_add_multi(int count, double* a, N_Vector x, N_Vector* Y, N_Vector* Z) {
  if (count < 1) return -1;
  if (count == 1) {
    linear_sum(a[0], x, 1.0, Y[0], Z[0]);
    return 0;
  }
  const sunindextype n = length(x);
  const double* xd = data(x);
  for (int i = 0; i < count; ++i) {
    const double* yd = data(Y[i]);
    double* zd = data(Z[i]);
    const double ai = a[i];
    for (sunindextype j = 0; j < n; ++j) zd[j] = ai * xd[j] + yd[j];
  }
  return 0;
}

// The same operations over arrays of vectors (the sensitivities): vector by vector, each as its
// single-vector form (the library's array forms compute the same per element).
int linear_sum_array(int count, double a, N_Vector* X, double b, N_Vector* Y, N_Vector* Z) {
  for (int i = 0; i < count; ++i) linear_sum(a, X[i], b, Y[i], Z[i]);
  return 0;
}

int scale_array(int count, double* c, N_Vector* X, N_Vector* Z) {
  for (int i = 0; i < count; ++i) scale(c[i], X[i], Z[i]);
  return 0;
}

int constant_array(int count, double c, N_Vector* Z) {
  for (int i = 0; i < count; ++i) constant(c, Z[i]);
  return 0;
}

int weighted_rms_norm_array(int count, N_Vector* X, N_Vector* W, double* norms) {
  for (int i = 0; i < count; ++i) norms[i] = weighted_rms_norm(X[i], W[i]);
  return 0;
}

// Z[j][i] = a_j X[i] + Y[j][i]
int scale_add_multi_array(int count, int sums, double* a, N_Vector* X, N_Vector** Y, N_Vector** Z) {
  for (int i = 0; i < count; ++i) {
    const sunindextype n = length(X[i]);
    const double* xd = data(X[i]);
    for (int j = 0; j < sums; ++j) {
      const double* yd = data(Y[j][i]);
      double* zd = data(Z[j][i]);
      const double aj = a[j];
      for (sunindextype k = 0; k < n; ++k) zd[k] = aj * xd[k] + yd[k];
    }
  }
  return 0;
}

// Z[i] = sum_j c_j X[j][i]
int linear_combination_array(int count, int sums, double* c, N_Vector** X, N_Vector* Z) {
  constexpr int kMost = 16;  // CVODES combines at most its order + 1 (BDF: 6) history vectors
  N_Vector local[kMost];
  std::vector<N_Vector> many(sums > kMost ? sums : 0);
  N_Vector* terms = sums > kMost ? many.data() : local;
  for (int i = 0; i < count; ++i) {
    for (int j = 0; j < sums; ++j) terms[j] = X[j][i];
    if (linear_combination(sums, c, terms, Z[i]) != 0) return -1;
  }
  return 0;
}

// Dense matrices: column-major, SM_COLUMNS_D columns of SM_ROWS_D entries, contiguous.
sunindextype entries(SUNMatrix A) { return SM_ROWS_D(A) * SM_COLUMNS_D(A); }

int matrix_zero(SUNMatrix A) {
  std::fill(SM_DATA_D(A), SM_DATA_D(A) + entries(A), 0.0);
  return SUNMAT_SUCCESS;
}

int matrix_copy(SUNMatrix A, SUNMatrix B) {  // B = A
  if (SM_ROWS_D(A) != SM_ROWS_D(B) || SM_COLUMNS_D(A) != SM_COLUMNS_D(B)) return SUNMAT_ILL_INPUT;
  std::memcpy(SM_DATA_D(B), SM_DATA_D(A), sizeof(double) * static_cast<std::size_t>(entries(A)));
  return SUNMAT_SUCCESS;
}

int matrix_scale_add_identity(double c, SUNMatrix A) {  // A = c A + I
  const sunindextype rows = SM_ROWS_D(A), columns = SM_COLUMNS_D(A);
  double* a = SM_DATA_D(A);
  for (sunindextype j = 0; j < columns; ++j) {
    double* column = a + j * rows;
    for (sunindextype i = 0; i < rows; ++i) column[i] *= c;
    if (j < rows) column[j] += 1.0;
  }
  return SUNMAT_SUCCESS;
}

SUNMatrix matrix_clone(SUNMatrix A) {
  SUNMatrix B = SUNDenseMatrix(SM_ROWS_D(A), SM_COLUMNS_D(A), A->sunctx);
  if (B) use_compiled_matrix_kernels(B);
  return B;
}

}  // namespace

void use_compiled_vector_kernels(N_Vector v) {
  N_Vector_Ops ops = v->ops;
  ops->nvlinearsum = linear_sum;
  ops->nvconst = constant;
  ops->nvprod = product;
  ops->nvdiv = quotient;
  ops->nvscale = scale;
  ops->nvabs = absolute;
  ops->nvinv = inverse;
  ops->nvaddconst = add_constant;
  ops->nvmaxnorm = max_norm;
  ops->nvwrmsnorm = weighted_rms_norm;
  ops->nvwsqrsumlocal = weighted_square_sum;
  // the fused operations only where they are enabled (a null entry makes SUNDIALS fall back on
  // the single-vector ones)
  if (ops->nvlinearcombination) ops->nvlinearcombination = linear_combination;
  if (ops->nvscaleaddmulti) ops->nvscaleaddmulti = scale_add_multi;
  if (ops->nvlinearsumvectorarray) ops->nvlinearsumvectorarray = linear_sum_array;
  if (ops->nvscalevectorarray) ops->nvscalevectorarray = scale_array;
  if (ops->nvconstvectorarray) ops->nvconstvectorarray = constant_array;
  if (ops->nvwrmsnormvectorarray) ops->nvwrmsnormvectorarray = weighted_rms_norm_array;
  if (ops->nvscaleaddmultivectorarray) ops->nvscaleaddmultivectorarray = scale_add_multi_array;
  if (ops->nvlinearcombinationvectorarray) ops->nvlinearcombinationvectorarray = linear_combination_array;
}

void use_compiled_matrix_kernels(SUNMatrix A) {
  A->ops->zero = matrix_zero;
  A->ops->copy = matrix_copy;
  A->ops->scaleaddi = matrix_scale_add_identity;
  A->ops->clone = matrix_clone;
}

}  // namespace dydp::engine
