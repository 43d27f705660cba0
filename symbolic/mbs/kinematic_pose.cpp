#include "symbolic/mbs/kinematic_pose.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace dydp::mbs {

KinematicSensors::KinematicSensors(const GeneratedModel& g) : g_(g) {
  for (int s = 0; s < g.sensor_count; ++s) {
    if (g.sensor_reads_acceleration[s]) {
      offset_.push_back(-1);
      continue;
    }
    offset_.push_back(size_);
    size_ += g.sensor_widths[s];
  }
}

int KinematicSensors::index(const std::string& port, int component) const {
  for (int s = 0; s < g_.sensor_count; ++s) {
    if (port != g_.sensor_ports[s]) continue;
    if (offset_[s] < 0 || component < 0 || component >= g_.sensor_widths[s]) return -1;
    return offset_[s] + component;
  }
  return -1;
}

namespace {

// The arrays every generated function reads, at one configuration (velocities and
// accelerations zero: a quasi-static pose), and the results of one evaluation.
class PoseEvaluation {
 public:
  PoseEvaluation(const GeneratedModel& g, const std::vector<double>& p)
      : g_(g), sensors_(g), p_(p), qd_(std::max(g.n, 1), 0.0), qdd_(qd_), lam_(std::max(g.m, 1), 0.0),
        inp_(std::max(g.inputs, 1), 0.0) {
    if (p_.empty()) p_.push_back(0.0);
  }

  /// h, J, the sensors and their derivatives w.r.t. every coordinate at q.
  void evaluate(const Eigen::VectorXd& q) {
    const int n = g_.n, m = g_.m, k = sensors_.size();
    set_driven(q);
    std::vector<double> hj(static_cast<size_t>(m + m * n) + 1);
    g_.constraints(q.data(), qd_.data(), qdd_.data(), lam_.data(), inp_.data(), p_.data(), hj.data());
    h = Eigen::Map<const Eigen::VectorXd>(hj.data(), m);
    J = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(hj.data() + m, m, n);
    // The sensors' tangent seeded on each coordinate (a driven one through its input too).
    std::vector<double> seed_q(static_cast<size_t>(n) * n, 0.0), seed_inp(static_cast<size_t>(n) * inp_.size(), 0.0);
    for (int i = 0; i < n; ++i) seed_q[static_cast<size_t>(i) * n + i] = 1.0;
    for (int i = 0; i < g_.driven_count; ++i)
      seed_inp[static_cast<size_t>(g_.driven[i]) * inp_.size() + g_.load_inputs + 3 * i] = 1.0;
    const std::vector<double> zero_n(static_cast<size_t>(n) * n, 0.0), zero_p(static_cast<size_t>(n) * p_.size(), 0.0);
    std::vector<double> out(static_cast<size_t>(k) + 1), dout(static_cast<size_t>(k) * n + 1);
    g_.sensors_kinematic_tangent(q.data(), qd_.data(), qdd_.data(), lam_.data(), inp_.data(), p_.data(), n,
                                 seed_q.data(), zero_n.data(), zero_n.data(), seed_inp.data(), zero_p.data(),
                                 out.data(), dout.data());
    S = Eigen::Map<const Eigen::VectorXd>(out.data(), k);
    S_q = Eigen::Map<const Eigen::MatrixXd>(dout.data(), k, n);
  }

  /// h and the sensors' derivatives w.r.t. the parameters `which`, at q (after evaluate(q)).
  void parameter_derivatives(const Eigen::VectorXd& q, const std::vector<int>& which) {
    const int n = g_.n, m = g_.m, k = sensors_.size(), np = static_cast<int>(which.size());
    h_p.setZero(m, np);
    S_p.setZero(k, np);
    if (np == 0) return;
    set_driven(q);
    std::vector<double> seed_p(static_cast<size_t>(np) * p_.size(), 0.0);
    for (int d = 0; d < np; ++d) seed_p[static_cast<size_t>(d) * p_.size() + which[d]] = 1.0;
    const std::vector<double> zero_n(static_cast<size_t>(np) * n + 1, 0.0),
        zero_inp(static_cast<size_t>(np) * inp_.size(), 0.0);
    std::vector<double> out(static_cast<size_t>(std::max(2 * m, k)) + 1),
        dout(static_cast<size_t>(std::max(m, k)) * np + 1);
    if (m > 0) {
      g_.constraints_tangent(q.data(), qd_.data(), qdd_.data(), lam_.data(), inp_.data(), p_.data(), np,
                             zero_n.data(), zero_n.data(), zero_n.data(), zero_inp.data(), seed_p.data(), out.data(),
                             dout.data());
      h_p = Eigen::Map<const Eigen::MatrixXd>(dout.data(), m, np);
    }
    g_.sensors_kinematic_tangent(q.data(), qd_.data(), qdd_.data(), lam_.data(), inp_.data(), p_.data(), np,
                                 zero_n.data(), zero_n.data(), zero_n.data(), zero_inp.data(), seed_p.data(),
                                 out.data(), dout.data());
    S_p = Eigen::Map<const Eigen::MatrixXd>(dout.data(), k, np);
  }

  Eigen::VectorXd h, S;
  Eigen::MatrixXd J, S_q, h_p, S_p;

