// Three ways to get d(psi)/dp, in cost and accuracy, in the same run: the diagram's exact
// tangent pass as CVODES' sensitivity right-hand side (the default), CVODES' own
// difference-quotient sensitivity right-hand side, and central finite differences of whole
// runs. Accuracy is against a reference run at rtol 1e-11 with the exact tangents.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <string>

#include "engine/analysis/run.hpp"
#include "engine/framework/diagram.hpp"

namespace {

using namespace dydp::engine;

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// Largest relative error over objectives and directions.
double worst_error(const std::vector<std::vector<double>>& g, const RunResult& ref) {
  double e = 0;
  for (size_t o = 0; o < ref.objectives.size(); ++o)
    for (size_t d = 0; d < ref.sensitivity_names.size(); ++d)
      e = std::max(e, std::fabs(g[o][d] - ref.objectives[o].sensitivity[d]) /
                          std::fabs(ref.objectives[o].sensitivity[d]));
  return e;
}

std::vector<std::vector<double>> gradients(const RunResult& r) {
  std::vector<std::vector<double>> g;
  for (const auto& o : r.objectives) g.push_back(o.sensitivity);
  return g;
}

void BM_SensitivityMethods(benchmark::State& state) {
  const std::string scene = std::string(DYDP_SOURCE_DIR) + "/scenarios/msd_sensitivity.yaml";
  const double rtol = std::pow(10.0, -static_cast<double>(state.range(0)));
  Diagram d = load_scene(scene);
  d.solver.rtol = 1e-11;
  d.solver.atol = 1e-13;
  const RunResult ref = run(d);
  d.solver.rtol = rtol;
  d.solver.atol = rtol * 1e-2;
  const int ns = static_cast<int>(d.sensitivities.size());

  double t_exact = 0, t_dq = 0, t_fd = 0, e_exact = 0, e_dq = 0, e_fd = 0;
  for (auto _ : state) {
    auto t0 = std::chrono::steady_clock::now();
    const RunResult exact = run(d);
    t_exact += seconds_since(t0);
    e_exact = worst_error(gradients(exact), ref);

    RunOptions dq;
    dq.difference_quotient_sensitivities = true;
    t0 = std::chrono::steady_clock::now();
    const RunResult quotient = run(d, dq);
    t_dq += seconds_since(t0);
    e_dq = worst_error(gradients(quotient), ref);

    // Central differences, step 1e-4 of each parameter (about the best for rtol 1e-8).
    RunOptions plain;
    plain.sensitivities = false;
    t0 = std::chrono::steady_clock::now();
    std::vector<std::vector<double>> fd(ref.objectives.size(), std::vector<double>(ns));
    benchmark::DoNotOptimize(run(d, plain));
    for (int k = 0; k < ns; ++k) {
      const int index = d.sensitivities[k];
      const double p0 = d.parameters[index].value, h = 1e-4 * std::fabs(p0);
      Diagram moved = load_scene(scene);
      moved.solver = d.solver;
      moved.set_parameter(index, p0 + h);
      const RunResult plus = run(moved, plain);
      moved.set_parameter(index, p0 - h);
      const RunResult minus = run(moved, plain);
      for (size_t o = 0; o < ref.objectives.size(); ++o)
        fd[o][k] = (plus.objectives[o].value - minus.objectives[o].value) / (2 * h);
    }
    t_fd += seconds_since(t0);
    e_fd = worst_error(fd, ref);
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["exact_s"] = t_exact / n;
  state.counters["dq_over_exact"] = t_dq / t_exact;
  state.counters["fd_over_exact"] = t_fd / t_exact;
  state.counters["exact_err"] = e_exact;
  state.counters["dq_err"] = e_dq;
  state.counters["fd_err"] = e_fd;
}

BENCHMARK(BM_SensitivityMethods)->ArgName("minus_log10_rtol")->Arg(6)->Arg(8)->Unit(benchmark::kMillisecond)->MinTime(1.0);

}  // namespace

BENCHMARK_MAIN();
