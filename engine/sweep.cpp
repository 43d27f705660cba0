#include "engine/sweep.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>

#include "engine/errors.hpp"

namespace dydp::engine {
namespace {

/// The scene with the spec's parameter and solver overrides.
Diagram load(const SweepSpec& spec) {
  Diagram d = load_scene(spec.scene, spec.overrides);
  apply_solver_overrides(d, spec.solver);
  return d;
}

/// psi of every objective for the scene at parameter value p, without sensitivities.
std::vector<double> objectives_at(const SweepSpec& spec, int index, double p) {
  Diagram d = load(spec);
  d.set_parameter(index, p, /*check_range=*/false);
  RunOptions o;
  o.sensitivities = false;
  std::vector<double> psi;
  for (const auto& obj : run(d, o).objectives) psi.push_back(obj.value);
  return psi;
}

}  // namespace

SweepResult sweep(const SweepSpec& spec) {
  // Validate once, up front, so that a bad spec fails before any thread starts.
  Diagram probe = load(spec);
  const int index = probe.find_parameter(spec.parameter);
  if (index < 0) throw InputError("--param", 0, spec.parameter, "no scene parameter of that name in " + spec.scene);
  if (spec.points < 1) throw InputError("--range", 0, "N", "needs at least one point");
  if (probe.objectives.empty())
    throw InputError(spec.scene, 0, "outputs", "a sweep needs at least one objective among the outputs");
  const SceneParameter& sp = probe.parameters[index];
  for (double p : {spec.low, spec.high})
    if (p < sp.lower || p > sp.upper)
      throw InputError("--range", 0, spec.parameter, "value " + format_number(p) + " outside the parameter's range");

  SweepResult result;
  result.parameter = spec.parameter;
  result.unit = sp.unit;
  result.fd_steps = spec.fd_steps;
  for (int o : probe.objectives) {
    result.objectives.push_back(probe.nodes[o].name);
    result.objective_units.push_back(probe.objective_unit(probe.nodes[o]));
  }
  result.points.resize(spec.points);
  for (int k = 0; k < spec.points; ++k)
    result.points[k].p = spec.points == 1 ? spec.low
                                          : spec.low + (spec.high - spec.low) * k / (spec.points - 1);

  std::atomic<int> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto worker = [&] {
    for (int k = next++; k < spec.points; k = next++) {
      try {
        SweepPoint& pt = result.points[k];
        Diagram d = load(spec);
        d.set_parameter(index, pt.p);
        // The swept parameter is the one sensitivity direction the sweep needs.
        d.set_sensitivities({index});
        RunResult r = run(d);
        for (const auto& obj : r.objectives) {
          pt.psi.push_back(obj.value);
          pt.dpsi.push_back(obj.sensitivity[0]);
        }
        pt.stats = r.stats;
        for (double h : spec.fd_steps) {
          const std::vector<double> plus = objectives_at(spec, index, pt.p + h);
          const std::vector<double> minus = objectives_at(spec, index, pt.p - h);
          std::vector<double> fd;
          for (size_t o = 0; o < plus.size(); ++o) fd.push_back((plus[o] - minus[o]) / (2 * h));
          pt.fd.push_back(fd);
        }
        if (spec.keep_runs) pt.run = std::move(r);
      } catch (...) {
        std::lock_guard<std::mutex> lock(failure_mutex);
        if (!failure) failure = std::current_exception();
        next = spec.points;
      }
    }
  };
  const int threads = std::max(1, std::min(spec.points, spec.threads > 0 ? spec.threads
                                                  : static_cast<int>(std::thread::hardware_concurrency())));
  std::vector<std::thread> pool;
  for (int i = 0; i < threads; ++i) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
  return result;
}

}  // namespace dydp::engine
