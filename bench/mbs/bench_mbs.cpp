// Generated against numerical multibody dynamics. For one model at one state (independent
// coordinates near the initial configuration, random velocities and inputs):
//   generated: ReducedDynamics::solve (generated M, c, h, J, Jdot qd; partitioning; Cholesky),
//   oracle: NumericDynamics::direct_dynamics (Newton-Euler at run time in ground components,
//           M by unit accelerations, the augmented system by LU),
//   tangent: ReducedDynamics::tangent seeded on every u and u_dot (2 nu directions).
// Each iteration times all three back to back, so the ratios (counters) come from the same
// machine load: oracle_over_generated, and tangent_per_direction_over_udd.
#include <benchmark/benchmark.h>

#include <chrono>
#include <random>
#include <string>

#include "generated_models/registry.hpp"
#include "symbolic/mbs/numeric_dynamics.hpp"
#include "symbolic/mbs/reduced_dynamics.hpp"

namespace {

using dydp::mbs::GeneratedModel;
using dydp::mbs::NumericDynamics;
using dydp::mbs::ReducedDynamics;
using Vector = Eigen::VectorXd;
using Matrix = Eigen::MatrixXd;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

void compare(benchmark::State& state, const std::string& name) {
  const GeneratedModel& g = *dydp::generated::find_model(name);
  NumericDynamics oracle(dydp::mbs::load_model(std::string(DYDP_MODELS_DIR) + "/" + name + ".mbs.yaml"));
  ReducedDynamics reduced(g);
  const int nu = reduced.nu();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const Vector q0 = Eigen::Map<const Vector>(g.initial_q, g.n);
  Vector u(nu), ud(nu), inputs = Vector::Zero(std::max(1, g.inputs));
  for (int i = 0; i < nu; ++i) {
    u[i] = q0[reduced.independent()[i]] + 0.02 * unit(rng);
    ud[i] = 0.5 * unit(rng);
  }
  for (int i = 0; i < g.load_inputs; ++i) inputs[i] = 100.0 * unit(rng);
  Vector q = q0, qd = Vector::Zero(g.n);
  for (int i = 0; i < nu; ++i) {
    q[reduced.independent()[i]] = u[i];
    qd[reduced.independent()[i]] = ud[i];
  }
  const int nd = 2 * nu;
  Matrix seeds_u = Matrix::Zero(nu, nd), seeds_ud = Matrix::Zero(nu, nd);
  seeds_u.leftCols(nu) = Matrix::Identity(nu, nu);
  seeds_ud.rightCols(nu) = Matrix::Identity(nu, nu);
  ReducedDynamics::Result r;
  Matrix dq, dqd, dqdd;
  const std::vector<int> independent = reduced.independent();
  const Vector oracle_inputs = inputs.head(g.inputs);
  double t_generated = 0.0, t_oracle = 0.0, t_tangent = 0.0;
  std::int64_t rounds = 0;
  for (auto _ : state) {
    auto start = Clock::now();
    reduced.solve(u.data(), ud.data(), inputs.data(), nullptr, q0, r);
    t_generated += seconds_since(start);
    benchmark::DoNotOptimize(r.udd.data());
    start = Clock::now();
    reduced.tangent(r, inputs.data(), nullptr, nd, seeds_u.data(), seeds_ud.data(), nullptr, nullptr, dq, dqd, dqdd);
    t_tangent += seconds_since(start);
    benchmark::DoNotOptimize(dqdd.data());
    start = Clock::now();
    const NumericDynamics::State s = oracle.direct_dynamics(q, qd, oracle_inputs, independent);
    t_oracle += seconds_since(start);
    benchmark::DoNotOptimize(s.qdd.data());
    ++rounds;
  }
  state.counters["generated_us"] = 1e6 * t_generated / rounds;
  state.counters["oracle_us"] = 1e6 * t_oracle / rounds;
  state.counters["tangent_us"] = 1e6 * t_tangent / rounds;
  state.counters["directions"] = nd;
  state.counters["oracle_over_generated"] = t_oracle / t_generated;
  state.counters["tangent_per_direction_over_udd"] = t_tangent / nd / t_generated;
}

void BM_Sedan(benchmark::State& state) { compare(state, "sedan"); }
void BM_Chain200(benchmark::State& state) { compare(state, "chain200"); }
BENCHMARK(BM_Sedan)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Chain200)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
