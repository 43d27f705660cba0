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
  for (int j : f_) {
    const auto iu = std::find(u_.begin(), u_.end(), j);
    free_place_.push_back(iu != u_.end() ? static_cast<int>(iu - u_.begin())
                                         : -1 - static_cast<int>(std::find(v_.begin(), v_.end(), j) - v_.begin()));
  }
  // B's structure from J's and Jv's blocks
  const int nu = this->nu(), n = model.n;
  block_u_.assign(jv_blocks_.blocks(), {});
  std::vector<int> block_of_v(model.m, 0);
  for (int b = 0; b < jv_blocks_.blocks(); ++b) {
    for (int k : jv_blocks_.block_cols(b)) block_of_v[k] = b;
    for (int i = 0; i < nu; ++i) {
      bool reads = false;
      for (int row : jv_blocks_.block_rows(b)) reads = reads || model.jacobian_nonzero[row * n + u_[i]] != 0;
      if (reads) block_u_[b].push_back(i);
    }
  }
  b_cols_.resize(f_.size());
  free_row_of_.assign(n, -1);
  for (std::size_t a = 0; a < f_.size(); ++a) {
    free_row_of_[f_[a]] = static_cast<int>(a);
    b_cols_[a] = free_place_[a] >= 0 ? std::vector<int>{free_place_[a]} : block_u_[block_of_v[-1 - free_place_[a]]];
  }
  row_of_v_.assign(model.m, -1);
  for (std::size_t a = 0; a < f_.size(); ++a) {
    if (free_place_[a] >= 0) {
      independent_rows_.push_back({f_[a], free_place_[a]});
    } else {
      dependent_rows_.emplace_back(static_cast<int>(a), -1 - free_place_[a]);
      row_of_v_[-1 - free_place_[a]] = static_cast<int>(a);
      for (int c : b_cols_[a]) dependent_entries_.push_back({f_[a], c, static_cast<int>(a) * nu + c});
    }
  }
  for (int i = 0; i < model.m; ++i)
    for (int j = 0; j < n; ++j)
      if (kind[j] != 1 && model.jacobian_nonzero[i * n + j] != 0) seeded_entries_.push_back({i, j});
  s_start_.assign(1, 0);
  for (int j = 0; j < n; ++j) {
    const int a = free_row_of_[j];
    if (a >= 0) {
      s_col_.insert(s_col_.end(), b_cols_[a].begin(), b_cols_[a].end());
      if (free_place_[a] < 0) s_col_.push_back(nu);  // beta
    }
    s_start_.push_back(static_cast<int>(s_col_.size()));
  }
  if (model.mass_matrix) {
    const int k = nu + (model.m > 0 ? 1 : 0);
    std::vector<std::vector<std::pair<int, int>>> terms(static_cast<std::size_t>(n) * k);
    for (int e = 0; e < model.mass_entries; ++e) {
      const int i = model.mass_rows[e], j = model.mass_cols[e];
      for (int t = s_start_[j]; t < s_start_[j + 1]; ++t) terms[static_cast<std::size_t>(i) * k + s_col_[t]].emplace_back(e, t);
      if (i != j)
        for (int t = s_start_[i]; t < s_start_[i + 1]; ++t) terms[static_cast<std::size_t>(j) * k + s_col_[t]].emplace_back(e, t);
    }
    std::vector<char> unit(s_col_.size(), 0);  // [B beta]'s entry is an independent row's 1
    for (const IndependentRow& row : independent_rows_) unit[s_start_[row.q]] = 1;
    mb_start_.assign(1, 0);
    for (std::size_t o = 0; o < terms.size(); ++o) {
      if (terms[o].empty()) continue;
      mb_place_.push_back(static_cast<int>(o));
      mb_unit_.push_back(model.mass_entries);  // the zero after M's entries
      for (const auto& [e, t] : terms[o]) {
        if (unit[t]) {
          mb_unit_.back() = e;  // (one at most: column c has a single independent row)
        } else {
          mb_mass_.push_back(e);
          mb_s_.push_back(t);
        }
      }
      mb_start_.push_back(static_cast<int>(mb_mass_.size()));
    }
  }
}

void ReducedDynamics::solve(const double* u, const double* ud, const double* inputs, const double* p,
                            const Vector& guess, Result& r) const {
  solve_kinematics(u, ud, inputs, p, guess, r);
  solve_dynamics(inputs, p, r);
}

