// Generated dynamics against Orocos KDL on serial chains (chain9: 9 joints, one prismatic, offset
// and inclined bodies; chain200: 200 revolutes). The KDL chain is built from the same model file
// (kdl_chain.hpp; tests/symbolic/mbs/kdl_test.cpp checks that both agree). Three comparisons:
//   inverse dynamics: the generated residual (M qdd + c, lam = 0, no inputs) vs ChainIdSolver_RNE;
//   mass matrix:      the generated inertial tangent seeded with the n identity columns
//                     (generated_mass_matrix below) vs ChainDynParam::JntToMass;
//   forward dynamics: ReducedDynamics::solve (residual, M by the tangent, Cholesky) vs
//                     ChainFdSolver_RNE (JntToMass, RNE at qdd = 0, KDL's LDL^T), and also vs
//                     KDL's same M and bias solved by Eigen's LLT instead of KDL's LDL^T
//                     (ldl_solver_eigen, plain loops), to tell the dynamics from the solve.
// One benchmark per comparison and model (so that each gets the whole sampling time: the inverse
// dynamics of chain200 is ~1/50 of its forward dynamics). Each iteration times the generated side
// and KDL back to back over the same kStates random states, accumulating the time of each, so the
// ratio counters (kdl_over_generated, kdl_llt_over_generated) come from the same machine load.
// The work arrays are allocated once, outside the timed loops, except inside
// ReducedDynamics::solve, which allocates its own temporaries (its API allows nothing else): on
// chain200 these are n x n matrices above glibc's mmap threshold, over 100 page faults a call
// (compare GLIBC_TUNABLES=glibc.malloc.mmap_threshold=33554432:glibc.malloc.trim_threshold=1073741824).
#include <benchmark/benchmark.h>

#include <chrono>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <algorithm>
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

