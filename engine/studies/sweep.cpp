#include "engine/studies/sweep.hpp"

#include <nlohmann/json.hpp>

#include "engine/analysis/run.hpp"
#include "engine/framework/errors.hpp"
#include "engine/studies/initial_equilibrium.hpp"
#include "engine/studies/run_sharing.hpp"

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
  for (const auto& obj : run_from_initial(d, o).objectives) psi.push_back(obj.value);
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

  // Each point is one run (plus its finite differences) whose numbers travel as a JSON record:
  // the same text whether it was computed by a thread of this process or by another MPI rank.
  auto run_point = [&](int k) {
    const double p = result.points[k].p;
    // The swept parameter is the one sensitivity direction the sweep needs.
    auto at_point = [&]() {
      Diagram d = load(spec);
      d.set_parameter(index, p);
      d.set_sensitivities({index});
      return d;
    };
    const RunResult r = run_study_point(at_point, spec.estimate);
    nlohmann::json j;
    const ErrorEstimate& e = r.stats.error_estimate;
    if (e.estimated)
      j["error_estimate"] = {{"signals", e.signal_error}, {"sensitivities", e.sensitivity_error},
                             {"worst_signal", e.worst_signal}, {"worst_sensitivity", e.worst_sensitivity},
                             {"how", e.how}, {"cpu_seconds", e.cpu_seconds}};
    j["warnings"] = r.stats.warnings;
    for (const auto& obj : r.objectives) {
      j["psi"].push_back(obj.value);
      j["dpsi"].push_back(obj.sensitivity[0]);
    }
    j["cpu_seconds"] = r.stats.cpu_seconds;
    j["steps"] = r.stats.steps;
    j["fd"] = nlohmann::json::array();
    for (double h : spec.fd_steps) {
      const std::vector<double> plus = objectives_at(spec, index, p + h);
      const std::vector<double> minus = objectives_at(spec, index, p - h);
      std::vector<double> fd;
      for (size_t o = 0; o < plus.size(); ++o) fd.push_back((plus[o] - minus[o]) / (2 * h));
      j["fd"].push_back(fd);
    }
    if (spec.keep_runs)
      j["run"] = {{"signal_names", r.signal_names}, {"sensitivity_names", r.sensitivity_names}, {"t", r.t},
                  {"values", r.values}, {"tangents", r.tangents}};
    return j.dump();
  };
  auto record = [&](int k, const std::string& text) {
    const auto j = nlohmann::json::parse(text);
    SweepPoint& pt = result.points[k];
    pt.psi = j["psi"].get<std::vector<double>>();
    pt.dpsi = j["dpsi"].get<std::vector<double>>();
    pt.fd = j["fd"].get<std::vector<std::vector<double>>>();
    pt.stats.cpu_seconds = j["cpu_seconds"];
    pt.stats.steps = j["steps"];
    if (j.contains("error_estimate")) {
      const auto& e = j["error_estimate"];
      ErrorEstimate& est = pt.stats.error_estimate;
      est.estimated = true;
      est.signal_error = e["signals"];
      est.sensitivity_error = e["sensitivities"];
      est.worst_signal = e["worst_signal"];
      est.worst_sensitivity = e["worst_sensitivity"];
      est.how = e["how"];
      est.cpu_seconds = e["cpu_seconds"];
    }
    pt.stats.warnings = j["warnings"].get<std::vector<std::string>>();
    if (j.contains("run")) {
      const auto& run = j["run"];
      pt.run.signal_names = run["signal_names"].get<std::vector<std::string>>();
      pt.run.sensitivity_names = run["sensitivity_names"].get<std::vector<std::string>>();
      pt.run.t = run["t"].get<std::vector<double>>();
      pt.run.values = run["values"].get<std::vector<double>>();
      pt.run.tangents = run["tangents"].get<std::vector<double>>();
    }
  };
  std::vector<int> todo(spec.points);
  for (int k = 0; k < spec.points; ++k) todo[k] = k;
  share_runs(todo, run_point, record, spec.threads > 0 ? spec.threads : (world_size() > 1 ? 1 : 0));
  result.complete = world_rank() == 0;
  return result;
}

}  // namespace dydp::engine