void ReducedDynamics::solve_kinematics(const double* u, const double* ud, const double* inputs, const double* p_in,
                                       const Vector& guess, Result& r) const {
  const int n = model_.n, m = model_.m, nu = this->nu();
  const double* p = params(p_in);
  Result::Work& w = r.work;
  if (static_cast<int>(w.lam_zero.size()) != std::max(1, m)) w.lam_zero.assign(std::max(1, m), 0.0);  // never written
  r.q = guess;
  r.dynamics_current = false;
  r.qd.setZero(n);
  r.qdd.setZero(n);
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

  // Constraints: h, then J row-major (read in place by the iteration, copied to r.J at the end).
  w.hj.resize(m + m * n + 1);
  r.J.resize(m, n);
  r.newton_iterations = 0;
  if (m > 0) {
    if (r.Jv.size() != m) r.Jv = jv_blocks_;
    w.fv.resize(m);
    for (;;) {
      model_.constraints(r.q.data(), r.qd.data(), r.qdd.data(), w.lam_zero.data(), in, p, w.hj.data());
      double norm = 0.0;
      for (int i = 0; i < m; ++i) norm = std::max(norm, std::abs(w.hj[i]));
      if (!r.Jv.compute_rows(w.hj.data() + m, n, v_) && std::isfinite(norm))
        throw std::runtime_error(std::string(model_.name) + ": the constraint Jacobian is singular");
      if (norm < 1e-13) break;
      if (++r.newton_iterations > 30 || !std::isfinite(norm))
        throw std::runtime_error(std::string(model_.name) + ": Newton-Raphson on the constraints did not converge");
      r.Jv.solve(w.hj.data(), m, 1, w.fv.data(), m);
      for (int i = 0; i < m; ++i) r.q[v_[i]] -= w.fv[i];
    }
    r.Jv.invert();  // the factors at the solution serve many right-hand sides from here on
    r.J = Eigen::Map<const RowMatrix>(w.hj.data() + m, m, n);
    jacobian_times(r.J, r.qd.data(), w.fv.data());  // Jv vd = -J qd (vd still zero in qd: J's seeded columns)
    r.Jv.solve(w.fv.data(), m, 1, w.fv.data(), m);
    for (int i = 0; i < m; ++i) r.qd[v_[i]] = -w.fv[i];
  }
}

void ReducedDynamics::predict(const Result& r, const double* u, Vector& guess) const {
  guess = r.q;
  if (!r.dynamics_current) return;
  const int nu = this->nu();
  for (const auto& [a, place] : dependent_rows_) {
    const double* row = r.B.data() + static_cast<Eigen::Index>(a) * nu;
    double dv = 0.0;
    for (int c : b_cols_[a]) dv += row[c] * (u[c] - r.q[u_[c]]);
    guess[v_[place]] += dv;
  }
}

void ReducedDynamics::solve_dynamics(const double* inputs, const double* p_in, Result& r) const {
  const int n = model_.n, m = model_.m;
  const double* p = params(p_in);
  Result::Work& w = r.work;
  if (static_cast<int>(w.lam_zero.size()) != std::max(1, m)) w.lam_zero.assign(std::max(1, m), 0.0);
  const double* in = model_.inputs ? inputs : pad_.data();
  r.qdd.setZero(n);
  for (std::size_t i = 0; i < d_.size(); ++i) r.qdd[d_[i]] = inputs[model_.load_inputs + 3 * i + 2];

  // c (with the driven accelerations) and the constraint bias.
  w.res.resize(n + m);
  model_.residual(r.q.data(), r.qd.data(), r.qdd.data(), w.lam_zero.data(), in, p, w.res.data());
  const double* c = w.res.data();
  const double* a0 = w.res.data() + n;

  const int nf = static_cast<int>(f_.size());
  free_basis(a0, r);

  // a tree (no constraints, u in coordinate order): B = I, M B = M, and the products would cost
  // two dense n^3 products
  const bool identity = m == 0 && u_ == f_;
  // M [B beta]: M qdd for qdd = B udd + beta is all we need.
  if (model_.mass_matrix) gathered_mass_basis(in, p, r);
  else seeded_mass_basis(in, p, r);

  const bool whole = identity && nf == n;  // no driven joints either: M_ff B is M
  factor_reduced(c, identity, whole, r);
  free_accelerations(identity, r);
  multipliers(c, r);
  r.dynamics_current = true;
}

