// Every generated model against the numerical Newton-Euler oracle (an independent formalism:
// ground-frame components, Eigen rotations, M by unit accelerations): M, c, the residual with
// cut forces, h, J, Jdot qd, sensors, point Jacobians at random states to 1e-10 relative; the
// partitioned direct dynamics udd (with v, v_dot, lam) likewise; its tangent against central
// differences of the oracle's direct dynamics, with a step study, to 1e-7.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "chain9/chain9.hpp"
#include "generated_models/registry.hpp"
#include "model_cases.hpp"
#include "oracle_compare.hpp"
#include "symbolic/mbs/numeric_dynamics.hpp"
#include "symbolic/mbs/reduced_dynamics.hpp"

namespace dydp::mbs {
namespace {

using namespace dydp::mbs::testing;

struct Fixture {
  const GeneratedModel* g;
  Model model;
  Vector p;  // symbolic parameters (padded)
  explicit Fixture(const std::string& name)
      : g(generated::find_model(name)), model(load_model(std::string(DYDP_MODELS_DIR) + "/" + name + ".mbs.yaml")) {
    p = Vector::Zero(std::max(g->parameters, 1));
    for (int i = 0; i < g->parameters; ++i) p[i] = g->parameter_values[i];
  }
};

Args random_args(std::mt19937& rng, const GeneratedModel& g, const Vector& p) {
  Args a;
  a.q = random_vector(rng, g.n, 1.2);
  a.qd = random_vector(rng, g.n, 2.0);
  a.qdd = random_vector(rng, g.n, 3.0);
  a.lam = random_vector(rng, g.m, 5.0);
  a.inp = random_vector(rng, g.inputs, 10.0);
  a.p = p;
  for (int i = 0; i < g.parameters; ++i) a.p[i] *= 1.0 + 0.1 * random_vector(rng, 1, 1.0)[0];
  return a;
}

class Generated : public ::testing::TestWithParam<std::string> {};
// The models with sensors only (instantiated below from models_where).
class GeneratedWithSensors : public Generated {};

TEST_P(Generated, EveryFunctionMatchesTheOracle) {
  Fixture f(GetParam());
  ASSERT_NE(f.g, nullptr);
  const GeneratedModel& g = *f.g;
  ASSERT_EQ(g.n, f.model.coordinates());
  ASSERT_EQ(g.m, f.model.constraint_count());
  NumericDynamics oracle(f.model);
  std::mt19937 rng(7);
  for (int trial = 0; trial < 3; ++trial) {
    const Args a = random_args(rng, g, f.p);
    oracle.set_symbolic_parameters(a.p.data());
    const int n = g.n, m = g.m;
    const Vector q = a.q.head(n), qd = a.qd.head(n), qdd = a.qdd.head(n), lam = a.lam.head(m),
                 inp = a.inp.head(g.inputs);

    const Matrix M = oracle.mass(q);
    EXPECT_LT(relative_error(generated_mass(g, a), M), 1e-10) << "M";
    // the composite-inertia entries (written as loops for chain200), and the entries they leave
    // out are zero in the oracle's M
    ASSERT_NE(g.mass_matrix, nullptr);
    EXPECT_LT(relative_error(generated_mass_matrix(g, a), M), 1e-10) << "M by composite inertias";
    const Vector r = generated_outputs(g.residual, n + m, a);
    EXPECT_LT(relative_error(r.head(n), oracle.residual(q, qd, qdd, Vector::Zero(m), inp)), 1e-10)
        << "M qdd + c (the residual reads no multipliers)";
    const Vector with_cut_forces = tangent_primal(g.residual_tangent, n + m, a);
    EXPECT_LT(relative_error(with_cut_forces.head(n), oracle.residual(q, qd, qdd, lam, inp)), 1e-10)
        << "M qdd + c - J^T lam (the residual tangent's primal)";
    if (m > 0) {
      EXPECT_GT(relative_error(with_cut_forces.head(n), r.head(n)), 1e-6) << "the random multipliers load the joints";
      Args unloaded = a;
      unloaded.lam.setZero();
      EXPECT_LT(relative_error(tangent_primal(g.residual_tangent, n + m, unloaded), r), 1e-12)
          << "without multipliers the tangent's primal is the residual";
    }
    Args at_rest = a;
    at_rest.qdd.setZero();
    at_rest.lam.setZero();
    EXPECT_LT(relative_error(generated_outputs(g.residual, n + m, at_rest).head(n), oracle.nonlinear(q, qd, inp)),
              1e-10)
        << "c";
    if (m > 0) {
      const Matrix J = oracle.constraint_jacobian(q);
      const Vector bias = oracle.constraint_bias(q, qd);
      EXPECT_LT(relative_error(r.tail(m), J * qdd + bias), 1e-10) << "J qdd + Jdot qd";
      const Vector hj = generated_outputs(g.constraints, m + m * n, a);
      EXPECT_LT(relative_error(hj.head(m), oracle.constraints(q)), 1e-10) << "h";
      const Matrix Jg = Eigen::Map<const Eigen::Matrix<double, -1, -1, Eigen::RowMajor>>(hj.data() + m, m, n);
      EXPECT_LT(relative_error(Jg, J), 1e-10) << "J";
      EXPECT_LT(relative_error(generated_outputs(g.residual, n + m, at_rest).tail(m), bias), 1e-10) << "Jdot qd";
    }
    if (g.sensor_outputs > 0) {
      EXPECT_LT(relative_error(generated_outputs(g.sensors, g.sensor_outputs, a), oracle.sensors(q, qd, qdd)), 1e-10)
          << "sensors";
    }
  }
}

// The two sensor groups (ports that do not read qdd, ports that do) are the full sensors'
// outputs split by port, in port order: values and tangents (three directions, seeded on every
// array) agree entry by entry with `sensors` and `sensors_tangent`, and every output is in
// exactly one group.
TEST_P(GeneratedWithSensors, SensorGroupsAreTheSensorsSplitByPort) {
  Fixture f(GetParam());
  ASSERT_NE(f.g, nullptr);
  const GeneratedModel& g = *f.g;
  ASSERT_GT(g.sensor_outputs, 0) << "no sensors";
  std::mt19937 rng(11);
  const Args a = random_args(rng, g, f.p);
  const int nd = 3, ns = g.sensor_outputs;
  auto seeds = [&](int size) { return Vector(random_vector(rng, std::max(1, size) * nd, 1.0)); };
  const Vector sq = seeds(g.n), sqd = seeds(g.n), sqdd = seeds(g.n), sinp = seeds(g.inputs), sp = seeds(g.parameters);
  auto tangent = [&](GeneratedTangent fn, int size) {
    std::vector<double> out(std::max(1, size)), dout(static_cast<std::size_t>(std::max(1, size)) * nd);
    fn(a.q.data(), a.qd.data(), a.qdd.data(), a.lam.data(), a.inp.data(), a.p.data(), nd, sq.data(), sqd.data(),
       sqdd.data(), sinp.data(), sp.data(), out.data(), dout.data());
    return std::make_pair(out, dout);
  };
  const Vector full = generated_outputs(g.sensors, ns, a);
  const auto [full_out, full_dout] = tangent(g.sensors_tangent, ns);
  int group_size[2] = {0, 0};
  for (int k = 0; k < g.sensor_count; ++k) group_size[g.sensor_reads_acceleration[k] ? 1 : 0] += g.sensor_widths[k];
  ASSERT_EQ(group_size[0] + group_size[1], ns);
  const Vector value[2] = {generated_outputs(g.sensors_kinematic, group_size[0], a),
                           generated_outputs(g.sensors_acceleration, group_size[1], a)};
  const auto kinematic = tangent(g.sensors_kinematic_tangent, group_size[0]);
  const auto acceleration = tangent(g.sensors_acceleration_tangent, group_size[1]);
  const std::pair<std::vector<double>, std::vector<double>>* group_tangent[2] = {&kinematic, &acceleration};
  int at = 0, in_group[2] = {0, 0};
  for (int k = 0; k < g.sensor_count; ++k) {
    const int group = g.sensor_reads_acceleration[k] ? 1 : 0;
    for (int i = 0; i < g.sensor_widths[k]; ++i, ++at) {
      const int j = in_group[group]++;
      const std::string what = std::string(g.sensor_names[at]) + (group ? " (acceleration group)" : " (kinematic group)");
      EXPECT_NEAR(value[group][j], full[at], 1e-12 * (1.0 + std::abs(full[at]))) << what;
      EXPECT_NEAR(group_tangent[group]->first[j], full_out[at], 1e-12 * (1.0 + std::abs(full_out[at]))) << what;
      for (int d = 0; d < nd; ++d) {
        const double expected = full_dout[static_cast<std::size_t>(d) * ns + at];
        EXPECT_NEAR(group_tangent[group]->second[static_cast<std::size_t>(d) * group_size[group] + j], expected,
                    1e-12 * (1.0 + std::abs(expected)))
            << what << ", direction " << d;
      }
    }
  }
}

// A consistent random state near the initial configuration: independent coordinates and
// velocities, inputs (driven motions near their initial values), parameters.
struct DynamicsCase {
  Vector u, ud, inputs, p, guess;
};

DynamicsCase random_case(std::mt19937& rng, const GeneratedModel& g, const Vector& p) {
  const int nu = g.independent_count;
  DynamicsCase c;
  c.guess = Eigen::Map<const Vector>(g.initial_q, g.n);
  c.u = random_vector(rng, nu, 0.05);
  c.ud = random_vector(rng, nu, 1.0);
  for (int i = 0; i < nu; ++i) c.u[i] += g.initial_q[g.independent[i]];
  c.inputs = random_vector(rng, g.inputs, 5.0);
  for (int i = 0; i < g.driven_count; ++i) {
    const int at = g.load_inputs + 3 * i;
    c.inputs[at] = g.initial_q[g.driven[i]] + 0.1 * c.inputs[at] / 5.0;
  }
  c.p = p;
  for (int i = 0; i < g.parameters; ++i) c.p[i] *= 1.0 + 0.05 * random_vector(rng, 1, 1.0)[0];
  return c;
}

NumericDynamics::State oracle_dynamics(NumericDynamics& oracle, const GeneratedModel& g, const DynamicsCase& c) {
  oracle.set_symbolic_parameters(c.p.data());
  Vector q = c.guess, qd = Vector::Zero(g.n);
  std::vector<int> independent(g.independent, g.independent + g.independent_count);
  for (int i = 0; i < g.independent_count; ++i) {
    q[g.independent[i]] = c.u[i];
    qd[g.independent[i]] = c.ud[i];
  }
  return oracle.direct_dynamics(q, qd, c.inputs.head(g.inputs), independent);
}

TEST_P(Generated, DirectDynamicsAndTangentMatchTheOracle) {
  Fixture f(GetParam());
  const GeneratedModel& g = *f.g;
  NumericDynamics oracle(f.model);
  ReducedDynamics reduced(g);
  std::mt19937 rng(11);
  const DynamicsCase c = random_case(rng, g, f.p);
  ReducedDynamics::Result r;
  reduced.solve(c.u.data(), c.ud.data(), c.inputs.data(), c.p.data(), c.guess, r);
  const NumericDynamics::State s = oracle_dynamics(oracle, g, c);
  EXPECT_LT(relative_error(r.q, s.q), 1e-10) << "q (v from Newton-Raphson)";
  EXPECT_LT(relative_error(r.qd, s.qd), 1e-10) << "qd";
  // Forward errors of a linear solve scale with the condition number of the reduced mass
  // matrix (a 200-body chain's is ~5e8): ill-conditioned models are checked by backward errors
  // (the oracle's equations of motion evaluated at the generated solution) instead.
  oracle.set_symbolic_parameters(c.p.data());
  Eigen::JacobiSVD<Matrix> svd(oracle.mass(r.q));
  const double condition = svd.singularValues()(0) / svd.singularValues()(g.n - 1);
  const bool well_conditioned = condition < 1e6;
  RecordProperty("mass_condition", std::to_string(condition));
  if (well_conditioned) {
    EXPECT_LT(relative_error(r.qdd, s.qdd), 1e-10) << "qdd";
    if (g.m > 0) {
      EXPECT_LT(relative_error(r.lam, s.lam), 1e-9) << "lambda";
    }
  } else {
    ASSERT_EQ(g.m, 0) << "backward checks are written for tree models";
    oracle.set_symbolic_parameters(c.p.data());
    const Vector inputs = c.inputs.head(g.inputs);
    const Matrix M = oracle.mass(r.q);
    const Vector rest = oracle.residual(r.q, r.qd, r.qdd, Vector(), inputs);
    const double scale = (M * r.qdd).cwiseAbs().maxCoeff() + oracle.nonlinear(r.q, r.qd, inputs).cwiseAbs().maxCoeff();
    EXPECT_LT(rest.cwiseAbs().maxCoeff() / scale, 1e-12) << "M qdd + c at the generated qdd";
    EXPECT_LT(relative_error(r.qdd, s.qdd), 1e-15 * condition) << "qdd, within the conditioning";
  }

  // Directions: every u, u_dot, input and parameter (a sample of them on large models).
  const int nu = g.independent_count, ni = g.inputs, np = g.parameters;
  const int total = 2 * nu + ni + np;
  std::vector<int> picked;
  for (int d = 0; d < total; ++d)
    if (total <= 40 || d % (total / 8) == 0 || d == total - 1) picked.push_back(d);
  const int nd = static_cast<int>(picked.size());
  Matrix du = Matrix::Zero(nu, nd), dud = Matrix::Zero(nu, nd), din = Matrix::Zero(std::max(ni, 1), nd),
         dp = Matrix::Zero(std::max(np, 1), nd);
  for (int k = 0; k < nd; ++k) {
    const int d = picked[k];
    if (d < nu)
      du(d, k) = 1.0;
    else if (d < 2 * nu)
      dud(d - nu, k) = 1.0;
    else if (d < 2 * nu + ni)
      din(d - 2 * nu, k) = 1.0;
    else
      dp(d - 2 * nu - ni, k) = 1.0;
  }
  Matrix dq, dqd, dqdd;
  reduced.tangent(r, c.inputs.data(), c.p.data(), nd, du.data(), dud.data(), din.data(), dp.data(), dq, dqd, dqdd);
  {
    // The same directions without the parameters' (dh = J dq, the position constraints'
    // tangent not called), one call per direction (the velocity tangent alone for each
    // direction that moves no coordinate): the same tangents.
    std::vector<int> kept;
    for (int k = 0; k < nd; ++k)
      if (picked[k] < 2 * nu + ni) kept.push_back(k);
    for (int k : kept) {
      Matrix eq, eqd, eqdd;
      const Vector one_du = du.col(k), one_dud = dud.col(k), one_din = din.col(k);
      reduced.tangent(r, c.inputs.data(), c.p.data(), 1, one_du.data(), one_dud.data(), one_din.data(), nullptr, eq,
                      eqd, eqdd);
      const double scale = std::max({dq.col(k).cwiseAbs().maxCoeff(), dqd.col(k).cwiseAbs().maxCoeff(),
                                     dqdd.col(k).cwiseAbs().maxCoeff(), 1.0});
      const double difference = std::max({(eq - dq.col(k)).cwiseAbs().maxCoeff(), (eqd - dqd.col(k)).cwiseAbs().maxCoeff(),
                                          (eqdd - dqdd.col(k)).cwiseAbs().maxCoeff()});
      // (rounding only; amplified by the reduced mass matrix's conditioning on a long chain)
      EXPECT_LT(difference, (well_conditioned ? 1e-9 : 1e-13 * condition) * scale)
          << "direction " << picked[k] << " alone, without parameter seeds";
    }
  }

  if (!well_conditioned) {
    // Backward check of the tangent: M dqdd + dr = 0 with dr the central difference of the
    // oracle's residual at frozen accelerations (well conditioned whatever M is).
    oracle.set_symbolic_parameters(c.p.data());
    const Matrix M = oracle.mass(r.q);
    double worst = 0.0;
    for (int k = 0; k < nd; ++k) {
      double best_k = 1e300;
      for (double h : {1e-3, 1e-4, 1e-5}) {
        auto residual_at = [&](double sign) {
          DynamicsCase x = c;
          x.u += sign * h * du.col(k);
          x.ud += sign * h * dud.col(k);
          x.inputs += sign * h * din.col(k);
          Vector q = r.q, qd = r.qd;
          for (int i = 0; i < nu; ++i) {
            q[g.independent[i]] = x.u[i];
            qd[g.independent[i]] = x.ud[i];
          }
          return Vector(oracle.residual(q, qd, r.qdd, Vector(), x.inputs.head(ni)));
        };
        const Vector dr = (residual_at(1.0) - residual_at(-1.0)) / (2 * h);
        const Vector lhs = M * dqdd.col(k);
        best_k = std::min(best_k, (lhs + dr).cwiseAbs().maxCoeff() / std::max(dr.cwiseAbs().maxCoeff(), 1e-300));
      }
      worst = std::max(worst, best_k);
    }
    RecordProperty("tangent_backward_error", std::to_string(worst));
    EXPECT_LT(worst, 1e-7) << "M dqdd + dr against central differences of the oracle's residual";
    return;
  }
  double best = 1e300, best_step = 0.0;
  for (double h : {1e-3, 1e-4, 1e-5, 1e-6}) {
    Matrix fd_q(g.n, nd), fd_qd(g.n, nd), fd_qdd(g.n, nd);
    for (int k = 0; k < nd; ++k) {
      DynamicsCase plus = c, minus = c;
      plus.guess = minus.guess = r.q;
      plus.u += h * du.col(k);
      minus.u -= h * du.col(k);
      plus.ud += h * dud.col(k);
      minus.ud -= h * dud.col(k);
      plus.inputs += h * din.col(k);
      minus.inputs -= h * din.col(k);
      plus.p += h * dp.col(k);
      minus.p -= h * dp.col(k);
      const auto sp = oracle_dynamics(oracle, g, plus), sm = oracle_dynamics(oracle, g, minus);
      fd_q.col(k) = (sp.q - sm.q) / (2 * h);
      fd_qd.col(k) = (sp.qd - sm.qd) / (2 * h);
      fd_qdd.col(k) = (sp.qdd - sm.qdd) / (2 * h);
    }
    const double e = std::max({relative_error(dq, fd_q), relative_error(dqd, fd_qd), relative_error(dqdd, fd_qdd)});
    if (e < best) {
      best = e;
      best_step = h;
    }
  }
  RecordProperty("tangent_error", std::to_string(best));
  EXPECT_LT(best, 1e-7) << "tangent against central differences (best step " << best_step << ")";
}

INSTANTIATE_TEST_SUITE_P(Models, Generated, ::testing::Values(DYDP_TEST_MODELS),
                         [](const auto& info) { return info.param; });
INSTANTIATE_TEST_SUITE_P(Models, GeneratedWithSensors, ::testing::ValuesIn(models_where({DYDP_TEST_MODELS}, has_sensors)),
                         [](const auto& info) { return info.param; });

TEST(Chain9, TipJacobianMatchesTheOracle) {
  Fixture f("chain9");
  NumericDynamics oracle(f.model);
  std::mt19937 rng(3);
  const Args a = random_args(rng, *f.g, f.p);
  std::vector<double> out(3 * 9);
  generated::tip_jacobian(a.q.data(), a.qd.data(), a.qdd.data(), a.lam.data(), a.inp.data(), a.p.data(), out.data());
  const Matrix J = Eigen::Map<const Eigen::Matrix<double, 3, 9, Eigen::RowMajor>>(out.data());
  const PointRef tip{static_cast<int>(f.model.bodies.size()) - 1, 0};
  EXPECT_LT(relative_error(J, oracle.point_jacobian(a.q.head(9), tip)), 1e-10);
}

}  // namespace
}  // namespace dydp::mbs
