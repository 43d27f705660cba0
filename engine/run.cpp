#include "engine/run.hpp"

#include "engine/cvodes_solver.hpp"
#include "engine/rk4_solver.hpp"
#include "engine/rosenbrock_solver.hpp"
#include "engine/sdirk_solver.hpp"

namespace dydp::engine {

std::string unit_per(const std::string& a, const std::string& b) {
  if (b.empty()) return a;
  const auto wrap = [](const std::string& u) { return u.find(' ') != std::string::npos ? "(" + u + ")" : u; };
  return (a.empty() ? "1" : wrap(a)) + " / " + wrap(b);
}

int RunResult::signal_index(const std::string& name) const {
  for (size_t i = 0; i < signal_names.size(); ++i)
    if (signal_names[i] == name) return static_cast<int>(i);
  return -1;
}

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
