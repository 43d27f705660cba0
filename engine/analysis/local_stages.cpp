#include "engine/analysis/local_stages.hpp"

#include <algorithm>
#include <cmath>

#include "engine/framework/errors.hpp"

namespace dydp::engine {
namespace {

/// The iteration is converged when its last correction (or the one its contraction rate
/// predicts next) moves no local state by more than this fraction of its nominal magnitude (or of
/// its value, where larger). 1e-5 is 6 % faster on the sedan but makes the discrete map rough at
/// the 1e-3 perturbations a difference check uses (docs/performance.md, 2026-12-06).
const double kTolerance = 1e-6;
/// The iteration keeps the matrix of the last stage (its local blocks at that stage's solution)
/// while each correction is at most this fraction of the one before; a slower one, as where a
/// valve opens within the step, has the local blocks evaluated at the current iterate.
const double kRefactorRate = 0.1;
/// A stage that has not converged in this many iterations is taken in halves like a failed one.
const int kIterations = 10;

}  // namespace

bool LocalStages::find(double t, const Vector& x) {
  nx_ = static_cast<int>(x.size());
  if (nx_ == 0) return false;
  jloc_.setZero(nx_, nx_);
  if (!ev_.local_jacobians(t, x.data(), jloc_.data(), nx_)) return false;
  std::vector<char> local(nx_, 0);
  for (const auto& [first, count] : ev_.local_state_ranges())
    for (int i = first; i < first + count; ++i) local[i] = 1;
  for (int i = 0; i < nx_; ++i) (local[i] ? v_ : u_).push_back(i);
  const int nu = static_cast<int>(u_.size()), nv = static_cast<int>(v_.size());
  ru_.setZero(nu), yu_.setZero(nu), xu_.setZero(nu), ku_.setZero(nu);
  rv_.setZero(nv), xv_.setZero(nv), kv_.setZero(nv);
  xi_.setZero(nx_), fv_.setZero(nx_);
  return true;
}

void LocalStages::factor(const Matrix& w, double h) {
  const int nu = static_cast<int>(u_.size()), nv = static_cast<int>(v_.size());
  const double gh = gamma_ * h;
  a_.resize(nu, nu), b_.resize(nu, nv), c_.resize(nv, nu);
  for (int j = 0; j < nu; ++j)
    for (int i = 0; i < nu; ++i) a_(i, j) = (i == j ? 1.0 : 0.0) - gh * w(u_[i], u_[j]);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) b_(i, j) = -gh * w(u_[i], v_[j]);
  for (int j = 0; j < nu; ++j)
    for (int i = 0; i < nv; ++i) c_(i, j) = -gh * w(v_[i], u_[j]);
  if (nu > 0) lu_a_.factor(a_.data(), nu);  // a zero pivot shows as a non-finite stage
  ainv_b_ = b_;
  for (int j = 0; j < nv && nu > 0; ++j) lu_a_.solve(ainv_b_.col(j).data(), ainv_b_.col(j).data());
  p_ = c_ * ainv_b_;
  schur_valid_ = false;
}

void LocalStages::solve_partitioned(const Vector& r_u, const Vector& r_v) {
  yu_ = r_u;
  if (yu_.size() > 0) lu_a_.solve(yu_.data(), yu_.data());
  xv_ = schur_.solve(r_v - c_ * yu_);
  xu_ = yu_ - ainv_b_ * xv_;
}

void LocalStages::factor_schur(double tb, const Vector& xs, double h) {
  const int nv = static_cast<int>(v_.size());
  ev_.local_jacobians_held(tb, xs.data(), jloc_.data(), nx_);
  ++stats_.local_jac_evals;
  schur_matrix_.resize(nv, nv);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nv; ++i)
      schur_matrix_(i, j) = (i == j ? 1.0 : 0.0) - gamma_ * h * jloc_(v_[i], v_[j]) - p_(i, j);
  schur_.compute(schur_matrix_);
  schur_valid_ = true;
}

