// Error against run time: a converged reference run, then a ladder of methods and settings,
// each with its CPU time, work counts and errors in signals, objectives and sensitivities.
#pragma once

#include <string>
#include <vector>

#include "engine/analysis/run_result.hpp"

namespace dydp::engine {

struct AccuracyRow {
  std::string method;         ///< "bdf", ...; "bdf (given)" for the diagram's own setting
  double setting = 0.0;       ///< rtol (CVODES) or step [s] (fixed-step)
  bool ok = false;
  std::string failure;        ///< why the run stopped, when !ok
  RunStats stats;
  double signal_error = 0.0;       ///< max over grid and signals of |y - y_ref| / max|y_ref|
  double objective_error = 0.0;    ///< max over objectives of |psi - psi_ref| / |psi_ref|
  double sensitivity_error = 0.0;  ///< max over objectives and directions, relative
  double signal_sensitivity_error = 0.0;  ///< max over grid, signals, directions, relative to scale
};

struct AccuracyReport {
  double reference_rtol = 0.0;
  double reference_check = 0.0;  ///< change of the reference when tightened 10x (same measures)
  RunStats reference_stats;
  std::vector<AccuracyRow> rows;
};

struct AccuracySpec {
  std::vector<std::string> methods = {"bdf", "adams", "rk4", "sdirk2"};
  std::vector<double> rtols = {1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9};
  std::vector<double> step_fractions = {1.0, 0.5, 0.2, 0.1, 0.05, 0.02};  ///< of output_step
  double reference_rtol = 1e-11;
  /// Also measure the diagram's own solver setting (a row marked `given`), after the ladder.
  bool given_setting = false;
};

/// Runs the study on a loaded diagram; its solver settings are changed run by run and restored.
AccuracyReport accuracy_study(Diagram& d, const AccuracySpec& spec,
                              const std::function<void(const AccuracyRow&)>& progress = {});

/// The cheapest successful row whose errors (signals, objectives, sensitivities) are all at
/// most `target`; null if none.
const AccuracyRow* cheapest_for(const AccuracyReport& r, double target);

}  // namespace dydp::engine
