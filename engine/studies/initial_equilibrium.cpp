#include "engine/studies/initial_equilibrium.hpp"

#include <algorithm>

#include "engine/analysis/error_estimate.hpp"
#include "engine/framework/errors.hpp"

namespace dydp::engine {

std::optional<Equilibrium> start_at_equilibrium(Diagram& d) {
  // A diagram without states starts where it is.
  if (!d.initial.equilibrium || d.num_states == 0 || d.start_is_current()) return std::nullopt;
  return start_at_equilibrium(d, d.time.start, {});
}

std::optional<Equilibrium> start_at_equilibrium(Diagram& d, double t, const std::vector<std::pair<int, double>>& held) {
  if (!d.initial.equilibrium || d.num_states == 0) return std::nullopt;
  d.start = StartState{};  // Newton starts from the blocks' own initial states
  EquilibriumOptions o;
  o.time = t;
  o.held = d.initial.held;
  for (const auto& h : held) {
    const auto same = [&](const std::pair<int, double>& g) { return g.first == h.first; };
    if (const auto it = std::find_if(o.held.begin(), o.held.end(), same); it != o.held.end()) it->second = h.second;
    else o.held.push_back(h);
  }
  Equilibrium eq;
  try {
    eq = find_equilibrium(d, o);
  } catch (const SolverError& e) {
    throw InputError(d.file, d.initial.line, "initial", std::string("equilibrium: ") + e.what());
  }
  StartState s;
  s.x = eq.x;
  s.parameters = eq.parameters;
  s.dx_dp.assign(eq.dx_dp.data(), eq.dx_dp.data() + eq.dx_dp.size());  // column-major: column c at c * n
  s.t = t;
  s.block_parameters = d.block_parameter_values();
  d.start = std::move(s);
  return eq;
}

RunResult run_from_initial(Diagram& d, const RunOptions& options) {
  start_at_equilibrium(d);
  return run(d, options);
}

RunResult run_study_point(const std::function<Diagram()>& make, bool estimate, bool adjoint) {
  Diagram d = make();
  start_at_equilibrium(d);
  RunOptions options;
  options.adjoint = adjoint;
  if (!estimate) return run(d, options);
  Diagram shadow = make();
  return run_with_error_estimate(d, shadow, options);
}

}  // namespace dydp::engine
