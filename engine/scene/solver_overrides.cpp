#include "engine/scene/solver_overrides.hpp"

#include <cmath>

#include "engine/framework/errors.hpp"
#include "engine/scene/scene_relations.hpp"

namespace dydp::engine {

void apply_solver_overrides(Diagram& d, const SolverOverrides& o) {
  const auto fail = [](const char* option, const std::string& message) {
    throw InputError(option, 0, "", message);
  };
  if (!o.method.empty()) {
    if (o.method != "bdf" && o.method != "adams" && o.method != "rk4" && o.method != "sdirk2" &&
        o.method != "rosw")
      fail("--solver", "unknown method '" + o.method + "' (bdf, adams, rk4, sdirk2, rosw)");
    d.solver.method = o.method;
  }
  if (o.rtol) {
    if (!(*o.rtol > 0 && *o.rtol < 1)) fail("--rtol", "value " + format_number(*o.rtol) + " must be in (0, 1)");
    d.solver.rtol = *o.rtol;
  }
  if (o.atol) {
    if (!(*o.atol > 0 && *o.atol < 1))
      fail("--atol", "value " + format_number(*o.atol) +
                         " must be in (0, 1) (it multiplies each state's nominal magnitude)");
    d.solver.atol = *o.atol;
  }
  if (o.step) {
    const double span = d.time.stop - d.time.start;
    if (!(*o.step > 0)) fail("--step", "value " + format_number(*o.step) + " must be positive");
    if (!(span / *o.step <= kMaxFixedSteps))
      fail("--step", "gives " + format_number(span / *o.step) + " steps, more than " +
                         format_number(kMaxFixedSteps));
    d.solver.step = *o.step;
  }
  if (o.max_order) {
    const int top = highest_order(d.solver.method);
    if (top == 0) fail("--max-order", "applies to bdf and adams only (method " + d.solver.method + ")");
    if (!(*o.max_order >= 1 && *o.max_order <= top))
      fail("--max-order", "value " + std::to_string(*o.max_order) + " must be in [1, " + std::to_string(top) +
                              "] for " + d.solver.method);
    d.solver.max_order = *o.max_order;
  } else if (const int top = highest_order(d.solver.method); top > 0 && d.solver.max_order > top) {
    fail("--solver", "the scene's solver.max_order " + std::to_string(d.solver.max_order) + " is beyond " +
                         d.solver.method + "'s highest order " + std::to_string(top) + ": add --max-order");
  }
}

}  // namespace dydp::engine
