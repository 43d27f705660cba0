#include "engine/scene/scene_relations.hpp"

#include <cmath>

#include "engine/framework/errors.hpp"

namespace dydp::engine {
namespace {

/// Line of section[key] when written, else of the section, else 0 (all defaults).
int line_of(const YAML::Node& section, const char* key) {
  if (!section) return 0;
  const YAML::Node v = section[key];
  const YAML::Node& at = v ? v : section;
  return at.Mark().is_null() ? 0 : at.Mark().line + 1;
}

bool written(const YAML::Node& section, const char* key) { return section && section[key]; }

}  // namespace

void check_time_relations(const std::string& file, const YAML::Node& section, const TimeSpec& time) {
  const auto fail = [&](const char* key, const std::string& message) {
    throw InputError(file, line_of(section, key), std::string("time.") + key, message);
  };
  const std::string limit = format_number(kMaxAbsTime);
  if (!(std::fabs(time.start) <= kMaxAbsTime))
    fail("start", "value " + format_number(time.start) + " outside [-" + limit + ", " + limit + "] s");
  if (!(std::fabs(time.stop) <= kMaxAbsTime))
    fail("stop", "value " + format_number(time.stop) + " outside [-" + limit + ", " + limit + "] s");
  const double span = time.stop - time.start;
  if (!(time.output_step <= span))
    fail("output_step", "longer than the run (" + format_number(time.output_step) + " s > stop - start = " +
                            format_number(span) + " s)");
  if (!(span / time.output_step <= kMaxOutputIntervals))
    fail("output_step", "gives " + format_number(span / time.output_step) +
                            " output intervals, more than " + format_number(kMaxOutputIntervals));
}

void check_solver_relations(const std::string& file, const YAML::Node& section,
                            const SolverSpec& solver, const TimeSpec& time) {
  const auto fail = [&](const char* key, const std::string& message) {
    throw InputError(file, line_of(section, key), std::string("solver.") + key, message);
  };
  if (!(solver.rtol < 1)) fail("rtol", "value " + format_number(solver.rtol) + " must be below 1");
  if (!(solver.atol < 1))
    fail("atol", "value " + format_number(solver.atol) +
                     " must be below 1 (states are SI: an error of 1 m or 1 rad controls nothing)");
  const double span = time.stop - time.start;
  if (written(section, "step")) {
    // Absent, the fixed-step methods take output_step / 10; written, the value is used as given
    // (a denormal never gets here: the loader refuses numbers that underflow).
    if (!(solver.step > 0)) fail("step", "must be positive (leave it out for output_step / 10)");
    if (!(span / solver.step <= kMaxFixedSteps))
      fail("step", "gives " + format_number(span / solver.step) + " steps, more than " +
                       format_number(kMaxFixedSteps));
  }
  if (written(section, "max_order")) {
    const int top = highest_order(solver.method);
    if (top == 0)
      fail("max_order", "applies to bdf and adams only (method " + solver.method + " has a fixed scheme)");
    if (!(solver.max_order >= 1 && solver.max_order <= top))
      fail("max_order", "value " + std::to_string(solver.max_order) + " must be a whole number in [1, " +
                            std::to_string(top) + "] for " + solver.method);
  }
  if (!(solver.min_step < time.output_step))
    fail("min_step", "value " + format_number(solver.min_step) + " s must be below time.output_step (" +
                         format_number(time.output_step) + " s)");
}

}  // namespace dydp::engine