// B over the free coordinates and beta, the free accelerations at udd = 0 (a0: the constraint bias).
void ReducedDynamics::free_basis(const double* a0, Result& r) const {
  const int n = model_.n, m = model_.m, nu = this->nu();
  Result::Work& w = r.work;
  const int nf = static_cast<int>(f_.size());
  // B over the free coordinates: rows u (identity) and v (-Jv^-1 Ju).
  // B's and M [B beta]'s entries outside their structure, and B's independent rows' 1s, are
  // written when they take their shape (or come from another model's partitioning); each call
  // writes the structural entries only.
  const bool reshape = w.shaped_by != this;
  w.shaped_by = this;
  const int k = nu + (m > 0 ? 1 : 0);  // [B beta]'s columns
  if (reshape || r.B.rows() != nf || r.B.cols() != nu) {
    r.B.setZero(nf, nu);
    for (int a = 0; a < nf; ++a)
      if (free_place_[a] >= 0) r.B(a, free_place_[a]) = 1.0;
  }
  if (reshape || r.MB.rows() != n || r.MB.cols() != k) r.MB.setZero(n, k);
  w.beta.setZero(nf);
  if (m > 0) {
    // Bv = -Jv^-1 Ju block by block, over the u columns that reach each block: the block's
    // inverse times its rows of J's column
    const double* J = r.J.data();  // row-major
    double* z = w.fv.data();       // (m entries: a block's part of one column)
    for (int b = 0; b < r.Jv.blocks(); ++b) {
      const std::vector<int>& rows = r.Jv.block_rows(b);
      const std::vector<int>& cols = r.Jv.block_cols(b);
      const int kb = static_cast<int>(rows.size());
      const double* inv = r.Jv.block_inverse(b);
      for (int c : block_u_[b]) {
        for (int j = 0; j < kb; ++j) z[j] = J[static_cast<Eigen::Index>(rows[j]) * n + u_[c]];
        for (int i = 0; i < kb; ++i) {
          double x = 0.0;
          for (int j = 0; j < kb; ++j) x += inv[i * kb + j] * z[j];
          r.B(row_of_v_[cols[i]], c) = -x;
        }
      }
    }
    w.beta_v.resize(m, 1);
    r.Jv.solve(a0, m, 1, w.beta_v.data(), m);
    for (const auto& [a, place] : dependent_rows_) w.beta[a] = -w.beta_v(place, 0);
  }
}

// r.MB = M [B beta] from M's structurally nonzero entries (the model's mass_matrix).
void ReducedDynamics::gathered_mass_basis(const double* in, const double* p, Result& r) const {
  const int nu = this->nu();
  Result::Work& w = r.work;
  // M's structurally nonzero entries by composite inertias times the structurally nonzero
  // entries of [B beta]: a corner's rows meet a corner's two or three columns
  w.mass.resize(model_.mass_entries + 1);
  model_.mass_matrix(r.q.data(), r.qd.data(), r.qdd.data(), pad_.data(), in, p, w.mass.data());
  w.mass[model_.mass_entries] = 0.0;
  w.s_val.resize(s_col_.size());  // (the dependent rows': the independent ones' 1 is not read)
  for (const auto& [a, place] : dependent_rows_) {
    const int j = f_[a];
    for (int t = s_start_[j]; t < s_start_[j + 1]; ++t) w.s_val[t] = s_col_[t] < nu ? r.B(a, s_col_[t]) : w.beta[a];
  }
  double* __restrict mb = r.MB.data();
  const double* mass = w.mass.data();
  const double* val = w.s_val.data();
  const int* start = mb_start_.data();
  const int* at_mass = mb_mass_.data();
  const int* at_s = mb_s_.data();
  const int* at_unit = mb_unit_.data();
  for (std::size_t o = 0; o < mb_place_.size(); ++o) {
    double sum = mass[at_unit[o]];
    for (int t = start[o]; t < start[o + 1]; ++t) sum += mass[at_mass[t]] * val[at_s[t]];
    mb[mb_place_[o]] = sum;
  }
}