 private:
  void set_driven(const Eigen::VectorXd& q) {
    for (int i = 0; i < g_.driven_count; ++i) inp_[g_.load_inputs + 3 * i] = q[g_.driven[i]];
  }

  const GeneratedModel& g_;
  KinematicSensors sensors_;
  std::vector<double> p_, qd_, qdd_, lam_, inp_;
};

}  // namespace

Pose solve_pose(const GeneratedModel& g, const std::vector<double>& p, const PoseSpec& spec,
                const std::vector<int>& parameters) {
  const int n = g.n, m = g.m;
  const int nt = static_cast<int>(spec.targets.size()), nf = static_cast<int>(spec.free.size());
  if (static_cast<int>(spec.q.size()) != n) throw std::runtime_error("pose: q has the wrong size");
  if (nf != m + nt)
    throw std::runtime_error("pose: " + std::to_string(nf) + " free coordinates for " + std::to_string(m) +
                             " constraints and " + std::to_string(nt) + " targets");
  if (static_cast<int>(p.size()) != g.parameters) throw std::runtime_error("pose: wrong number of parameters");
  std::vector<char> is_free(static_cast<size_t>(n), 0);
  for (const int j : spec.free) is_free[static_cast<size_t>(j)] = 1;

  PoseEvaluation e(g, p);
  Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(spec.q.data(), n);
  auto residual = [&]() {
    Eigen::VectorXd r(m + nt);
    r.head(m) = e.h;
    for (int t = 0; t < nt; ++t) r[m + t] = e.S[spec.targets[t].sensor] - spec.targets[t].value;
    return r;
  };
  auto jacobian = [&]() {
    Eigen::MatrixXd a(m + nt, nf);
    for (int c = 0; c < nf; ++c) {
      a.col(c).head(m) = e.J.col(spec.free[c]);
      for (int t = 0; t < nt; ++t) a(m + t, c) = e.S_q(spec.targets[t].sensor, spec.free[c]);
    }
    return a;
  };

  Pose pose;
  e.evaluate(q);
  Eigen::VectorXd r = residual();
  // Newton-Raphson, the step halved while it does not reduce the residual: a pose is a few
  // millimetres or degrees from the last one of a sweep, inside the quadratic range.
  constexpr int kMaxIterations = 40;
  for (; pose.iterations < kMaxIterations && r.lpNorm<Eigen::Infinity>() > 1e-13; ++pose.iterations) {
    Eigen::FullPivLU<Eigen::MatrixXd> lu(jacobian());
    if (!lu.isInvertible()) throw std::runtime_error("pose: the constraints and targets do not fix the free coordinates");
    const Eigen::VectorXd dz = lu.solve(-r);
    const double before = r.lpNorm<Eigen::Infinity>();
    double step = 1.0;
    Eigen::VectorXd trial = q;
    for (int halving = 0; halving < 30; ++halving, step *= 0.5) {
      trial = q;
      for (int c = 0; c < nf; ++c) trial[spec.free[c]] += step * dz[c];
      e.evaluate(trial);
      r = residual();
      if (r.lpNorm<Eigen::Infinity>() < before || before < 1e-10) break;
    }
    q = trial;
    if (step * dz.lpNorm<Eigen::Infinity>() < 1e-15) break;
  }
  pose.residual = r.lpNorm<Eigen::Infinity>();
  if (!(pose.residual < 1e-9))
    throw std::runtime_error("pose: Newton did not close the loops (residual " + std::to_string(pose.residual) + ")");

  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(jacobian());
  const int k = static_cast<int>(e.S.size());
  Eigen::MatrixXd S_free(k, nf);
  for (int c = 0; c < nf; ++c) S_free.col(c) = e.S_q.col(spec.free[c]);

  // Along s: the held coordinates move by q_rate, the targets by their rates.
  Eigen::VectorXd held_rate = Eigen::VectorXd::Zero(n);
  if (!spec.q_rate.empty())
    for (int j = 0; j < n; ++j)
      if (!is_free[static_cast<size_t>(j)]) held_rate[j] = spec.q_rate[static_cast<size_t>(j)];
  Eigen::VectorXd rhs(m + nt);
  rhs.head(m) = -e.J * held_rate;
  const Eigen::VectorXd S_held_rate = e.S_q * held_rate;
  for (int t = 0; t < nt; ++t) rhs[m + t] = spec.targets[t].rate - S_held_rate[spec.targets[t].sensor];
  const Eigen::VectorXd dz = lu.solve(rhs);
  pose.sensors_rate = S_held_rate + S_free * dz;

  // With respect to the parameters: the held coordinates and the targets stay. (No blocks of
  // zero-column matrices: Eigen offsets their null data pointer.)
  const int np = static_cast<int>(parameters.size());
  pose.sensors_dp.setZero(k, np);
  if (np > 0) {
    e.parameter_derivatives(q, parameters);
    Eigen::MatrixXd rhs_p(m + nt, np);
    rhs_p.topRows(m) = -e.h_p;
    for (int t = 0; t < nt; ++t) rhs_p.row(m + t) = -e.S_p.row(spec.targets[t].sensor);
    pose.sensors_dp = e.S_p + S_free * lu.solve(rhs_p);
  }
  pose.q = q;
  pose.sensors = e.S;
  return pose;
}

}  // namespace dydp::mbs
