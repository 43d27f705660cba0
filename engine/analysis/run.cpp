#include "engine/analysis/run.hpp"

#include "engine/analysis/cvodes_solver.hpp"
#include "engine/analysis/rk4_solver.hpp"
#include "engine/analysis/rosenbrock_solver.hpp"
#include "engine/analysis/sdirk_solver.hpp"

namespace dydp::engine {

RunResult run(const Diagram& d, const RunOptions& options) {
  RunResult r = d.solver.method == "rk4"      ? run_rk4(d, options)
                : d.solver.method == "sdirk2" ? run_sdirk(d, options)
                : d.solver.method == "rosw"   ? run_rosenbrock(d, options)
                                              : run_cvodes(d, options);
  // The load-time warnings first: what the input says, then what the run found.
  r.stats.warnings.insert(r.stats.warnings.begin(), d.warnings.begin(), d.warnings.end());
  return r;
}

}  // namespace dydp::engine