// r.MB = M [B beta] by the model's inertial pass seeded on [B beta] (no mass_matrix).
void ReducedDynamics::seeded_mass_basis(const double* in, const double* p, Result& r) const {
  const int n = model_.n, m = model_.m, nu = this->nu();
  const int nf = static_cast<int>(f_.size()), k = nu + (m > 0 ? 1 : 0);
  Result::Work& w = r.work;
  // the inertial pass seeded on [B beta] (nu + 1 directions; M itself, n directions, is never
  // formed): a tree too deep for M's entries
  r.seeds.setZero(n, k);  // kept in r: a large tree's n x n blocks would be fresh pages each call
  for (int a = 0; a < nf; ++a) {
    r.seeds.row(f_[a]).head(nu) = r.B.row(a);
    if (m > 0) r.seeds(f_[a], nu) = w.beta[a];
  }
  w.out.resize(n);
  w.mass_columns.resize(n, k);
  model_.mass(r.q.data(), r.qd.data(), r.qdd.data(), pad_.data(), in, p, k, r.seeds.data(), w.out.data(),
              w.mass_columns.data());
  r.MB = w.mass_columns;
}

// M_ff B, M beta and c over the free rows, and the Cholesky factor of B^T M_ff B (c: the residual's n entries).
void ReducedDynamics::factor_reduced(const double* c, bool identity, bool whole, Result& r) const {
  const int n = model_.n, m = model_.m, nu = this->nu();
  const int nf = static_cast<int>(f_.size());
  Result::Work& w = r.work;
  w.Mbeta.resize(nf);
  w.cf.resize(nf);
  if (!whole) r.MBf.resize(nf, nu);  // M_ff B
  for (int a = 0; a < nf; ++a) {
    if (!whole) r.MBf.row(a) = r.MB.row(f_[a]).head(nu);
    w.Mbeta[a] = m > 0 ? r.MB(f_[a], nu) : 0.0;
    w.cf[a] = c[f_[a]];
  }
  bool definite = false;
  // (M_ff and B^T M_ff B are symmetric: a row-major copy read column-major is the same matrix)
  if (whole) {
    definite = r.reduced.compute(Eigen::Map<const Matrix>(r.MB.data(), n, n));
  } else if (identity) {
    definite = r.reduced.compute(Eigen::Map<const Matrix>(r.MBf.data(), nf, nf));
  } else {
    w.reduced.setZero(nu, nu);  // B^T M_ff B over B's structure, column by column
    double* __restrict reduced = w.reduced.data();
    for (int a = 0; a < nf; ++a) {
      const double* mbf = r.MBf.data() + static_cast<Eigen::Index>(a) * nu;
      const double* b = r.B.data() + static_cast<Eigen::Index>(a) * nu;
      for (int col : b_cols_[a]) {
        double* column = reduced + static_cast<Eigen::Index>(col) * nu;
        for (int i = 0; i < nu; ++i) column[i] += b[col] * mbf[i];
      }
    }
    definite = r.reduced.compute(w.reduced);
  }
  if (!definite)
    throw std::runtime_error(std::string(model_.name) + ": reduced mass matrix is not positive definite");
}

// udd from the reduced system, and the free coordinates' accelerations qdd = B udd + beta.
void ReducedDynamics::free_accelerations(bool identity, Result& r) const {
  const int nu = this->nu();
  const int nf = static_cast<int>(f_.size());
  Result::Work& w = r.work;
  w.cf += w.Mbeta;
  if (identity) {
    r.udd = w.cf;
  } else {
    r.udd.setZero(nu);
    for (int a = 0; a < nf; ++a)
      for (int c : b_cols_[a]) r.udd[c] += r.B(a, c) * w.cf[a];
  }
  r.reduced.solve_in_place(r.udd);
  r.udd = -r.udd;
  w.qddf = w.beta;
  for (int a = 0; a < nf; ++a)
    for (int c : b_cols_[a]) w.qddf[a] += r.B(a, c) * r.udd[c];
  for (int a = 0; a < nf; ++a) r.qdd[f_[a]] = w.qddf[a];
}

