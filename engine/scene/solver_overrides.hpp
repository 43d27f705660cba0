// Command-line replacements for a scene's solver section (--solver, --rtol, --atol, --step,
// --max-order),
// checked by the rules the scene's own values obey, so a user changes the integrator without
// editing the scene.
#pragma once

#include <optional>
#include <string>

#include "engine/framework/diagram.hpp"

namespace dydp::engine {

struct SolverOverrides {
  std::string method;            ///< empty: the scene's
  std::optional<double> rtol, atol, step;
  std::optional<int> max_order;

  bool empty() const { return method.empty() && !rtol && !atol && !step && !max_order; }
};

/// Replaces the given fields of d.solver. Throws InputError naming the option ("--rtol") on a
/// value the scene would refuse (unknown method, tolerance not in (0, 1), step not positive or
/// giving too many steps, an order the method does not have).
void apply_solver_overrides(Diagram& d, const SolverOverrides& o);

}  // namespace dydp::engine
