// The one march every integrator of dydp's own (RK4, SDIRK2, Rosenbrock-W) runs in: the state,
// its sensitivities and the quadratures from the initial state, over the output grid and the
// blocks' breakpoints (timeline.hpp), recorded at each output time, with the run's statistics at
// the end. An integrator supplies only its Stepper: how to go from one stop of the timeline to
// the next. Fixed-step schemes derive from FixedStepper and implement one step; error-controlled
// ones implement advance() and choose their own steps. (CVODES keeps its own march: it owns
// its state vectors, cvodes_solver.cpp.)
#pragma once

#include <Eigen/Dense>
#include <cmath>
#include <functional>
#include <memory>
#include <string>

#include "engine/analysis/run_result.hpp"
#include "engine/evaluation/evaluator.hpp"

namespace dydp::engine {

using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic>;
using Vector = Eigen::VectorXd;

/// gamma = 1 - 1/sqrt 2: SDIRK2's (L-stable, stiffly accurate) and ROS2's (rosenbrock_solver.cpp).
/// A literal (the double nearest to what 1.0 - 1.0 / std::sqrt(2.0) rounds to), so that it is
/// constant-initialised: computed, it would be initialised at start-up in an order the other
/// files' constants cannot rely on (clang does not fold std::sqrt). step_driver_test checks it.
inline constexpr double kGamma2 = 0.29289321881345254;

/// What a stepper advances: x (num_states), q (max(num_quadratures, 1): one unused zero
/// without quadratures), S = dx/dp (num_states x ns), Sq = dq/dp (q's rows x ns).
struct MarchState {
  double t = 0.0;
  Vector x, q;
  Matrix S, Sq;
};

class Stepper {
 public:
  virtual ~Stepper() = default;
  /// At the start and after each breakpoint, where the right-hand side may jump.
  virtual void begin(MarchState& s) {}
  /// From s.t to `target` exactly (the next output time or breakpoint; s.t is set to it after).
  virtual void advance(MarchState& s, double target) = 0;
  /// Leaves the evaluator's outputs (and, with sensitivities, their tangents) at (s.t, s.x, s.S)
  /// for the recorder. The default evaluates them.
  virtual void prepare_record(const MarchState& s, Evaluator& ev, int ns);
  /// The step the run reports in run.json (`step`): the fixed step, or the largest taken.
  virtual double reported_step() const = 0;
};

/// A scheme of equal steps of at most `h_max` between two stops of the timeline.
class FixedStepper : public Stepper {
 public:
  explicit FixedStepper(double h_max) : h_max_(h_max) {}
  void advance(MarchState& s, double target) override;
  double reported_step() const override { return h_max_; }

 protected:
  /// One step of size h from s.t (which the driver sets to the step's start).
  virtual void step(MarchState& s, double h) = 0;
  double h_max_;
};

/// The scene's fixed step: solver.step, else a tenth of the output step.
double scene_fixed_step(const Diagram& d);

/// Makes the stepper once the evaluator and the run's statistics exist.
using StepperFactory = std::function<std::unique_ptr<Stepper>(Evaluator& ev, int ns, RunStats& stats)>;

/// Runs the diagram with the stepper `make` builds; `method` names it in run.json.
RunResult march(const Diagram& d, const RunOptions& options, const std::string& method, const StepperFactory& make);

}  // namespace dydp::engine
