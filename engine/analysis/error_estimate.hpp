// Every run's estimate of its own global error, from a shadow run: the same scene integrated
// once more, beside the run in a second thread, with the integrator's accuracy loosened by a
// known factor, and the difference of the two scaled back to the run's own error.
// - Error-controlled integrators (BDF, Adams, rosw without a fixed step): the shadow at 4 x
//   rtol and atol. Their global error grows about as the tolerance (for rosw: the step control
//   on its embedded first-order estimate keeps h^2 ~ tol, and its error is of order h^2), so
//   the difference is about 3 x the run's error.
// - Fixed steps of a scheme of order p (rk4 4, sdirk2 2, rosw 2): the shadow at half the step;
//   the difference is about (2^p - 1) / 2^p of the run's error (Richardson). The shadow costs
//   twice the run, in its own thread.
// The error is that of docs/accuracy.md: the worst over the output grid of |error| over the
// column's largest magnitude, over the logged signals and, apart, their sensitivity columns;
// a column that stays within 1e-12 of zero in the run is left out (nothing to be relative to).
#pragma once

#include <string>

#include "engine/analysis/run_result.hpp"

namespace dydp::engine {

struct ShadowPlan {
  SolverSpec solver;     ///< the shadow's settings
  double divisor = 1.0;  ///< the shadow's difference over the run's error
  std::string how;       ///< for run.json
};

/// The shadow's settings for a run with these (its time spec for the default fixed step).
ShadowPlan shadow_plan(const SolverSpec& solver, const TimeSpec& time);

/// Fills run.stats.error_estimate from the two runs on the same output grid.
void estimate_from_shadow(RunResult& run, const RunResult& shadow, const ShadowPlan& plan);

/// Runs d and the shadow diagram (the same scene, loaded again: a diagram's blocks are not
/// shared between threads) side by side, and returns d's result with its error estimate. The
/// shadow's settings are set here (shadow_plan of d's). A shadow that fails leaves the estimate
/// out and says so in the warnings.
RunResult run_with_error_estimate(const Diagram& d, Diagram& shadow, const RunOptions& options);

/// The stated accuracy of a run's defaults: 1 % in every logged signal, 5 % in every
/// sensitivity column. A run whose estimate exceeds it says so (warnings, stderr).
inline constexpr double kSignalTarget = 0.01;
inline constexpr double kSensitivityTarget = 0.05;

}  // namespace dydp::engine
