// A screening study: N Sobol' points over the ranges the scene declares for P parameters, each
// one run with all P sensitivity directions, plus one run at the nominal point; the runs shared
// among threads and MPI ranks, each recorded in the output folder as it ends (runs/run_NNNNN.json,
// written atomically) so that an interrupted study resumes where it stopped; then the screening
// measures of every objective (engine/studies/screening.hpp).
#pragma once

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "engine/scene/solver_overrides.hpp"
#include "engine/studies/screening.hpp"

namespace dydp::engine {

struct ScreenSpec {
  std::string scene;
  std::vector<std::pair<std::string, std::string>> overrides;  ///< --set
  SolverOverrides solver;
  std::vector<std::string> parameters;  ///< scene parameters or declared directions, with ranges
  int samples = 16;
  std::string out;                      ///< the runs are recorded in out/runs/
  bool resume = false;                  ///< keep the records of out/runs/, run only what is missing
  int threads = 0;                      ///< 0: one per core (one per rank under MPI)
  bool estimate = true;                 ///< each run estimates its own error (a shadow run beside it)
  /// The gradients by the adjoint method (one backward run per point, whatever P); the runs'
  /// error estimates then cover their signals only.
  bool adjoint = false;
  /// Called on rank 0 after each recorded run: runs recorded so far in this invocation, runs
  /// this invocation has to do.
  std::function<void(int done, int todo)> progress;
};

/// One run: index 0 is the nominal point, index k >= 1 Sobol' point k.
struct ScreenRun {
  int index = 0;
  std::vector<double> p;                      ///< the P parameter values
  std::vector<double> psi;                    ///< per objective
  std::vector<std::vector<double>> gradient;  ///< gradient[o][i] = dpsi_o/dp_i
  double cpu_seconds = 0.0;
  long steps = 0;
  /// The run's own error estimate (engine/analysis/error_estimate.hpp), NaN when not estimated.
  double error_signals = std::numeric_limits<double>::quiet_NaN();
  double error_sensitivities = std::numeric_limits<double>::quiet_NaN();
  std::vector<std::string> warnings;  ///< the run's (an estimate above the target)
};

struct ScreenResult {
  std::vector<ScreeningRange> ranges;        ///< per parameter, nominal = the scene's value
  std::vector<std::string> units;            ///< per parameter
  std::vector<std::string> objectives, objective_units;
  ScreenRun nominal;
  std::vector<ScreenRun> samples;            ///< in index order, 1 .. N
  std::vector<ScreeningEstimate> estimates;  ///< per objective
  int recorded_before = 0;                   ///< runs taken from an earlier invocation's records
  bool complete = false;                     ///< false on MPI ranks other than 0
};

/// Runs (or resumes) the study. Throws InputError for a bad spec or records of another study
/// in out/runs with --resume, SolverError when a run fails (its record is not written).
ScreenResult screen(const ScreenSpec& spec);

/// The record file of run `index` under `out`.
std::string screen_record_path(const std::string& out, int index);

}  // namespace dydp::engine
