// Coordinate partitioning over the generated functions (see reduced_dynamics.hpp).
#include "symbolic/mbs/reduced_dynamics.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace dydp::mbs {

ReducedDynamics::ReducedDynamics(const GeneratedModel& model) : model_(model), pad_(64, 0.0) {
  std::vector<int> kind(model.n, 1);  // 0 independent, 1 dependent, 2 driven
  for (int i = 0; i < model.independent_count; ++i) kind[model.independent[i]] = 0;
  for (int i = 0; i < model.driven_count; ++i) kind[model.driven[i]] = 2;
  for (int j = 0; j < model.n; ++j) {
    if (kind[j] == 0) u_.push_back(j);
    if (kind[j] == 1) v_.push_back(j);
    if (kind[j] == 2) d_.push_back(j);
    else f_.push_back(j);
  }
  if (static_cast<int>(v_.size()) != model.m)
    throw std::runtime_error(std::string(model.name) + ": dependent coordinates do not match the constraints");
  u_.assign(model.independent, model.independent + model.independent_count);
  // Jv's structure: independent loops make it block diagonal (up to a permutation)
  Eigen::Matrix<char, Eigen::Dynamic, Eigen::Dynamic> pattern(model.m, model.m);
  for (int i = 0; i < model.m; ++i)
    for (int k = 0; k < model.m; ++k) pattern(i, k) = model.jacobian_nonzero[i * model.n + v_[k]] != 0;
  jv_blocks_.set_pattern(pattern);
}

namespace {

Eigen::MatrixXd columns(const Eigen::MatrixXd& A, const std::vector<int>& cols) {
  Eigen::MatrixXd C(A.rows(), static_cast<Eigen::Index>(cols.size()));
  for (std::size_t i = 0; i < cols.size(); ++i) C.col(i) = A.col(cols[i]);
  return C;
}

}  // namespace

void ReducedDynamics::solve(const double* u, const double* ud, const double* inputs, const double* p,
                            const Vector& guess, Result& r) const {
  solve_kinematics(u, ud, inputs, p, guess, r);
  solve_dynamics(inputs, p, r);
}

void ReducedDynamics::solve_kinematics(const double* u, const double* ud, const double* inputs, const double* p_in,
                                       const Vector& guess, Result& r) const {
  const int n = model_.n, m = model_.m, nu = this->nu();
  const double* p = params(p_in);
  std::vector<double> lam_zero(std::max(1, m), 0.0);
  r.q = guess;
  r.qd = Vector::Zero(n);
  r.qdd = Vector::Zero(n);
  for (int i = 0; i < nu; ++i) {
    r.q[u_[i]] = u[i];
    r.qd[u_[i]] = ud[i];
  }
  const int driven_at = model_.load_inputs;
  for (std::size_t i = 0; i < d_.size(); ++i) {
    r.q[d_[i]] = inputs[driven_at + 3 * i];
    r.qd[d_[i]] = inputs[driven_at + 3 * i + 1];
  }
  const double* in = model_.inputs ? inputs : pad_.data();

  // Constraints: h, J.
  std::vector<double> hj(m + m * n + 1);
  r.J.resize(m, n);
  auto evaluate_constraints = [&] {
    model_.constraints(r.q.data(), r.qd.data(), r.qdd.data(), lam_zero.data(), in, p, hj.data());
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < n; ++j) r.J(i, j) = hj[m + i * n + j];
  };
  r.newton_iterations = 0;
  if (m > 0) {
    for (;;) {
      evaluate_constraints();
      double norm = 0.0;
      for (int i = 0; i < m; ++i) norm = std::max(norm, std::abs(hj[i]));
      if (r.Jv.size() != m) r.Jv = jv_blocks_;
      r.Jv.compute(columns(r.J, v_));
      if (norm < 1e-13) break;
      if (++r.newton_iterations > 30 || !std::isfinite(norm))
        throw std::runtime_error(std::string(model_.name) + ": Newton-Raphson on the constraints did not converge");
      const Vector dv = r.Jv.solve(Eigen::Map<const Vector>(hj.data(), m));
      for (int i = 0; i < m; ++i) r.q[v_[i]] -= dv[i];
    }
    const Vector vd = r.Jv.solve(-(r.J * r.qd));
    for (int i = 0; i < m; ++i) r.qd[v_[i]] = vd[i];
  }
}

