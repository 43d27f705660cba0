// One FMU instance's numbers and the diagram's passes over them: time, the FMU's state vector
// (the blocks' states, then the objectives' integrals), the inputs, the tunable parameters;
// derivatives, variable values, event indicators, and the partial derivatives of FMI 3.0's
// fmi3GetDirectionalDerivative and fmi3GetAdjointDerivative from the blocks' tangents (exact).
// Nothing here knows the FMI calling sequence: fmi3_functions.cpp does.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "engine/evaluation/evaluator.hpp"
#include "engine/framework/diagram.hpp"
#include "fmi/exposure.hpp"
#include "fmi/variable_table.hpp"

namespace dydp::fmi {

/// What fmi3GetFMUState keeps: everything the next values depend on.
struct ModelSnapshot {
  double time = 0.0;
  double segment_start = 0.0;
  std::vector<double> states, inputs, parameters;
  std::vector<double> sensitivities;  ///< the states' sensitivities, when the FMU has directions
};

class FmuModel {
 public:
  /// Loads the FMU description `fmu_file` (resources/fmu.yaml) and its scene. Throws
  /// engine::InputError on a bad scene or description.
  explicit FmuModel(const std::string& fmu_file);

  const VariableTable& table() const { return table_; }
  const engine::Diagram& diagram() const { return *diagram_; }
  int num_states() const { return table_.num_states(); }
  /// The description's sensitivity directions (Co-Simulation): the first of the diagram's.
  int num_sensitivities() const { return static_cast<int>(table_.sensitivities.size()); }
  double stop_time() const { return stop_; }

  /// Time span and the start state from the blocks' initial states at t0 (parameters as set),
  /// or the equilibrium of `initial: equilibrium`; with directions, their sensitivities there.
  void start(double t0, double stop);
  void set_time(double t);
  double time() const { return t_; }
  /// Where the present segment between breakpoints began: blocks choose their branch with it.
  void set_segment_start(double t);
  void set_states(const double* x);
  const std::vector<double>& states() const { return x_; }
  /// d(FMU state)/d(direction) for the directions, direction d at [d * num_states()]: set at the
  /// start and moved by the integrator; setting the states or a parameter leaves them as they were.
  const std::vector<double>& sensitivities() const { return sens_; }
  /// The integrator's move of the sensitivities (with move_to).
  void move_sensitivities(const double* s);
  /// d(sensitivities)/dt at (t, x) for the sensitivities s (layout as sensitivities()): the
  /// tangent pass along the states' sensitivities and the directions' parameter seeds.
  void sensitivity_derivatives(const double* s, double* sdot);

  /// Sets a parameter or an input; throws engine::InputError out of its bounds.
  void set_value(const Variable& v, double value);
  /// The value of any variable at (t, x, inputs).
  double value(const Variable& v);
  /// d(FMU state)/dt: the blocks' derivatives, then the quadratures' integrands.
  void derivatives(double* xdot);
  void event_indicators(double* z) const;
  /// The first breakpoint after t, or +inf.
  double next_breakpoint(double t) const;

  /// J seed for the unknowns' rows and the knowns' columns (states, inputs, differentiable
  /// parameters as knowns; derivatives, outputs as unknowns). Throws std::invalid_argument
  /// naming a reference that cannot be one.
  void directional_derivative(const std::vector<const Variable*>& unknowns, const std::vector<const Variable*>& knowns,
                              const double* seed, double* sensitivity);
  /// J^T seed, seed one per unknown, sensitivity one per known.
  void adjoint_derivative(const std::vector<const Variable*>& unknowns, const std::vector<const Variable*>& knowns,
                          const double* seed, double* sensitivity);
  /// d(FMU state derivatives)/d(FMU states), column-major (num_states^2).
  void state_jacobian(double* jac);

  /// Counts the changes made from outside an integration (states, inputs, parameters set, a
  /// restored state): an integrator inside the FMU restarts when it moved.
  long changes() const { return changes_; }
  /// The integrator's own moves of (t, x), which do not count as changes.
  void move_to(double t, const double* x);

  ModelSnapshot snapshot() const;
  void restore(const ModelSnapshot& s);

 private:
  void refresh();  ///< after inputs or parameters changed: the evaluator's caches go
  double objective_value(int node, const double* dq, double* dpsi);
  double sensitivity_value(const Variable& v);

  /// The held inputs' tangents: zero in each of nd directions (the importer's values do not
  /// move with a parameter) for the tangent passes of the sensitivities.
  void hold_input_tangents(int nd);

  std::unique_ptr<engine::Diagram> diagram_;
  VariableTable table_;
  std::unique_ptr<engine::Evaluator> ev_;
  long changes_ = 0;
  double t_ = 0.0, segment_start_ = 0.0, stop_ = 0.0;
  std::vector<double> x_, inputs_, sens_;
  /// The signals' tangents along the sensitivities at (t_, x_): valid until either moves.
  std::vector<double> output_sens_;
  bool output_sens_valid_ = false;
  std::vector<std::pair<int, double>> held_;
};

}  // namespace dydp::fmi