// The multipliers lam from the dependent rows (c: the residual's n entries).
void ReducedDynamics::multipliers(const double* c, Result& r) const {
  const int m = model_.m, nu = this->nu();
  Result::Work& w = r.work;
  // Multipliers: J^T lam = M qdd + c on the dependent rows, M qdd = M B udd + M beta.
  r.lam.resize(m);
  if (m > 0) {  // (the dependent rows only)
    w.fv.resize(m);
    for (int i = 0; i < m; ++i) w.fv[i] = c[v_[i]] + r.MB(v_[i], nu) + r.MB.row(v_[i]).head(nu).dot(r.udd);
    r.Jv.transpose_solve(w.fv.data(), m, 1, r.lam.data(), m);
  }
}

void ReducedDynamics::seed_arrays(int nd, const double* dinputs, const double* dp_in, Matrix& dinp, Matrix& dp,
                                  Matrix& dqdd) const {
  if (dinputs && model_.inputs) dinp = Eigen::Map<const Matrix>(dinputs, model_.inputs, nd);
  else dinp.setZero(std::max(1, model_.inputs), nd);
  if (dp_in && model_.parameters) dp = Eigen::Map<const Matrix>(dp_in, model_.parameters, nd);
  else dp.setZero(std::max(1, model_.parameters), nd);
  dqdd.setZero(model_.n, nd);
  for (int d = 0; d < nd; ++d)
    for (std::size_t i = 0; i < d_.size(); ++i) dqdd(d_[i], d) = dinp(model_.load_inputs + 3 * i + 2, d);
}

void ReducedDynamics::tangent_kinematics(const Result& r, const double* inputs, const double* p_in, int nd,
                                         const double* du, const double* dud, const double* dinputs,
                                         const double* dp_in, Matrix& dq, Matrix& dqd) const {
  const int n = model_.n, m = model_.m, nu = this->nu();
  const double* p = params(p_in);
  const double* in = model_.inputs ? inputs : pad_.data();
  Result::Work& w = r.work;
  seed_arrays(nd, dinputs, dp_in, w.dinp, w.dp, w.dqdd_seed);
  dq.setZero(n, nd);
  dqd.setZero(n, nd);
  const int driven_at = model_.load_inputs;
  for (int d = 0; d < nd; ++d) {
    for (int i = 0; i < nu; ++i) {
      dq(u_[i], d) = du ? du[d * nu + i] : 0.0;
      dqd(u_[i], d) = dud ? dud[d * nu + i] : 0.0;
    }
    for (std::size_t i = 0; i < d_.size(); ++i) {
      dq(d_[i], d) = w.dinp(driven_at + 3 * i, d);
      dqd(d_[i], d) = w.dinp(driven_at + 3 * i + 1, d);
    }
  }
  if (m > 0) {
    // dh = Ju du + Jv dv + h_p dp = 0, then d(J qd) = 0 likewise for dv_dot. (lam is not read
    // by these functions.) Without parameter seeds, dh is J dq over the seeded columns (J is
    // at hand); otherwise h's own tangent.
    w.out.resize(2 * m);
    w.dout.resize(2 * m, nd);
    w.dh.resize(m, nd);
    w.dv.resize(m, nd);
    const bool parameters_seeded = model_.parameters > 0 && !(w.dp.array() == 0.0).all();
    // A direction with no seed on u, the driven joints or the parameters moves no coordinate
    // (dh = 0, dv = 0) and has d(J qd) = J dqd: the solves and the generated tangents run on
    // the others (when they come first, on those only).
    split_directions(dq, parameters_seeded ? &w.dp : nullptr, nd, w.moving, w.still);
    const int k = static_cast<int>(w.moving.size());
    const int solved = leading(w.moving) ? k : nd;
    if (parameters_seeded) {
      model_.constraints_tangent(r.q.data(), r.qd.data(), r.qdd.data(), w.lam_zero.data(), in, p, nd, dq.data(),
                                 dqd.data(), w.dqdd_seed.data(), w.dinp.data(), w.dp.data(), w.out.data(),
                                 w.dh.data());
    } else {
      for (int d = 0; d < solved; ++d) jacobian_times(r.J, dq.data() + d * n, w.dh.data() + d * m);
    }
    if (solved > 0) r.Jv.solve(w.dh.data(), m, solved, w.dv.data(), m);
    for (int i = 0; i < m; ++i) dq.row(v_[i]).head(solved) = -w.dv.row(i).head(solved);  // (zero past them)
    if (w.still.empty()) {
      model_.velocity_constraints_tangent(r.q.data(), r.qd.data(), r.qdd.data(), w.lam_zero.data(), in, p, nd,
                                          dq.data(), dqd.data(), w.dqdd_seed.data(), w.dinp.data(), w.dp.data(),
                                          w.out.data(), w.dout.data());
    } else {
      if (k > 0) {
        const DirectionSeeds s = directions(w.moving, dq, dqd, w.dqdd_seed, w.dout, w);
        model_.velocity_constraints_tangent(r.q.data(), r.qd.data(), r.qdd.data(), w.lam_zero.data(), in, p, k,
                                            s.dq, s.dqd, s.dqdd, s.dinp, s.dp, w.out.data(), s.dout);
        put_directions(w.moving, w, w.dout);
      }
      for (int d : w.still) jacobian_times(r.J, dqd.data() + d * n, w.dout.data() + d * 2 * m + m);
    }
    r.Jv.solve(w.dout.data() + m, 2 * m, nd, w.dv.data(), m);
    for (int i = 0; i < m; ++i) dqd.row(v_[i]) = -w.dv.row(i);
  }
}

