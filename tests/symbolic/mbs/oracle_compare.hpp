// Helpers of the multibody tests: random states, and the generated functions evaluated into
// Eigen objects for comparison with the numerical oracle.
#pragma once

#include <Eigen/Dense>
#include <random>
#include <vector>

#include "symbolic/mbs/generated_model.hpp"

namespace dydp::mbs::testing {

using Vector = Eigen::VectorXd;
using Matrix = Eigen::MatrixXd;

inline Vector random_vector(std::mt19937& rng, int n, double scale) {
  std::uniform_real_distribution<double> dist(-scale, scale);
  Vector v(std::max(n, 1));
  for (int i = 0; i < v.size(); ++i) v[i] = dist(rng);
  return v;
}

// max |a - b| / max(max |b|, 1e-300)
inline double relative_error(const Matrix& a, const Matrix& b) {
  const double scale = std::max(b.cwiseAbs().maxCoeff(), 1e-300);
  return (a - b).cwiseAbs().maxCoeff() / scale;
}

// Arrays padded to one element, as the generated functions read them.
struct Args {
  Vector q, qd, qdd, lam, inp, p;
};

inline Matrix generated_mass(const GeneratedModel& g, const Args& a) {
  const int n = g.n;
  std::vector<double> out(n), dout(n * n);
  const Matrix eye = Matrix::Identity(n, n);
  g.mass(a.q.data(), a.qd.data(), a.qdd.data(), a.lam.data(), a.inp.data(), a.p.data(), n, eye.data(), out.data(),
         dout.data());
  return Eigen::Map<Matrix>(dout.data(), n, n);
}

// M from the composite-inertia entries (zero elsewhere); the model must have them.
inline Matrix generated_mass_matrix(const GeneratedModel& g, const Args& a) {
  std::vector<double> out(std::max(1, g.mass_entries));
  g.mass_matrix(a.q.data(), a.qd.data(), a.qdd.data(), a.lam.data(), a.inp.data(), a.p.data(), out.data());
  Matrix M = Matrix::Zero(g.n, g.n);
  for (int e = 0; e < g.mass_entries; ++e) M(g.mass_rows[e], g.mass_cols[e]) = M(g.mass_cols[e], g.mass_rows[e]) = out[e];
  return M;
}

inline Vector generated_outputs(GeneratedFunction f, int size, const Args& a) {
  std::vector<double> out(std::max(size, 1));
  f(a.q.data(), a.qd.data(), a.qdd.data(), a.lam.data(), a.inp.data(), a.p.data(), out.data());
  return Eigen::Map<Vector>(out.data(), size);
}

// The primal outputs a tangent function writes (called with no direction): for the residual's
// tangent, M qdd + c - J^T lam and J qdd + Jdot qd with the multipliers of `a`.
inline Vector tangent_primal(GeneratedTangent f, int size, const Args& a) {
  std::vector<double> out(std::max(size, 1)), unused(1, 0.0);
  f(a.q.data(), a.qd.data(), a.qdd.data(), a.lam.data(), a.inp.data(), a.p.data(), 0, unused.data(), unused.data(),
    unused.data(), unused.data(), unused.data(), out.data(), unused.data());
  return Eigen::Map<Vector>(out.data(), size);
}

}  // namespace dydp::mbs::testing
