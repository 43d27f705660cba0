// Generated dynamics against Orocos KDL on serial chains (chain9: 9 joints, one prismatic, offset
// and inclined bodies; chain200: 200 revolutes). The KDL chain is built from the same model file
// (kdl_chain.hpp; tests/mbs/test_kdl.cpp checks that both agree). Three comparisons:
//   inverse dynamics: the generated residual (M qdd + c, lam = 0, no inputs) vs ChainIdSolver_RNE;
//   mass matrix:      the generated inertial tangent seeded with the n identity columns
//                     (generated_mass_matrix below) vs ChainDynParam::JntToMass;
//   forward dynamics: ReducedDynamics::solve (residual, M by the tangent, Cholesky) vs
//                     ChainFdSolver_RNE (JntToMass, RNE at qdd = 0, KDL's LDL^T), and also vs
//                     KDL's same M and bias solved by Eigen's LLT instead of KDL's LDL^T
//                     (ldl_solver_eigen, plain loops), to tell the dynamics from the solve.
// Each benchmark iteration runs the seven parts back to back over the same kStates random states,
// accumulating the time of each part, so the ratios (counters kdl_over_generated_*) come from the
// same machine load. The work arrays are allocated once, outside the timed loops, except inside
// ReducedDynamics::solve, which allocates its own temporaries (its API allows nothing else).
#include <benchmark/benchmark.h>

#include <chrono>
#include <random>
#include <string>
#include <vector>

#include "bench/mbs/kdl_chain.hpp"
#include "generated_models/registry.hpp"
#include "symbolic/mbs/reduced_dynamics.hpp"