void ReducedDynamics::jacobian_times(const RowMatrix& J, const double* x, double* out) const {
  for (int i = 0; i < model_.m; ++i) out[i] = 0.0;
  for (const JacobianEntry& e : seeded_entries_) out[e.row] += J(e.row, e.col) * x[e.col];
}

void ReducedDynamics::split_directions(const Matrix& dq, const Matrix* dp, int nd, std::vector<int>& moving,
                                       std::vector<int>& still) {
  moving.clear();
  still.clear();
  for (int d = 0; d < nd; ++d) {
    const bool moves = !(dq.col(d).array() == 0.0).all() || (dp && !(dp->col(d).array() == 0.0).all());
    (moves ? moving : still).push_back(d);
  }
}

void ReducedDynamics::gather_columns(const Matrix& a, const std::vector<int>& cols, Matrix& out) {
  out.resize(a.rows(), static_cast<Eigen::Index>(cols.size()));
  for (std::size_t c = 0; c < cols.size(); ++c) out.col(static_cast<Eigen::Index>(c)) = a.col(cols[c]);
}

bool ReducedDynamics::leading(const std::vector<int>& cols) {
  for (std::size_t c = 0; c < cols.size(); ++c)
    if (cols[c] != static_cast<int>(c)) return false;
  return true;
}

ReducedDynamics::DirectionSeeds ReducedDynamics::directions(const std::vector<int>& cols, const Matrix& dq,
                                                            const Matrix& dqd, const Matrix& dqdd, Matrix& dout,
                                                            Result::Work& w) {
  if (leading(cols))
    return {dq.data(), dqd.data(), dqdd.data(), w.dinp.data(), w.dp.data(), w.dinp.rows(), w.dp.rows(), dout.data()};
  gather_columns(dq, cols, w.g_dq), gather_columns(dqd, cols, w.g_dqd), gather_columns(dqdd, cols, w.g_dqdd);
  gather_columns(w.dinp, cols, w.g_dinp), gather_columns(w.dp, cols, w.g_dp);
  w.g_dout.resize(dout.rows(), static_cast<Eigen::Index>(cols.size()));
  return {w.g_dq.data(),   w.g_dqd.data(),   w.g_dqdd.data(),  w.g_dinp.data(),
          w.g_dp.data(),   w.g_dinp.rows(),  w.g_dp.rows(),    w.g_dout.data()};
}

void ReducedDynamics::put_directions(const std::vector<int>& cols, Result::Work& w, Matrix& dout) {
  if (leading(cols)) return;
  for (std::size_t c = 0; c < cols.size(); ++c) dout.col(cols[c]) = w.g_dout.col(static_cast<Eigen::Index>(c));
}

int ReducedDynamics::tangent_block(const Result::Work& w, int d, const Matrix& dq, const Matrix& dqd,
                                   const Matrix& dqdd) const {
  const int n = model_.n;
  bool moves = false;
  int group = -2;  // -2: no seed yet; -1: seeds outside any one group
  for (const Matrix* seeds : {&dq, &dqd, &dqdd}) {
    const double* col = seeds->data() + static_cast<Eigen::Index>(d) * n;
    for (int i = 0; i < n && group != -1; ++i) {
      if (col[i] == 0.0) continue;
      moves = moves || seeds == &dq;
      const int g = model_.tangent_group[i];
      group = group == -2 || group == g ? g : -1;
    }
  }
  const bool loads = !(w.dinp.col(d).array() == 0.0).all() || !(w.dp.col(d).array() == 0.0).all();
  if (group >= 0 && !loads) return 2 + 2 * group + (moves ? 0 : 1);
  // a direction without seeds is cheapest in any group's velocity block
  if (group == -2 && !loads && model_.tangent_groups > 0) return 3;
  return moves ? 0 : 1;
}