void ReducedDynamics::solve_dynamics(const double* inputs, const double* p_in, Result& r) const {
  const int n = model_.n, m = model_.m, nu = this->nu();
  const double* p = params(p_in);
  const double* lam0 = pad_.data();
  std::vector<double> lam_zero(std::max(1, m), 0.0);
  const double* in = model_.inputs ? inputs : pad_.data();
  r.qdd = Vector::Zero(n);
  for (std::size_t i = 0; i < d_.size(); ++i) r.qdd[d_[i]] = inputs[model_.load_inputs + 3 * i + 2];

  // c (with the driven accelerations) and the constraint bias.
  std::vector<double> res(n + m);
  model_.residual(r.q.data(), r.qd.data(), r.qdd.data(), lam_zero.data(), in, p, res.data());
  const Vector c = Eigen::Map<const Vector>(res.data(), n);
  const Vector a0 = Eigen::Map<const Vector>(res.data() + n, m);

  const int nf = static_cast<int>(f_.size());
  // B over the free coordinates: rows u (identity) and v (-Jv^-1 Ju).
  r.B = Matrix::Zero(nf, nu);
  Vector beta = Vector::Zero(nf);
  Matrix Bv, beta_v;
  if (m > 0) {
    Bv = -r.Jv.solve(columns(r.J, u_));
    beta_v = -r.Jv.solve(a0);
  }
  for (int a = 0; a < nf; ++a) {
    const int j = f_[a];
    const auto iu = std::find(u_.begin(), u_.end(), j);
    if (iu != u_.end()) {
      r.B(a, iu - u_.begin()) = 1.0;
    } else {
      const int iv = static_cast<int>(std::find(v_.begin(), v_.end(), j) - v_.begin());
      r.B.row(a) = Bv.row(iv);
      beta[a] = beta_v(iv, 0);
    }
  }

  // M [B beta] from the inertial pass seeded on those accelerations (nu + 1 directions; M
  // itself, n directions, is never formed): M qdd for qdd = B udd + beta is all we need.
  const int k = nu + (m > 0 ? 1 : 0);
  // kept in r between calls: a large tree's n x n blocks would be fresh pages at every call
  r.seeds.setZero(n, k);
  for (int a = 0; a < nf; ++a) {
    r.seeds.row(f_[a]).head(nu) = r.B.row(a);
    if (m > 0) r.seeds(f_[a], nu) = beta[a];
  }
  // (M's composite-inertia entries, NAME_mass_matrix, applied to [B beta] entry by entry cost the
  // sedan as much as the tangent's 14 extra directions: udd 322 k instructions against 304 k,
  // docs/performance.md; the tangent is kept.)
  std::vector<double> out(n);
  r.MB.resize(n, k);
  model_.mass(r.q.data(), r.qd.data(), r.qdd.data(), lam0, in, p, k, r.seeds.data(), out.data(), r.MB.data());

  // a tree (no constraints, u in coordinate order): B = I, M B = M, and the products would cost
  // two dense n^3 products
  const bool identity = m == 0 && u_ == f_;
  const bool whole = identity && nf == n;  // no driven joints either: M_ff B is M
  Vector Mbeta = Vector::Zero(nf);
  Vector cf(nf);
  if (!whole) r.MBf.resize(nf, nu);  // M_ff B
  for (int a = 0; a < nf; ++a) {
    if (!whole) r.MBf.row(a) = r.MB.row(f_[a]).head(nu);
    if (m > 0) Mbeta[a] = r.MB(f_[a], nu);
    cf[a] = c[f_[a]];
  }
  if (whole) r.reduced.compute(r.MB);
  else if (identity) r.reduced.compute(r.MBf);
  else r.reduced.compute(r.B.transpose() * r.MBf);
  if (r.reduced.info() != Eigen::Success)
    throw std::runtime_error(std::string(model_.name) + ": reduced mass matrix is not positive definite");
  r.udd = identity ? Vector(r.reduced.solve(-cf)) : Vector(r.reduced.solve(-(r.B.transpose() * (cf + Mbeta))));
  const Vector qddf = r.B * r.udd + beta;
  for (int a = 0; a < nf; ++a) r.qdd[f_[a]] = qddf[a];

  // Multipliers: J^T lam = M qdd + c on the dependent rows, M qdd = M B udd + M beta.
  r.lam = Vector::Zero(m);
  if (m > 0) {
    const Vector full = c + r.MB.leftCols(nu) * r.udd + r.MB.col(nu);
    Vector fv(m);
    for (int i = 0; i < m; ++i) fv[i] = full[v_[i]];
    r.lam = r.Jv.transpose_solve(fv);
  }
}

void ReducedDynamics::seed_arrays(int nd, const double* dinputs, const double* dp_in, Matrix& dinp, Matrix& dp,
                                  Matrix& dqdd) const {
  dinp = Matrix::Zero(std::max(1, model_.inputs), nd);
  dp = Matrix::Zero(std::max(1, model_.parameters), nd);
  if (dinputs && model_.inputs) dinp = Eigen::Map<const Matrix>(dinputs, model_.inputs, nd);
  if (dp_in && model_.parameters) dp = Eigen::Map<const Matrix>(dp_in, model_.parameters, nd);
  dqdd = Matrix::Zero(model_.n, nd);
  for (int d = 0; d < nd; ++d)
    for (std::size_t i = 0; i < d_.size(); ++i) dqdd(d_[i], d) = dinp(model_.load_inputs + 3 * i + 2, d);
}

