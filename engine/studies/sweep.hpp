// Parameter sweeps: psi and d(psi)/dp at each point of a range of one scene parameter, runs
// spread over the machine's cores (and over MPI ranks under mpirun, engine/studies/run_sharing.hpp); optionally central finite differences at given steps, to
// show their error against the exact derivative.
#pragma once

#include <string>
#include <vector>

#include "engine/analysis/run_result.hpp"
#include "engine/scene/solver_overrides.hpp"

namespace dydp::engine {

struct SweepSpec {
  std::string scene;
  std::vector<std::pair<std::string, std::string>> overrides;
  SolverOverrides solver;        ///< --solver, --rtol, --atol, --step
  std::string parameter;
  double low = 0.0, high = 1.0;
  int points = 5;
  std::vector<double> fd_steps;  ///< absolute steps for central differences; empty: none
  int threads = 0;               ///< 0: one per core
  bool keep_runs = false;        ///< keep every run's full result (for reports)
  /// Each point's run estimates its own error (a shadow run beside it,
  /// engine/analysis/error_estimate.hpp); false: no shadow runs.
  bool estimate = true;
};

struct SweepPoint {
  double p = 0.0;
  std::vector<double> psi;            ///< per objective
  std::vector<double> dpsi;           ///< per objective, d(psi)/dp for the swept parameter
  std::vector<std::vector<double>> fd;  ///< fd[s][o]: central difference with step s
  RunStats stats;                     ///< cpu_seconds, steps, error_estimate and warnings only
  RunResult run;                      ///< when keep_runs: names, t, values, tangents
};

struct SweepResult {
  std::string parameter, unit;
  std::vector<std::string> objectives;
  std::vector<std::string> objective_units;  ///< unit of each objective's psi
  std::vector<double> fd_steps;
  std::vector<SweepPoint> points;
  bool complete = true;  ///< false on MPI ranks other than 0 (their points are not filled)
};

/// Runs the sweep; throws InputError for a bad spec, SolverError when a run fails (under MPI:
/// on rank 0).
SweepResult sweep(const SweepSpec& spec);

}  // namespace dydp::engine