void LocalStages::solve(double tb, const Vector& xb, const Eigen::Ref<const Vector>& fb, const Vector& c, double h,
                        Vector& k) {
  const int nu = static_cast<int>(u_.size()), nv = static_cast<int>(v_.size());
  const double gh = gamma_ * h;
  k.head(nx_).setZero();
  ku_.setZero(nu);
  kv_.setZero(nv);
  xi_ = xb;
  double last_size = 0.0, last_rate = 0.0;
  for (int it = 0; it < kIterations; ++it) {
    try {
      if (it == 0) {
        for (int i = 0; i < nv; ++i) fv_(v_[i]) = fb(v_[i]);
        // The first iterate is the linearly implicit stage itself, with the matrix of the last
        // stage (the states have moved by a stage at most).
        if (!schur_valid_) factor_schur(tb, xi_, h);
      } else {
        for (int i = 0; i < nv; ++i) xi_(v_[i]) = xb(v_[i]) + gh * kv_(i);
        ev_.local_derivatives(tb, xi_.data(), fv_.data());
        if (it >= 2 && last_rate > kRefactorRate) factor_schur(tb, xi_, h);
      }
    } catch (const OutOfDomain& e) {
      throw domain_failure<StageFailure>(tb, e);
    }
    for (int i = 0; i < nv; ++i) rv_(i) = kv_(i) - fv_(v_[i]) - c(v_[i]);
    rv_.noalias() += c_ * ku_;
    if (it == 0) {
      for (int i = 0; i < nu; ++i) ru_(i) = -(fb(u_[i]) + c(u_[i]));
      solve_partitioned(ru_, rv_);
    } else {
      // The u rows are linear and every iterate solves them exactly: their residual is zero.
      xv_ = schur_.solve(rv_);
      xu_.noalias() = -ainv_b_ * xv_;
    }
    ku_ -= xu_;
    kv_ -= xv_;
    ++stats_.nonlinear_iterations;
    double size = 0.0;
    for (int i = 0; i < nv; ++i)
      size = std::max(size, std::abs(gh * xv_(i)) / std::max(scale_(v_[i]), std::abs(xb(v_[i]))));
    if (!std::isfinite(size)) break;
    // Converged when the correction, or the one its contraction rate predicts next, is below the
    // tolerance (the usual test of implicit integrators, Hairer and Wanner IV.8).
    const double rate = it > 0 && last_size > 0 ? size / last_size : 1.0;
    if (it > 1 && rate >= 1.0) break;  // diverging
    if (it > 0 && (size <= kTolerance || (rate < 1.0 && rate / (1.0 - rate) * size <= kTolerance))) {
      for (int i = 0; i < nu; ++i) k(u_[i]) = ku_(i);
      for (int i = 0; i < nv; ++i) k(v_[i]) = kv_(i);
      if (ns_ > 0) {  // the sensitivities' matrix at the stage's solution
        for (int i = 0; i < nv; ++i) xi_(v_[i]) = xb(v_[i]) + gh * kv_(i);
        try {
          factor_schur(tb, xi_, h);
        } catch (const OutOfDomain& e) {
          throw domain_failure<StageFailure>(tb, e);
        }
      }
      return;
    }
    last_size = size;
    last_rate = rate;
  }
  ++stats_.nonlinear_failures;
  throw StageFailure{tb, "", "the local stage's Newton iteration did not converge in " + std::to_string(kIterations) +
                                 " iterations"};
}

void LocalStages::solve_tangent(double tb, const Vector& xb, const Matrix& dxb, const Matrix& dfb, const Matrix& dc,
                                double h, const Vector& k, Matrix& dk) {
  const int nu = static_cast<int>(u_.size()), nv = static_cast<int>(v_.size());
  xi_ = xb;
  for (int i = 0; i < nv; ++i) xi_(v_[i]) += gamma_ * h * k(v_[i]);
  dloc_.setZero(nx_, ns_);
  try {
    ev_.local_derivatives_tangent(tb, xi_.data(), ns_, {dxb.data(), nx_}, true, {dloc_.data(), nx_});
  } catch (const OutOfDomain& e) {
    throw domain_failure<StageFailure>(tb, e);
  }
  for (int col = 0; col < ns_; ++col) {
    for (int i = 0; i < nu; ++i) ru_(i) = dfb(u_[i], col) + dc(u_[i], col);
    for (int i = 0; i < nv; ++i) rv_(i) = dloc_(v_[i], col) + dc(v_[i], col);
    solve_partitioned(ru_, rv_);
    for (int i = 0; i < nu; ++i) dk(u_[i], col) = xu_(i);
    for (int i = 0; i < nv; ++i) dk(v_[i], col) = xv_(i);
  }
}

}  // namespace dydp::engine
