#include "engine/analysis/tolerances.hpp"

#include <cmath>

namespace dydp::engine {

std::vector<double> state_nominals(const Diagram& d) {
  std::vector<double> out(d.num_states, 1.0);
  for (const Node& n : d.nodes) {
    // A node read from a scene carries its own (overridden) values; others the block's.
    const std::vector<double>& own = n.state_nominal.empty() ? n.block->state_nominals() : n.state_nominal;
    for (int i = 0; i < n.block->num_states(); ++i) out[n.state_offset + i] = own[i];
  }
  return out;
}

std::string state_label(const Diagram& d, int i) {
  for (const Node& n : d.nodes)
    if (i >= n.state_offset && i < n.state_offset + n.block->num_states())
      return n.name + "." + n.block->state_names()[i - n.state_offset];
  // past the states: the objective integrals, which CVODES integrates with them ([x; q])
  const int k = i - d.num_states;
  for (const Node& n : d.nodes)
    if (k >= n.quad_offset && k < n.quad_offset + n.block->num_quadratures())
      return n.name + ".integral" + (n.block->num_quadratures() > 1 ? std::to_string(k - n.quad_offset) : "");
  return "state " + std::to_string(i);
}

AbsoluteTolerances absolute_tolerances(const Diagram& d, double atol, int directions) {
  AbsoluteTolerances t;
  const std::vector<double> nominal =
      d.solver.nominal_scaling ? state_nominals(d) : std::vector<double>(d.num_states, 1.0);
  for (double v : nominal) t.states.push_back(atol * v);
  t.quadratures.assign(d.num_quadratures, atol);
  if (d.solver.nominal_scaling)
    for (const Node& n : d.nodes)
      for (int i = 0; i < n.block->num_quadratures(); ++i)
        t.quadratures[n.quad_offset + i] = atol * n.block->quadrature_nominals()[i];
  for (int dir = 0; dir < directions; ++dir) {
    // dx/dp is held to atol * nominal / |p|: a stiffness of 1e5 N/m and a mass of 400 kg have
    // their sensitivities held to the same relative accuracy (p = 0: unit scale).
    const double pv = std::fabs(d.parameters[d.sensitivities[dir]].value);
    const double scale = pv > 0 ? 1.0 / pv : 1.0;
    for (double v : t.states) t.sensitivities.push_back(v * scale);
    for (double v : t.quadratures) t.quadrature_sensitivities.push_back(v * scale);
  }
  return t;
}

}  // namespace dydp::engine