void ReducedDynamics::residual_tangent(const Result& r, const double* lam, const double* in, const double* p, int nd,
                                       const Matrix& dq, const Matrix& dqd, const Matrix& dqdd) const {
  Result::Work& w = r.work;
  const int n = model_.n, rows = n + model_.m;
  w.out.resize(rows);
  w.dout.resize(rows, nd);
  if (model_.residual_tangent_groups) {
    // each direction in its block, the blocks' directions consecutive (a counting sort)
    const int blocks = 2 + 2 * model_.tangent_groups;
    w.block.resize(nd);
    w.order.resize(nd);
    w.per_block.assign(2 * blocks, 0);
    int* const count = w.per_block.data();
    int* const next = count + blocks;  // where each block's next direction goes in order
    for (int d = 0; d < nd; ++d) ++count[w.block[d] = tangent_block(w, d, dq, dqd, dqdd)];
    // A block runs its directions two at a time and an odd last one alone; the position block
    // takes a velocity direction of its group (dq = 0 is a seed like any other there) to make
    // up a pair: one pass on pairs costs less than the odd pass and the velocity block's.
    for (int b = 0; b < blocks; b += 2)
      if (count[b] % 2 == 1 && count[b + 1] > 0)
        for (int d = nd - 1; d >= 0; --d)
          if (w.block[d] == b + 1) {
            w.block[d] = b, ++count[b], --count[b + 1];
            break;
          }
    for (int b = 1; b < blocks; ++b) next[b] = next[b - 1] + count[b - 1];
    for (int d = 0; d < nd; ++d) w.order[next[w.block[d]]++] = d;
    const DirectionSeeds s = directions(w.order, dq, dqd, dqdd, w.dout, w);
    model_.residual_tangent_groups(r.q.data(), r.qd.data(), r.qdd.data(), lam, in, p, count, s.dq, s.dqd, s.dqdd,
                                   s.dinp, s.dp, w.out.data(), s.dout);
    put_directions(w.order, w, w.dout);
    return;
  }
  if (model_.residual_velocity_tangent) split_directions(dq, nullptr, nd, w.moving, w.still);
  if (!model_.residual_velocity_tangent || w.still.empty()) {
    model_.residual_tangent(r.q.data(), r.qd.data(), r.qdd.data(), lam, in, p, nd, dq.data(), dqd.data(),
                            dqdd.data(), w.dinp.data(), w.dp.data(), w.out.data(), w.dout.data());
    return;
  }
  // the moving directions' tangent, then the others' (dq = 0) from the velocity tangent, on
  // seeds whose first k columns are the moving directions
  const int k = static_cast<int>(w.moving.size());
  std::vector<int>& order = w.moving;  // moving, then still
  order.insert(order.end(), w.still.begin(), w.still.end());
  const DirectionSeeds s = directions(order, dq, dqd, dqdd, w.dout, w);
  if (k > 0)
    model_.residual_tangent(r.q.data(), r.qd.data(), r.qdd.data(), lam, in, p, k, s.dq, s.dqd, s.dqdd, s.dinp, s.dp,
                            w.out.data(), s.dout);
  model_.residual_velocity_tangent(r.q.data(), r.qd.data(), r.qdd.data(), lam, in, p, nd - k, s.dqd + k * n,
                                   s.dqdd + k * n, s.dinp + k * s.ld_inp, s.dp + k * s.ld_p, w.out.data(),
                                   s.dout + static_cast<Eigen::Index>(k) * rows);
  put_directions(order, w, w.dout);
}

void ReducedDynamics::tangent(const Result& r, const double* inputs, const double* p, int nd, const double* du,
                              const double* dud, const double* dinputs, const double* dp, Matrix& dq, Matrix& dqd,
                              Matrix& dqdd) const {
  tangent_kinematics(r, inputs, p, nd, du, dud, dinputs, dp, dq, dqd);
  dqdd = r.work.dqdd_seed;  // the seeds tangent_kinematics arranged serve the dynamic half too
  dynamics_from_seeds(r, inputs, p, nd, dq, dqd, dqdd);
}

