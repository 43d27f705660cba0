// What a run takes and gives: its options, the recorded results (signals and their
// sensitivities on the output grid, objectives with d(psi)/dp) and the statistics that go to
// run.json. Every integrator fills these; engine/analysis/run.hpp picks the integrator.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "engine/framework/diagram.hpp"

namespace dydp::engine {

struct RunResult;

struct RunOptions {
  bool sensitivities = true;                  ///< false: --no-sens, no tangent work at all
  /// CVODES only: true replaces the diagram's tangent pass by CVODES' own difference-quotient
  /// sensitivity right-hand side (for comparison; the default is the exact tangent pass).
  bool difference_quotient_sensitivities = false;
  std::function<void(double t)> progress;     ///< called at every output time
  /// Called at every output time with the result so far (its last sample is the new one):
  /// for streaming outputs. An exception thrown here ends the run.
  std::function<void(const RunResult&)> on_sample;
  /// The objectives' gradients by the adjoint method (engine/analysis/cvodes_adjoint.hpp): a
  /// forward run with checkpoints, then one backward run for every objective together; the
  /// signals carry no sensitivities. CVODES methods only.
  bool adjoint = false;
  /// Adjoint: forward steps between checkpoints (the chunks replayed one at a time backwards).
  int steps_between_checkpoints = 1000;
};

/// A state that limited the step size (see engine/analysis/step_limiters.hpp).
struct LimitingState {
  std::string state;   ///< block.state
  long steps = 0;      ///< accepted steps at which its weighted local error was the largest
  double share = 0.0;  ///< steps / all counted steps
};

/// The run's own estimate of its global error (engine/analysis/error_estimate.hpp): the worst
/// over the output grid of |error| over each column's largest magnitude, over the logged
/// signals and, apart, over their sensitivity columns.
struct ErrorEstimate {
  bool estimated = false;
  double signal_error = 0.0;       ///< over the logged signals (Qt's macro takes "signals")
  double sensitivity_error = 0.0;  ///< over their sensitivity columns
  std::string how;           ///< what it was estimated from ("shadow at 4 x rtol, atol")
  double cpu_seconds = 0.0;  ///< the shadow run's CPU time (its own thread), not in cpu_seconds
  std::string worst_signal;       ///< the column of the largest signal error
  std::string worst_sensitivity;  ///< the column of the largest sensitivity error
};

/// What the adjoint run did (run.json `adjoint`).
struct AdjointStats {
  bool used = false;
  int objectives = 0;                ///< adjoint directions: the requested objectives
  int segments = 0;                  ///< integration segments (between breakpoints)
  long checkpoints = 0;              ///< forward checkpoints (chunks), all segments
  int steps_between_checkpoints = 0; ///< the chunks' length, in forward steps
  long replay_steps = 0;             ///< forward steps taken again, chunk by chunk, for the backward run
  long replays_differing = 0;        ///< replayed chunks whose steps differ from the first pass's (0)
  long backward_steps = 0;
  long backward_rhs_evals = 0;       ///< adjoint passes for the adjoint states
  long backward_quadrature_evals = 0;  ///< adjoint passes for the parameter gradient
  long backward_jac_evals = 0;       ///< backward Newton matrices (the transposed diagram Jacobian)
  long forward_steps = 0;            ///< of the forward run alone
  /// Checkpoint and interpolation data held: a state per checkpoint, and y and y' per stored
  /// step of the chunk being replayed (Hermite).
  double checkpoint_bytes = 0.0;
  double peak_rss_bytes = 0.0;       ///< the process's peak resident set when the run ended
  double forward_cpu_seconds = 0.0;
  double backward_cpu_seconds = 0.0;
};

struct RunStats {
  std::string method;
  double rtol = 0.0, atol = 0.0, step = 0.0;
  long steps = 0;
  long rhs_evals = 0;             ///< value passes for state derivatives
  long sens_rhs_evals = 0;        ///< tangent passes for the sensitivity equations
  long jac_evals = 0;             ///< Jacobians (each one tangent pass over jacobian_colours directions)
  /// Directions of a Jacobian's tangent pass: the colours of its columns (columns whose rows do
  /// not meet share one, engine/evaluation/jacobian_colouring.hpp), the states when none can share.
  int jacobian_colours = 0;
  long local_jac_evals = 0;       ///< refreshes of the blocks' own diagonal Jacobian blocks only
  long error_test_failures = 0;
  long nonlinear_iterations = 0;
  long nonlinear_failures = 0;    ///< corrector convergence failures (step retried smaller)
  long substeps = 0;              ///< fixed-step schemes: steps taken as two halves (their Newton
                                  ///< iteration failed at the full step)
  double cpu_seconds = 0.0;
  double simulated_seconds = 0.0;
  double realtime_factor = 0.0;   ///< simulated seconds per CPU second
  std::vector<std::string> warnings;
  /// BDF and Adams: the highest order allowed (solver.max_order, else the method's own limit);
  /// steps_per_order[k - 1] counts the accepted steps taken at order k.
  int max_order = 0;
  std::vector<long> steps_per_order;
  /// Variable-step solvers: the states that limited the step most often, most often first.
  std::vector<LimitingState> limiting_states;
  ErrorEstimate error_estimate;
  AdjointStats adjoint;
};

struct ObjectiveResult {
  std::string name;
  std::string unit;                 ///< of value (sensitivities: unit per unit of the parameter)
  double value = 0.0;
  std::vector<double> sensitivity;  ///< one per sensitivity direction
};

/// "a / b" for the unit of a derivative da/db ("" when both are unknown).
std::string unit_per(const std::string& a, const std::string& b);

struct RunResult {
  std::vector<std::string> signal_names;       ///< logged scalars
  std::vector<std::string> sensitivity_names;  ///< the directions (empty without sensitivities)
  std::vector<double> t;                       ///< output grid
  std::vector<double> values;                  ///< values[k * nsig + i]
  std::vector<double> tangents;                ///< tangents[(k * ns + d) * nsig + i]
  /// Whether the signals carry their sensitivities (tangents): false for an adjoint run, whose
  /// sensitivity_names are those of the objectives' gradients only.
  bool signal_sensitivities = true;
  std::vector<double> final_state;
  std::vector<ObjectiveResult> objectives;
  RunStats stats;

  int num_signals() const { return static_cast<int>(signal_names.size()); }
  double value(int k, int i) const { return values[k * num_signals() + i]; }
  double tangent(int k, int d, int i) const {
    return tangents[(k * static_cast<int>(sensitivity_names.size()) + d) * num_signals() + i];
  }
  int signal_index(const std::string& name) const;
};

}  // namespace dydp::engine
