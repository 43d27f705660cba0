// A scene loaded, validated, pruned and ordered: the frozen diagram the solvers run.
// Nodes hold the block instances and where their ports, states and quadratures live in the
// engine's flat arrays; scene parameters drive block parameters through `$name` references.
#pragma once

#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "engine/framework/block.hpp"
#include "engine/framework/objective.hpp"
#include "engine/framework/registry.hpp"

namespace dydp::engine {

struct TimeSpec {
  double start = 0.0;
  double stop = 1.0;
  double output_step = 0.01;
};

struct SolverSpec {
  std::string method = "bdf";  ///< bdf | adams | rk4 | sdirk2 | rosw
  double rtol = 1e-6;
  double atol = 1e-8;
  double step = 0.0;           ///< fixed-step methods; 0: output_step / 10
  long max_steps = 500000;     ///< per output interval (CVODES mxstep)
  /// CVODES: smallest step [s]. A run that needs a smaller one (a block refusing every point
  /// ahead, a solution gone singular) stops naming time and block instead of crawling.
  double min_step = 1e-12;
  /// CVODES: include the sensitivities (and quadrature sensitivities) in the error test.
  /// Off, the steps are chosen for the states alone: cheaper, sensitivities less controlled.
  bool sens_error_test = true;
  /// Absolute tolerances scaled by the states' nominal magnitudes (atol * nominal_i); false:
  /// atol as it stands for every state, the nominal magnitudes ignored.
  bool nominal_scaling = true;
  /// BDF and Adams: the Newton iteration's convergence test, as a fraction of the error test's
  /// tolerance (CVODES' nonlinear convergence coefficient, its default 0.1). A larger value
  /// stops the iteration sooner and declares fewer convergence failures (each costs a Jacobian).
  double newton_coefficient = 0.1;
  /// BDF and Adams: the highest order the integrator may use (BDF at most 5, Adams at most 12);
  /// 0: the method's own limit. BDF's orders 4 and 5 are stable on a narrower wedge around the
  /// imaginary axis: on lightly damped fast modes (a wheel on its tyre, oil columns) at loose
  /// tolerances they fail the error test where order 3 does not (docs/accuracy.md).
  int max_order = 0;
  /// BDF: the blocks' own diagonal blocks of the Newton matrix (Block::local_jacobian, the
  /// dampers' pressures) refreshed at each set-up, with a set-up every 5 steps; false: CVODES'
  /// own (the kept Jacobian as it is, a set-up every 20 steps).
  bool refresh_local_jacobians = true;
};

/// Where a run starts (`initial:` in a scene, docs/scenes.md).
struct InitialSpec {
  /// `initial: equilibrium`: from the static equilibrium at time.start with the inputs held at
  /// their values there (engine/studies/initial_equilibrium.hpp computes it before each run);
  /// false: from the blocks' own initial states.
  bool equilibrium = false;
  /// `initial.hold`: signals the equilibrium holds at other values (a pad's rate at 0), resolved
  /// to (signal offset, value); `hold_names` as written, one per entry (a port's every element).
  std::vector<std::pair<int, double>> held;
  std::vector<std::string> hold_names;
  int line = 0;  ///< of `initial:` (0: not written)
};

/// A run's start given from outside the blocks' initial_state: x0 and dx0/dp, set by
/// engine/studies/initial_equilibrium.hpp for `initial: equilibrium` and valid only for the
/// block parameters and start time it was computed at (engine/analysis/run.cpp refuses a stale one).
struct StartState {
  std::vector<double> x;                 ///< empty: the blocks' own initial states
  std::vector<int> parameters;           ///< the scene parameter of each column of dx_dp
  std::vector<double> dx_dp;             ///< column c at dx_dp[c * num_states ...]
  double t = 0.0;                        ///< the time.start it was computed at
  std::vector<double> block_parameters;  ///< every kept block's p, in node order, when computed
};

struct SceneParameter {
  std::string name;
  double value = 0.0;
  std::string unit;
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  int line = 0;
  /// A direction named by block parameters: the list of its entry (`directions` or
  /// `sensitivities`, its messages name that list; `line` is the entry's); empty for a
  /// parameter written under `parameters:`.
  std::string direction_list;
};

struct Node {
  std::string name;                 ///< inside a subsystem instance: `corner_fl.damper`
  const BlockType* type = nullptr;
  std::string file;                 ///< where the block is written (a subsystem's file); empty: the scene
  int line = 0;
  std::unique_ptr<Block> block;
  const Objective* objective = nullptr;  ///< the block as an objective, or null
  /// The settings it was made from (its consistency checks read them again when a scene
  /// parameter changes); null for nodes not read from a scene.
  std::shared_ptr<const BlockSettings> settings;