// The generated mass matrix M(q): its composite-inertia entries where the model has them
// (chain9), otherwise column j is the inertial pass's tangent along qdd = e_j (n directions;
// chain200, too deep a tree for the entries' code).
struct MassWork {
  explicit MassWork(int n) : seeds(Matrix::Identity(n, n)), out(std::max(n, 1)), M(Matrix::Zero(n, n)) {}
  Matrix seeds;
  std::vector<double> out;
  Matrix M;
};
void generated_mass_matrix(const GeneratedModel& g, const double* q, const double* qd, const double* qdd,
                           const double* lam, const double* inp, const double* p, MassWork& w) {
  if (!g.mass_matrix) {
    g.mass(q, qd, qdd, lam, inp, p, g.n, w.seeds.data(), w.out.data(), w.M.data());
    return;
  }
  w.out.resize(std::max(1, g.mass_entries));
  g.mass_matrix(q, qd, qdd, lam, inp, p, w.out.data());
  for (int e = 0; e < g.mass_entries; ++e) w.M(g.mass_rows[e], g.mass_cols[e]) = w.M(g.mass_cols[e], g.mass_rows[e]) = w.out[e];
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

// A model's two sides, its random states and the work arrays, built once per model.
struct Setup {
  explicit Setup(const std::string& name)
      : g(*dydp::generated::find_model(name)),
        n(g.n),
        kdl(dydp::mbs::load_model(std::string(DYDP_MODELS_DIR) + "/" + name + ".mbs.yaml")),
        reduced(g),
        lam(Vector::Zero(1)),
        inp(Vector::Zero(1)),
        p(g.parameters ? Vector(Eigen::Map<const Vector>(g.parameter_values, g.parameters)) : Vector::Zero(1)),
        residual(n),
        mass(n),
        no_torques(n),
        llt(n) {
    KDL::SetToZero(no_torques);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    states.resize(kStates);
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
  }
  // Empty when both sides compute the same thing at the first state (tests/symbolic/mbs/kdl_test.cpp
  // checks it more closely).
  std::string check() {
    if (g.m != 0 || g.inputs != 0 || reduced.nu() != n) return "not an unconstrained chain without inputs";
    State& s = states[0];
    generated_inverse(s);
    generated_mass_matrix(g, s.q.data(), s.qd.data(), s.qdd.data(), lam.data(), inp.data(), p.data(), mass);
    reduced.solve(s.u.data(), s.ud.data(), inp.data(), nullptr, s.q, result);
    // kdl.torques first: kdl_forward_llt overwrites them.
    if (kdl.inverse(s.kq, s.kqd, s.kqdd)) return "KDL's inverse dynamics failed";
    if (max_relative(kdl.torques.data, residual) > 1e-10) return "inverse dynamics: KDL and the generated residual disagree";
    if (kdl.mass(s.kq) || kdl.forward(s.kq, s.kqd, no_torques) || kdl_forward_llt(kdl, s.kq, s.kqd, llt))
      return "a KDL solver failed";
    if (max_relative(kdl.H.data, mass.M) > 1e-10) return "mass matrix: KDL and the generated one disagree";
    if (max_relative(kdl.qdd.data, result.qdd) > 1e-7 || max_relative(llt.qdd, result.qdd) > 1e-7)
      return "forward dynamics: KDL and ReducedDynamics::solve disagree";
    return {};
  }
  void generated_inverse(const State& s) {
    g.residual(s.q.data(), s.qd.data(), s.qdd.data(), lam.data(), inp.data(), p.data(), residual.data());
  }

  const GeneratedModel& g;
  const int n;
  dydp::bench::KdlDynamics kdl;
  ReducedDynamics reduced;
  const Vector lam, inp, p;  // arrays of size zero are passed as one unused element
  std::vector<State> states;
  Vector residual;
  MassWork mass;
  ReducedDynamics::Result result;
  KDL::JntArray no_torques;
  KdlLlt llt;
};

Setup& setup(const std::string& name) {
  static std::map<std::string, std::unique_ptr<Setup>> cache;
  std::unique_ptr<Setup>& s = cache[name];
  if (!s) s = std::make_unique<Setup>(name);
  return *s;
}

// Times `f` over every state, adding the seconds to `total`.
template <class F>
void timed(std::vector<State>& states, double& total, F&& f) {
  const auto start = Clock::now();
  for (const State& s : states) {
    f(s);
    benchmark::ClobberMemory();
  }
  total += seconds_since(start);
}

void report(benchmark::State& bs, int n, std::int64_t rounds, double t_gen, double t_kdl) {
  const double per = 1e6 / (static_cast<double>(rounds) * kStates);  // microseconds per state
  bs.counters["n"] = n;
  bs.counters["gen_us"] = t_gen * per;
  bs.counters["kdl_us"] = t_kdl * per;
  bs.counters["kdl_over_generated"] = t_kdl / t_gen;
}

enum class Part { Inverse, Mass, Forward };

void compare(benchmark::State& bs, const std::string& name, Part part) {
  Setup& w = setup(name);
  if (const std::string error = w.check(); !error.empty()) {
    bs.SkipWithError(error.c_str());
    return;
  }
  double t_gen = 0, t_kdl = 0, t_llt = 0;
  std::int64_t rounds = 0;
  for (auto _ : bs) {
    switch (part) {
      case Part::Inverse:
        timed(w.states, t_gen, [&](const State& s) {
          w.generated_inverse(s);
          benchmark::DoNotOptimize(w.residual.data());
        });
        timed(w.states, t_kdl, [&](const State& s) {
          w.kdl.inverse(s.kq, s.kqd, s.kqdd);
          benchmark::DoNotOptimize(w.kdl.torques.data.data());
        });
        break;
      case Part::Mass:
        timed(w.states, t_gen, [&](const State& s) {
          generated_mass_matrix(w.g, s.q.data(), s.qd.data(), s.qdd.data(), w.lam.data(), w.inp.data(), w.p.data(),
                                w.mass);
          benchmark::DoNotOptimize(w.mass.M.data());
        });
        timed(w.states, t_kdl, [&](const State& s) {
          w.kdl.mass(s.kq);
          benchmark::DoNotOptimize(w.kdl.H.data.data());
        });
        break;
      case Part::Forward:
        timed(w.states, t_gen, [&](const State& s) {
          w.reduced.solve(s.u.data(), s.ud.data(), w.inp.data(), nullptr, s.q, w.result);
          benchmark::DoNotOptimize(w.result.qdd.data());
        });
        timed(w.states, t_kdl, [&](const State& s) {
          w.kdl.forward(s.kq, s.kqd, w.no_torques);
          benchmark::DoNotOptimize(w.kdl.qdd.data.data());
        });
        timed(w.states, t_llt, [&](const State& s) {
          kdl_forward_llt(w.kdl, s.kq, s.kqd, w.llt);
          benchmark::DoNotOptimize(w.llt.qdd.data());
        });
        break;
    }
    ++rounds;
  }
  report(bs, w.n, rounds, t_gen, t_kdl);
  if (part == Part::Forward) {
    bs.counters["kdl_llt_us"] = t_llt * 1e6 / (static_cast<double>(rounds) * kStates);
    bs.counters["kdl_llt_over_generated"] = t_llt / t_gen;
  }
}

BENCHMARK_CAPTURE(compare, chain9_inverse, std::string("chain9"), Part::Inverse)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(compare, chain9_mass, std::string("chain9"), Part::Mass)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(compare, chain9_forward, std::string("chain9"), Part::Forward)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(compare, chain200_inverse, std::string("chain200"), Part::Inverse)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(compare, chain200_mass, std::string("chain200"), Part::Mass)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(compare, chain200_forward, std::string("chain200"), Part::Forward)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
