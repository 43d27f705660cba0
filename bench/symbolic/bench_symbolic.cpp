// Benchmarks of the symbolic core: elimination and differentiation throughput on a
// 100k-assignment list and on a 200-body chain, and emitted-code evaluation against the
// interpreter on the same chain list (compiled at build time by generate_chain).
#include <benchmark/benchmark.h>

#include <memory>

#include "bench_chain_generated.hpp"
#include "chain_model.hpp"
#include "random_list.hpp"
#include "symbolic/differentiate.hpp"
#include "symbolic/eliminate.hpp"
#include "symbolic/interpret.hpp"

namespace dydp::symbolic {
namespace {

struct Fixture {
  Context ctx;
  EquationList list{ctx};
};

std::unique_ptr<Fixture> random_fixture(std::size_t n) {
  auto f = std::make_unique<Fixture>();
  testing::make_random_list(f->list, n, 50, 42);
  return f;
}

std::unique_ptr<Fixture> chain_fixture(std::size_t bodies) {
  auto f = std::make_unique<Fixture>();
  bench::build_chain(f->list, bodies);
  return f;
}

void BM_EliminateRandom100k(benchmark::State& state) {
  const auto f = random_fixture(100'000);
  for (auto _ : state) {
    EquationList kept = eliminate(f->list);
    benchmark::DoNotOptimize(kept.size());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(f->list.size()));
  state.counters["assignments"] = static_cast<double>(f->list.size());
}
BENCHMARK(BM_EliminateRandom100k)->Unit(benchmark::kMillisecond);

void BM_DifferentiateRandom100k(benchmark::State& state) {
  const auto f = random_fixture(100'000);
  const EquationList list = eliminate(f->list);
  const Direction dir = along(f->ctx.element(0, 0));
  std::size_t produced = 0;
  for (auto _ : state) {
    EquationList d = differentiate(list, std::span<const Direction>(&dir, 1));
    produced = d.size() - d.primal_assignments();
    benchmark::DoNotOptimize(produced);
  }
  // Items: primal assignments differentiated (the hash-consing pool grows across iterations;
  // repeated runs reuse existing nodes, so the first iteration is the most expensive).
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(list.size()));
  state.counters["assignments"] = static_cast<double>(list.size());
  state.counters["derivative_assignments"] = static_cast<double>(produced);
}
BENCHMARK(BM_DifferentiateRandom100k)->Unit(benchmark::kMillisecond);

void BM_DifferentiateRandom100kFresh(benchmark::State& state) {
  for (auto _ : state) {
    state.PauseTiming();
    auto f = random_fixture(100'000);
    const Direction dir = along(f->ctx.element(0, 0));
    state.ResumeTiming();
    EquationList d = differentiate(f->list, std::span<const Direction>(&dir, 1));
    benchmark::DoNotOptimize(d.size());
    state.PauseTiming();
    f.reset();
    state.ResumeTiming();
  }
  state.SetItemsProcessed(state.iterations() * 100'000);
}
BENCHMARK(BM_DifferentiateRandom100kFresh)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_EliminateChain200(benchmark::State& state) {
  const auto f = chain_fixture(200);
  EliminationStats stats;
  for (auto _ : state) {
    EquationList kept = eliminate(f->list, &stats);
    benchmark::DoNotOptimize(kept.size());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(f->list.size()));
  state.counters["before"] = static_cast<double>(stats.before);
  state.counters["after"] = static_cast<double>(stats.after);
}
BENCHMARK(BM_EliminateChain200)->Unit(benchmark::kMillisecond);

void BM_TangentListChain200(benchmark::State& state) {
  for (auto _ : state) {
    state.PauseTiming();
    auto f = chain_fixture(200);
    const ArrayId seeded[2] = {0, 1};
    state.ResumeTiming();
    EquationList t = tangent_list(f->list, seeded);
    benchmark::DoNotOptimize(t.size());
    state.counters["tangent_assignments"] = static_cast<double>(t.size());
    state.PauseTiming();
    f.reset();
    state.ResumeTiming();
  }
}
BENCHMARK(BM_TangentListChain200)->Unit(benchmark::kMillisecond)->Iterations(3);

// --- emitted code against the interpreter, same list, same inputs ---------------------------

struct ChainInputs {
  std::vector<double> q, qd, qdd, p;
  explicit ChainInputs(std::size_t bodies)
      : q(testing::random_values(bodies, 1)), qd(testing::random_values(bodies, 2)),
        qdd(testing::random_values(bodies, 3)), p(2 * bodies, 1.0) {}
};

void BM_ChainInterpreter(benchmark::State& state) {
  const auto f = chain_fixture(DYDP_BENCH_CHAIN_BODIES);
  const EquationList list = eliminate(f->list);
  const Tape tape(list);
  const ChainInputs in(DYDP_BENCH_CHAIN_BODIES);
  const double* arrays[4] = {in.q.data(), in.qd.data(), in.qdd.data(), in.p.data()};
  std::vector<double> out(tape.output_count());
  for (auto _ : state) {
    tape.evaluate<double>(arrays, out.data());
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["assignments"] = static_cast<double>(list.size());
}
BENCHMARK(BM_ChainInterpreter)->Unit(benchmark::kMicrosecond);

void BM_ChainCompiled(benchmark::State& state) {
  const ChainInputs in(DYDP_BENCH_CHAIN_BODIES);
  std::vector<double> out(DYDP_BENCH_CHAIN_BODIES);
  for (auto _ : state) {
    bench_generated::chain_dynamics(in.q.data(), in.qd.data(), in.qdd.data(), in.p.data(), out.data());
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_ChainCompiled)->Unit(benchmark::kMicrosecond);

void BM_ChainCompiledTangent(benchmark::State& state) {
  const std::size_t n = DYDP_BENCH_CHAIN_BODIES;
  const int nd = static_cast<int>(state.range(0));
  const ChainInputs in(n);
  const std::vector<double> seed_q = testing::random_values(n * nd, 4);
  const std::vector<double> seed_qd = testing::random_values(n * nd, 5);
  std::vector<double> out(n), dout(n * nd);
  for (auto _ : state) {
    bench_generated::chain_tangent(in.q.data(), in.qd.data(), in.qdd.data(), in.p.data(), nd,
                                   seed_q.data(), seed_qd.data(), out.data(), dout.data());
    benchmark::DoNotOptimize(dout.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_ChainCompiledTangent)->Arg(1)->Arg(8)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace dydp::symbolic

BENCHMARK_MAIN();