namespace {

using dydp::mbs::GeneratedModel;
using dydp::mbs::ReducedDynamics;
using Vector = Eigen::VectorXd;
using Matrix = Eigen::MatrixXd;
using Clock = std::chrono::steady_clock;

constexpr int kStates = 8;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// The generated mass matrix M(q): column j is the inertial pass's tangent along qdd = e_j
// (n directions). Kept in this one function so that a dedicated mass-matrix entry point of
// GeneratedModel can replace it.
struct MassWork {
  explicit MassWork(int n) : seeds(Matrix::Identity(n, n)), out(n), M(n, n) {}
  Matrix seeds;
  Vector out;
  Matrix M;
};
void generated_mass_matrix(const GeneratedModel& g, const double* q, const double* qd, const double* qdd,
                           const double* lam, const double* inp, const double* p, MassWork& w) {
  g.mass(q, qd, qdd, lam, inp, p, g.n, w.seeds.data(), w.out.data(), w.M.data());
}

// Forward dynamics from KDL's mass matrix and RNE at qdd = 0, solved by Eigen's Cholesky.
struct KdlLlt {
  explicit KdlLlt(int n) : llt(n), qdd(n), zero(n) { KDL::SetToZero(zero); }
  Eigen::LLT<Matrix> llt;
  Vector qdd;
  KDL::JntArray zero;
};
int kdl_forward_llt(dydp::bench::KdlDynamics& kdl, const KDL::JntArray& q, const KDL::JntArray& qd, KdlLlt& w) {
  if (const int e = kdl.mass(q)) return e;
  if (const int e = kdl.inverse(q, qd, w.zero)) return e;
  w.llt.compute(kdl.H.data);
  w.qdd = -kdl.torques.data;
  w.llt.solveInPlace(w.qdd);
  return w.llt.info() == Eigen::Success ? 0 : -1;
}

struct State {
  Vector q, qd, qdd, u, ud;
  KDL::JntArray kq, kqd, kqdd;
};

double max_relative(const Matrix& a, const Matrix& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(b.cwiseAbs().maxCoeff(), 1e-300);
}

void compare(benchmark::State& bs, const std::string& name) {
  const GeneratedModel& g = *dydp::generated::find_model(name);
  const int n = g.n;
  dydp::bench::KdlDynamics kdl(dydp::mbs::load_model(std::string(DYDP_MODELS_DIR) + "/" + name + ".mbs.yaml"));
  ReducedDynamics reduced(g);
  if (g.m != 0 || g.inputs != 0 || reduced.nu() != n) {
    bs.SkipWithError("not an unconstrained chain without inputs");
    return;
  }
  // Arrays of size zero are passed as one unused element.
  const Vector lam = Vector::Zero(1), inp = Vector::Zero(1);
  const Vector p = g.parameters ? Vector(Eigen::Map<const Vector>(g.parameter_values, g.parameters)) : Vector::Zero(1);

  std::mt19937 rng(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<State> states(kStates);
  for (State& s : states) {
    s.q.resize(n);
    s.qd.resize(n);
    s.qdd.resize(n);
    for (int i = 0; i < n; ++i) {
      s.q[i] = 1.5 * unit(rng);
      s.qd[i] = unit(rng);
      s.qdd[i] = unit(rng);
    }
    s.u.resize(n);
    s.ud.resize(n);
    for (int i = 0; i < n; ++i) {
      s.u[i] = s.q[reduced.independent()[i]];
      s.ud[i] = s.qd[reduced.independent()[i]];
    }
    s.kq.resize(n);
    s.kqd.resize(n);
    s.kqdd.resize(n);
    s.kq.data = s.q;
    s.kqd.data = s.qd;
    s.kqdd.data = s.qdd;
  }
  Vector residual(n);
  MassWork mass(n);
  ReducedDynamics::Result result;
  KDL::JntArray no_torques(n);
  KDL::SetToZero(no_torques);
  KdlLlt llt(n);

  // Both sides compute the same thing (tests/mbs/test_kdl.cpp checks it more closely).
  {
    const State& s = states[0];
    g.residual(s.q.data(), s.qd.data(), s.qdd.data(), lam.data(), inp.data(), p.data(), residual.data());
    generated_mass_matrix(g, s.q.data(), s.qd.data(), s.qdd.data(), lam.data(), inp.data(), p.data(), mass);
    reduced.solve(s.u.data(), s.ud.data(), inp.data(), nullptr, s.q, result);
    if (kdl.inverse(s.kq, s.kqd, s.kqdd) || kdl.mass(s.kq) || kdl.forward(s.kq, s.kqd, no_torques) ||
        max_relative(kdl.torques.data, residual) > 1e-10 || max_relative(kdl.H.data, mass.M) > 1e-10 ||
        max_relative(kdl.qdd.data, result.qdd) > 1e-7 || kdl_forward_llt(kdl, s.kq, s.kqd, llt) ||
        max_relative(llt.qdd, result.qdd) > 1e-7) {
      bs.SkipWithError("KDL and the generated functions disagree");
      return;
    }
  }

  double t_gen_id = 0, t_kdl_id = 0, t_gen_mass = 0, t_kdl_mass = 0, t_gen_fd = 0, t_kdl_fd = 0, t_kdl_llt = 0;
  std::int64_t rounds = 0;
  for (auto _ : bs) {
    auto start = Clock::now();
    for (const State& s : states) {
      g.residual(s.q.data(), s.qd.data(), s.qdd.data(), lam.data(), inp.data(), p.data(), residual.data());
      benchmark::DoNotOptimize(residual.data());
      benchmark::ClobberMemory();
    }
    t_gen_id += seconds_since(start);
    start = Clock::now();
    for (const State& s : states) {
      kdl.inverse(s.kq, s.kqd, s.kqdd);
      benchmark::DoNotOptimize(kdl.torques.data.data());
      benchmark::ClobberMemory();
    }
    t_kdl_id += seconds_since(start);

    start = Clock::now();
    for (const State& s : states) {
      generated_mass_matrix(g, s.q.data(), s.qd.data(), s.qdd.data(), lam.data(), inp.data(), p.data(), mass);
      benchmark::DoNotOptimize(mass.M.data());
      benchmark::ClobberMemory();
    }
    t_gen_mass += seconds_since(start);
    start = Clock::now();
    for (const State& s : states) {
      kdl.mass(s.kq);
      benchmark::DoNotOptimize(kdl.H.data.data());
      benchmark::ClobberMemory();
    }
    t_kdl_mass += seconds_since(start);

    start = Clock::now();
    for (const State& s : states) {
      reduced.solve(s.u.data(), s.ud.data(), inp.data(), nullptr, s.q, result);
      benchmark::DoNotOptimize(result.qdd.data());
      benchmark::ClobberMemory();
    }
    t_gen_fd += seconds_since(start);
    start = Clock::now();
    for (const State& s : states) {
      kdl.forward(s.kq, s.kqd, no_torques);
      benchmark::DoNotOptimize(kdl.qdd.data.data());
      benchmark::ClobberMemory();
    }
    t_kdl_fd += seconds_since(start);
    start = Clock::now();
    for (const State& s : states) {
      kdl_forward_llt(kdl, s.kq, s.kqd, llt);
      benchmark::DoNotOptimize(llt.qdd.data());
      benchmark::ClobberMemory();
    }
    t_kdl_llt += seconds_since(start);
    ++rounds;
  }
  const double per = 1e6 / (static_cast<double>(rounds) * kStates);  // microseconds per state
  bs.counters["n"] = n;
  bs.counters["gen_id_us"] = t_gen_id * per;
  bs.counters["kdl_id_us"] = t_kdl_id * per;
  bs.counters["gen_mass_us"] = t_gen_mass * per;
  bs.counters["kdl_mass_us"] = t_kdl_mass * per;
  bs.counters["gen_fd_us"] = t_gen_fd * per;
  bs.counters["kdl_fd_us"] = t_kdl_fd * per;
  bs.counters["kdl_llt_fd_us"] = t_kdl_llt * per;
  bs.counters["kdl_over_generated_id"] = t_kdl_id / t_gen_id;
  bs.counters["kdl_over_generated_mass"] = t_kdl_mass / t_gen_mass;
  bs.counters["kdl_over_generated_fd"] = t_kdl_fd / t_gen_fd;
  bs.counters["kdl_llt_over_generated_fd"] = t_kdl_llt / t_gen_fd;
}

void BM_KdlChain9(benchmark::State& state) { compare(state, "chain9"); }
void BM_KdlChain200(benchmark::State& state) { compare(state, "chain200"); }
BENCHMARK(BM_KdlChain9)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_KdlChain200)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
