// The dydp subcommands, each a function of its parsed arguments returning the exit status.
#pragma once

#include <cmath>
#include <ostream>
#include <string>
#include <vector>

#include "engine/analysis/run_result.hpp"
#include "engine/scene/solver_overrides.hpp"

namespace dydp::apps {

struct RunArgs {
  std::string scene;
  engine::SolverOverrides solver;  ///< --solver, --rtol, --atol, --step
  std::string out = "out";
  std::vector<std::string> sets;  ///< NAME=VALUE
  bool no_sens = false;
  bool no_estimate = false;  ///< --no-estimate: no shadow run, no error estimate
  bool report = false;
  std::string format = "csv";     ///< csv | mat (also run.mat)
  /// --adjoint: the objectives' gradients for every declared parameter and direction by the
  /// adjoint method; the signals without sensitivities.
  bool adjoint = false;
};

struct SweepArgs {
  std::string scene;
  engine::SolverOverrides solver;  ///< --solver, --rtol, --atol, --step
  std::string out = "out";
  std::vector<std::string> sets;
  std::string parameter;
  std::string range;              ///< LO:HI:N
  std::vector<double> fd_steps;   ///< --fd: absolute steps for central differences
  double delta = 0.0;             ///< --delta: report the change of psi for this step of p
  bool no_estimate = false;       ///< --no-estimate: no shadow runs (no error estimates)
  bool report = false;
  std::string format = "csv";     ///< csv | mat (also sweep.mat)
};

struct AccuracyArgs {
  std::string scene;
  engine::SolverOverrides solver;  ///< --solver, --rtol, --atol, --step
  std::string out = "out";
  std::vector<std::string> sets;
  double target = 1e-4;  ///< requested relative accuracy for the "cheapest setting" line
  std::vector<std::string> methods = {"bdf", "adams", "rk4", "sdirk2"};
  bool methods_given = false;  ///< --methods written (with solver overrides: no ladder unless)
};

struct ReplayArgs {
  std::string scene;
  engine::SolverOverrides solver;  ///< --solver, --rtol, --atol, --step
  std::string input;              ///< recorded CSV: t, one column per pad, measured responses
  std::string out = "out";
  std::vector<std::string> sets;
  bool realtime = false;          ///< pace to the wall clock
  bool no_sens = false;
  bool no_estimate = false;  ///< --no-estimate: no shadow run, no error estimate
  std::string format = "csv";     ///< csv | mat (also replay.mat) | rpc (also signals.rsp)
};

struct ScreenArgs {
  std::string scene;
  engine::SolverOverrides solver;  ///< --solver, --rtol, --atol, --step
  std::string out = "out";
  std::vector<std::string> sets;
  std::vector<std::string> parameters;  ///< --params: scene parameters or declared directions
  int samples = 16;
  bool report = false;
  bool resume = false;
  int threads = 0;                ///< --threads: 0 one per core (one per rank under MPI)
  bool no_estimate = false;       ///< --no-estimate: no shadow runs
  bool adjoint = false;           ///< --adjoint: the gradients by the adjoint method
};

/// equilibrium, linearize, modes, frf: the analyses about one operating point.
struct LinearArgs {
  std::string scene;
  std::string out = "out";
  std::vector<std::string> sets;
  double time = std::nan("");          ///< --time: the inputs held at their values then (default t0)
  double at = std::nan("");            ///< linearize --at T: about the run's state at T, not the equilibrium
  std::vector<std::string> holds;      ///< --hold SIGNAL=VALUE: a signal held at a value
  std::vector<std::string> inputs;     ///< --input: signals (frf: SIGNAL or SIGNAL:RATE_SIGNAL)
  std::vector<std::string> outputs;    ///< --output: signals (linearize: default the logged ones)
  std::string frequencies = "0.5:30:60";  ///< frf --frequencies LO:HI:N [Hz], log spaced
  double max_frequency = 30.0;         ///< modes: the terminal table's highest frequency [Hz]
  bool report = false;
  std::string format = "csv";          ///< csv | mat
};

/// kc: the suspension kinematics of the scene's car.
struct KcArgs {
  std::string scene;
  std::string out = "out";
  std::vector<std::string> sets;
  std::string block;         ///< --block: the multibody block (default: the first)
  double travel = 0.08;      ///< --travel: wheel travel swept each way [m]
  int points = 33;           ///< --points: poses per wheel travel sweep (odd)
  bool report = false;
  std::string format = "csv";
};

/// fmu: the scene (or an FMU description naming one) as an FMI 3.0 FMU.
struct FmuArgs {
  std::string scene;
  std::string out;
  std::string kind = "both";  ///< me | cs | both
};

int fmu_command(const FmuArgs& args);
int run_command(const RunArgs& args);
int kc_command(const KcArgs& args);
int equilibrium_command(const LinearArgs& args);
int linearize_command(const LinearArgs& args);
int modes_command(const LinearArgs& args);
int frf_command(const LinearArgs& args);
int screen_command(const ScreenArgs& args);
int replay_command(const ReplayArgs& args);
int accuracy_command(const AccuracyArgs& args);
int sweep_command(const SweepArgs& args);
int blocks_command(std::ostream& out);

/// Prints the scene's load-time warnings to stderr ("warning: file:line: field: message").
/// "  estimated error: signals 0.31 %, sensitivities 1.2 % (shadow run at ...)", when estimated.
void print_error_estimate(std::ostream& out, const engine::RunStats& stats);
/// The run's own warnings (those the load gave are printed before the run), on stderr.
void print_run_warnings(const engine::Diagram& d, const engine::RunResult& r);
void print_warnings(const std::vector<std::string>& warnings);

/// "  step limited by: car.qd.z 41 %, damper_fl.q_valve 12 %, ..." (nothing for fixed-step runs).
void print_limiting_states(std::ostream& out, const engine::RunStats& stats);

/// "LO:HI:N" as three numbers (sweep --range, frf --frequencies); false when it is not that
/// shape. The callers check the values against their own rules.
bool split_range(const std::string& text, double& lo, double& hi, double& n);

/// Splits NAME=VALUE pairs; throws InputError naming --set on a malformed one.
std::vector<std::pair<std::string, std::string>> parse_sets(const std::vector<std::string>& sets);

}  // namespace dydp::apps