void ReducedDynamics::tangent_dynamics(const Result& r, const double* inputs, const double* p_in, int nd,
                                       const double* dinputs, const double* dp_in, const Matrix& dq,
                                       const Matrix& dqd, Matrix& dqdd) const {
  seed_arrays(nd, dinputs, dp_in, r.work.dinp, r.work.dp, dqdd);
  dynamics_from_seeds(r, inputs, p_in, nd, dq, dqd, dqdd);
}

void ReducedDynamics::dynamics_from_seeds(const Result& r, const double* inputs, const double* p_in, int nd,
                                          const Matrix& dq, const Matrix& dqd, Matrix& dqdd) const {
  const int n = model_.n, m = model_.m;
  const double* p = params(p_in);
  const double* in = model_.inputs ? inputs : pad_.data();
  Result::Work& w = r.work;
  const double* lam = m ? r.lam.data() : pad_.data();
  // dr = dM qdd + dc - dJ^T lam (qdd, lam frozen; driven dqdd seeded), da = dJ qdd + d(Jdot qd).
  residual_tangent(r, lam, in, p, nd, dq, dqd, dqdd);
  const int nf = static_cast<int>(f_.size()), nu = this->nu(), rows = n + m;
  w.dudd.resize(nu, nd);
  double* dudd = w.dudd.data();
  // a tree in coordinate order: B = I (see solve_dynamics), dudd = -M^-1 dr
  if (m == 0 && u_ == f_) {
    for (int d = 0; d < nd; ++d)
      for (int a = 0; a < nf; ++a) dudd[d * nu + a] = w.dout(f_[a], d);
    r.reduced.solve_in_place(dudd, nu, nd);
    for (int d = 0; d < nd; ++d)
      for (int a = 0; a < nf; ++a) dqdd(f_[a], d) = -dudd[d * nu + a];
    return;
  }
  // dbeta = -Jv^-1 da on the dependent rows (zero on the independent ones); then, direction by
  // direction over B's structure, B^T M_ff (B dudd + dbeta) = -B^T dr: the right-hand side
  // B^T dr + (M_ff B)^T dbeta (M symmetric, M_ff B from solve_dynamics), solved, and
  // dqdd = B dudd + dbeta on the free coordinates.
  if (m > 0) {
    w.dbeta_v.resize(m, nd);
    r.Jv.solve(w.dout.data() + n, rows, nd, w.dbeta_v.data(), m);
    w.MBv.resize(m, nu);  // the dependent rows of M_ff B: dbeta is zero on the others
    for (const auto& [a, k] : dependent_rows_) w.MBv.row(k) = r.MBf.row(a);
    w.dudd.noalias() = w.MBv.transpose() * w.dbeta_v;  // -(M_ff B)^T dbeta
  } else {
    w.dudd.setZero();
  }
  const double* B = r.B.data();
  for (int d = 0; d < nd; ++d) {
    const double* dr = w.dout.data() + static_cast<Eigen::Index>(d) * rows;
    double* __restrict rhs = dudd + static_cast<Eigen::Index>(d) * nu;
    for (int c = 0; c < nu; ++c) rhs[c] = -rhs[c];
    for (const IndependentRow& u : independent_rows_) rhs[u.place] += dr[u.q];
    for (const DependentEntry& e : dependent_entries_) rhs[e.c] += B[e.b] * dr[e.q];
  }
  r.reduced.solve_in_place(dudd, nu, nd);  // -dudd
  for (int d = 0; d < nd; ++d) {
    const double* dbv = m > 0 ? w.dbeta_v.data() + static_cast<Eigen::Index>(d) * m : nullptr;
    const double* minus_du = dudd + static_cast<Eigen::Index>(d) * nu;
    double* __restrict out = dqdd.data() + static_cast<Eigen::Index>(d) * n;
    for (const IndependentRow& u : independent_rows_) out[u.q] = -minus_du[u.place];
    for (const auto& [a, k] : dependent_rows_) out[f_[a]] = -dbv[k];
    for (const DependentEntry& e : dependent_entries_) out[e.q] -= B[e.b] * minus_du[e.c];
  }
}

}  // namespace dydp::mbs