  std::vector<double> p;            ///< parameter values, ParamSpec order
  std::vector<int> p_scene;         ///< scene parameter driving p[j], or -1
  std::vector<int> p_line;          ///< where p[j] was written (0: default)
  /// Nominal magnitude of each state (the block's, with the scene's `nominal:` entries);
  /// empty for nodes not read from a scene: the block's declared values.
  std::vector<double> state_nominal;
  std::vector<std::string> p_file;  ///< the file of p_line[j] (an instance's value: the including file); empty: `file`
  std::vector<int> input_source;    ///< signal offset of the output feeding input k
  std::vector<int> output_offset;   ///< signal offset of output k
  int state_offset = 0;
  int quad_offset = 0;

  /// The file where p[j] was written (`scene_file` when that is the scene itself).
  const std::string& parameter_file(size_t j, const std::string& scene_file) const {
    if (j < p_file.size() && !p_file[j].empty()) return p_file[j];
    return file.empty() ? scene_file : file;
  }
};

/// One call of a block's outputs (and of their tangents) in the value and tangent passes.
struct OutputStep {
  int node = 0;
  std::vector<int> outputs;          ///< the outputs first computable here: they read exactly
  std::vector<int> reads;            ///< these inputs (sorted)
  std::vector<unsigned char> ready;  ///< per input of the node: computed (read by this step or
                                     ///< an earlier step of the node)
  bool inputs_ready = true;          ///< every input some output of the node reads is ready
};

struct LoggedSignal {
  std::string name;  ///< block.port, with [i] appended per element when width > 1
  int offset = 0;    ///< in the signal array
};

class Diagram {
 public:
  std::string file;
  std::string scene_name;
  TimeSpec time;
  SolverSpec solver;
  std::vector<SceneParameter> parameters;
  std::vector<int> sensitivities;      ///< indices into parameters: the directions
  InitialSpec initial;
  StartState start;
  std::vector<Node> nodes;             ///< kept blocks, in scene order
  /// Output evaluation, in dependency order: one step per group of a block's outputs that read
  /// the same inputs (state-only outputs first).
  std::vector<OutputStep> output_steps;
  std::vector<std::string> pruned;     ///< blocks no requested output needs
  /// Legal but probably unintended input found at load time ("file:line: field: message"):
  /// printed by the commands and recorded in run.json `warnings`.
  std::vector<std::string> warnings;
  std::vector<LoggedSignal> logged;    ///< one entry per scalar logged
  std::vector<int> objectives;         ///< node indices of requested objectives
  int num_states = 0;
  int num_signals = 0;
  int num_quadratures = 0;

  int find_parameter(const std::string& name) const;
  /// Unit of the signal at `offset` (an output's element), following outputs that carry their
  /// first input's unit upstream; "" when unknown.
  std::string signal_unit(int offset) const;
  /// Unit of an objective node's psi: its kind applied to the unit of its first input.
  std::string objective_unit(const Node& n) const;
  /// Sets a scene parameter and every block parameter it drives; checks the bounds of both
  /// (the scene parameter's range only with check_range: finite differences step past it).
  void set_parameter(int index, double value, bool check_range = true);
  /// Makes these scene parameters the sensitivity directions; throws InputError (at the block
  /// parameter's line) when one drives a parameter its block cannot differentiate.
  void set_sensitivities(const std::vector<int>& directions);
  /// Seed of block parameter j of node n in sensitivity direction d.
  double parameter_seed(const Node& n, int j, int d) const {
    return n.p_scene[j] >= 0 && n.p_scene[j] == sensitivities[d] ? 1.0 : 0.0;
  }
  /// Every kept block's parameter values, in node order (what `start` was computed for).
  std::vector<double> block_parameter_values() const;
  /// Whether `start` is set and was computed for the present block parameters and time.start.
  bool start_is_current() const;
  /// All breakpoints of the kept blocks in (t0, t1], sorted, unique.
  std::vector<double> breakpoints(double t0, double t1) const;
};

/// Throws InputError when one of `directions` drives a block parameter of `nodes` that its block
/// cannot differentiate.
void check_differentiable(const std::vector<Node>& nodes, const Diagram& d, const std::vector<int>& directions);

/// The scene parameters (and directions) that every block they drive can differentiate, in the
/// scene's order: what the linear analyses give derivatives for, and what `--adjoint` takes as
/// its directions (those that drive a switching time or another setting without a tangent are
/// left out).
std::vector<int> differentiable_parameters(const Diagram& d);

/// Loads a scene file; overrides are --set NAME=VALUE pairs for scene parameters;
/// setting_overrides (SETTING, VALUE) replace that setting in every block whose type declares
/// it (replay: the recorded input file). Throws InputError on bad input.
Diagram load_scene(const std::string& path,
                   const std::vector<std::pair<std::string, std::string>>& overrides = {},
                   const std::vector<std::pair<std::string, std::string>>& setting_overrides = {});

}  // namespace dydp::engine
