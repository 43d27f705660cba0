// Cost of sensitivities on a chain of N coupled mass-spring-damper blocks: a run with P
// sensitivity directions against the same run without (target: under 1 + 0.5 P), and against
// central finite differences (2P + 1 runs without sensitivities). Ratios come from runs
// timed in the same iteration, so machine load affects both sides alike.
#include <benchmark/benchmark.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "engine/analysis/run.hpp"
#include "engine/framework/diagram.hpp"

namespace {

using namespace dydp::engine;

/// N masses; mass 1 is pulled by a spring from a sine-driven base, mass i by springs to
/// masses i-1 and i+1. Each mass has its own spring to ground and damper (msd block).
std::string chain_scene(int n, int p, bool sens_error_test) {
  static const char* kParams[] = {"stiffness", "damping", "mass", "coupling"};
  std::ostringstream s;
  s << "scene: chain" << n << "\ntime: {start: 0.0, stop: 10.0, output_step: 0.01}\n"
    << "solver: {method: bdf, rtol: 1.0e-6, atol: 1.0e-8, sens_error_test: "
    << (sens_error_test ? "true" : "false") << "}\nparameters:\n"
    << "  stiffness: {value: 400.0}\n  damping: {value: 2.0}\n  mass: {value: 1.0}\n"
    << "  coupling: {value: 900.0}\nsensitivities: [";
  for (int k = 0; k < p; ++k) s << (k ? ", " : "") << kParams[k];
  s << "]\nblocks:\n  base: {type: source.sine, amplitude: 0.01, frequency: 1.5}\n";
  for (int i = 1; i <= n; ++i) {
    s << "  m" << i << ": {type: mass_spring_damper, m: $mass, k: $stiffness, c: $damping}\n"
      << "  stretch" << i << ": {type: math.sum, signs: +-}\n"
      << "  spring" << i << ": {type: math.gain, k: $coupling}\n"
      << "  force" << i << ": {type: math.sum, signs: " << (i < n ? "+-" : "+") << "}\n";
  }
  s << "  x_rms: {type: objective.rms}\nconnections:\n";
  for (int i = 1; i <= n; ++i) {
    s << "  - " << (i == 1 ? "base.y" : "m" + std::to_string(i - 1) + ".x") << " -> stretch" << i << ".in1\n"
      << "  - m" << i << ".x -> stretch" << i << ".in2\n"
      << "  - stretch" << i << ".y -> spring" << i << ".u\n"
      << "  - spring" << i << ".y -> force" << i << ".in1\n";
    if (i < n) s << "  - spring" << i + 1 << ".y -> force" << i << ".in2\n";
    s << "  - force" << i << ".y -> m" << i << ".f\n";
  }
  s << "  - m" << n << ".x -> x_rms.in\noutputs: [m" << n << ".x, x_rms]\n";
  return s.str();
}

Diagram load_chain(int n, int p, bool sens_error_test) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("dydp_chain_" + std::to_string(n) + "_" + std::to_string(p) + "_" +
                     std::to_string(sens_error_test) + ".yaml");
  std::ofstream(path) << chain_scene(n, p, sens_error_test);
  return load_scene(path.string());
}

double seconds_of(const Diagram& d, bool sensitivities) {
  RunOptions o;
  o.sensitivities = sensitivities;
  const auto t0 = std::chrono::steady_clock::now();
  benchmark::DoNotOptimize(run(d, o));
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

void BM_ChainSensitivityCost(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0)), p = static_cast<int>(state.range(1));
  const Diagram d = load_chain(n, p, state.range(2) != 0);
  double plain = 0, sens = 0;
  for (auto _ : state) {
    plain += seconds_of(d, false);
    sens += seconds_of(d, true);
  }
  state.counters["plain_s"] = plain / state.iterations();
  state.counters["sens_s"] = sens / state.iterations();
  state.counters["sens_over_plain"] = sens / plain;
  state.counters["target"] = 1.0 + 0.5 * p;
  state.counters["fd_over_sens"] = (2 * p + 1) * plain / sens;
}

BENCHMARK(BM_ChainSensitivityCost)
    ->ArgNames({"N", "P", "sens_error_test"})
    ->ArgsProduct({{10, 100}, {1, 2, 4}, {1, 0}})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);

}  // namespace

BENCHMARK_MAIN();
