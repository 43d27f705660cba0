#include "engine/analysis/run.hpp"

#include <stdexcept>

#include "engine/analysis/cvodes_adjoint.hpp"
#include "engine/analysis/cvodes_solver.hpp"
#include "engine/analysis/rk4_solver.hpp"
#include "engine/analysis/rosenbrock_solver.hpp"
#include "engine/analysis/sdirk_solver.hpp"

namespace dydp::engine {

RunResult run(const Diagram& d, const RunOptions& options) {
  // A start from outside (`initial: equilibrium`) must be that of these parameters: a stale one
  // would start a sweep's point from another point's equilibrium, its sensitivities wrong.
  if (!d.start.x.empty() && !d.start_is_current())
    throw std::logic_error("the run's start state was computed for other parameter values or another start time");
  if (d.initial.equilibrium && d.num_states > 0 && d.start.x.empty())
    throw std::logic_error("the scene starts at its equilibrium (initial: equilibrium) but none was computed: "
                           "run it through engine/studies/initial_equilibrium.hpp");
  RunResult r = options.adjoint               ? run_cvodes_adjoint(d, options)
                : d.solver.method == "rk4"      ? run_rk4(d, options)
                : d.solver.method == "sdirk2" ? run_sdirk(d, options)
                : d.solver.method == "rosw"   ? run_rosenbrock(d, options)
                                              : run_cvodes(d, options);
  // The load-time warnings first: what the input says, then what the run found.
  r.stats.warnings.insert(r.stats.warnings.begin(), d.warnings.begin(), d.warnings.end());
  return r;
}

}  // namespace dydp::engine