void ReducedDynamics::tangent_kinematics(const Result& r, const double* inputs, const double* p_in, int nd,
                                         const double* du, const double* dud, const double* dinputs,
                                         const double* dp_in, Matrix& dq, Matrix& dqd) const {
  const int n = model_.n, m = model_.m, nu = this->nu();
  const double* p = params(p_in);
  const double* in = model_.inputs ? inputs : pad_.data();
  Matrix dinp, dp, dqdd;
  seed_arrays(nd, dinputs, dp_in, dinp, dp, dqdd);
  dq = Matrix::Zero(n, nd);
  dqd = Matrix::Zero(n, nd);
  const int driven_at = model_.load_inputs;
  for (int d = 0; d < nd; ++d) {
    for (int i = 0; i < nu; ++i) {
      dq(u_[i], d) = du ? du[d * nu + i] : 0.0;
      dqd(u_[i], d) = dud ? dud[d * nu + i] : 0.0;
    }
    for (std::size_t i = 0; i < d_.size(); ++i) {
      dq(d_[i], d) = dinp(driven_at + 3 * i, d);
      dqd(d_[i], d) = dinp(driven_at + 3 * i + 1, d);
    }
  }
  const Vector lam = r.lam.size() >= std::max(m, 1) ? r.lam : Vector::Zero(std::max(m, 1));  // not read here
  if (m > 0) {
    // dh = Ju du + Jv dv + h_p dp = 0 (h's own tangent), then d(J qd) = 0 likewise for dv_dot.
    std::vector<double> out(2 * m);
    Matrix dout(2 * m, nd), dh(m, nd);
    model_.constraints_tangent(r.q.data(), r.qd.data(), r.qdd.data(), lam.data(), in, p, nd, dq.data(), dqd.data(),
                               dqdd.data(), dinp.data(), dp.data(), out.data(), dh.data());
    const Matrix dv = -r.Jv.solve(dh);
    for (int i = 0; i < m; ++i) dq.row(v_[i]) = dv.row(i);
    model_.velocity_constraints_tangent(r.q.data(), r.qd.data(), r.qdd.data(), lam.data(), in, p, nd, dq.data(),
                                        dqd.data(), dqdd.data(), dinp.data(), dp.data(), out.data(), dout.data());
    const Matrix dvd = -r.Jv.solve(Matrix(dout.bottomRows(m)));
    for (int i = 0; i < m; ++i) dqd.row(v_[i]) = dvd.row(i);
  }
}

void ReducedDynamics::tangent(const Result& r, const double* inputs, const double* p, int nd, const double* du,
                              const double* dud, const double* dinputs, const double* dp, Matrix& dq, Matrix& dqd,
                              Matrix& dqdd) const {
  tangent_kinematics(r, inputs, p, nd, du, dud, dinputs, dp, dq, dqd);
  tangent_dynamics(r, inputs, p, nd, dinputs, dp, dq, dqd, dqdd);
}

void ReducedDynamics::tangent_dynamics(const Result& r, const double* inputs, const double* p_in, int nd,
                                       const double* dinputs, const double* dp_in, const Matrix& dq,
                                       const Matrix& dqd, Matrix& dqdd) const {
  const int n = model_.n, m = model_.m;
  const double* p = params(p_in);
  const double* in = model_.inputs ? inputs : pad_.data();
  Matrix dinp, dp;
  seed_arrays(nd, dinputs, dp_in, dinp, dp, dqdd);
  const Vector lam = m ? r.lam : Vector::Zero(1);
  // dr = dM qdd + dc - dJ^T lam (qdd, lam frozen; driven dqdd seeded), da = dJ qdd + d(Jdot qd).
  std::vector<double> out(n + m);
  Matrix dout(n + m, nd);
  model_.residual_tangent(r.q.data(), r.qd.data(), r.qdd.data(), lam.data(), in, p, nd, dq.data(), dqd.data(),
                          dqdd.data(), dinp.data(), dp.data(), out.data(), dout.data());
  const int nf = static_cast<int>(f_.size());
  Matrix dbeta = Matrix::Zero(nf, nd), drf(nf, nd);
  if (m > 0) {
    const Matrix dbeta_v = -r.Jv.solve(Matrix(dout.bottomRows(m)));
    for (int a = 0; a < nf; ++a) {
      const auto iv = std::find(v_.begin(), v_.end(), f_[a]);
      if (iv != v_.end()) dbeta.row(a) = dbeta_v.row(iv - v_.begin());
    }
  }
  for (int a = 0; a < nf; ++a) drf.row(a) = dout.row(f_[a]);
  // a tree in coordinate order: B = I (see solve_dynamics); otherwise B^T M_ff dbeta =
  // (M_ff B)^T dbeta, M being symmetric, with M_ff B from solve_dynamics
  if (m == 0 && u_ == f_) {
    const Matrix dudd = r.reduced.solve(-drf);
    for (int a = 0; a < nf; ++a) dqdd.row(f_[a]) = dudd.row(a);
    return;
  }
  const Matrix dudd = r.reduced.solve(-(r.B.transpose() * drf + r.MBf.transpose() * dbeta));
  const Matrix dqddf = r.B * dudd + dbeta;
  for (int a = 0; a < nf; ++a) dqdd.row(f_[a]) = dqddf.row(a);
}

}  // namespace dydp::mbs
