// The diagram's passes over its blocks in evaluation order: the value pass (outputs), state
// derivatives and quadrature integrands, and the tangent pass (their forward derivatives for
// many directions at once). Solvers call these; nothing here knows which solver runs.
#pragma once

#include <string>
#include <vector>

#include "engine/framework/diagram.hpp"
#include "engine/framework/local_adjoint.hpp"

namespace dydp::engine {

class Evaluator {
 public:
  /// `directions`: the sensitivity directions whose parameter seeds the tangent pass applies
  /// (the diagram's sensitivities, or none for a run without them).
  Evaluator(const Diagram& d, bool with_sensitivities);

  int num_directions() const { return ns_; }

  /// Evaluates with these scene parameter values (indexed like Diagram::parameters) instead
  /// of the diagram's, for CVODES' difference-quotient sensitivities, which perturb them.
  void use_parameter_values(const double* scene_values);
  void set_segment_start(double t) { segment_start_ = t; valid_ = false; }

  /// x(t0) and, for the sensitivity directions, dx(t0)/dp (ld = num_states).
  void initial_state(double t0, double* x0);
  void initial_state_tangent(double t0, const double* x0, DirView dx0);

  /// Value pass: every kept block's outputs at (t, x). Cached: repeated calls are free.
  void outputs(double t, const double* x);
  /// xdot = f(t, x) (runs the value pass if needed).
  void derivatives(double t, const double* x, double* xdot);
  /// Quadrature integrands at (t, x).
  void quadratures(double t, const double* x, double* qdot);

  /// Tangent pass for nd directions: state seeds dx (ld = num_states, null data: zero) and, when
  /// with_params, the parameter seeds of the first nd sensitivity directions (nd at most
  /// num_directions(): an FMU's stepper carries only the directions it outputs). Fills the
  /// signal tangents and, where given, dxdot (ld = num_states) and dqdot (ld = num_quadratures).
  void tangents(double t, const double* x, int nd, ConstDirView dx, bool with_params,
                DirView dxdot, DirView dqdot);

  /// Adjoint pass for nm adjoint directions, the transpose of the tangent pass: given weights
  /// lambda on the state derivatives (ld = num_states, null data: zero) and wq on the quadrature
  /// integrands (ld = num_quadratures, null data: zero), adds lambda^T f_x + wq^T q_x to ax
  /// (ld = num_states) and, when ap has data, lambda^T f_p + wq^T q_p along the sensitivity
  /// directions to ap (element (d, m) at ap.data[m * ap.ld + d]; the directions' parameter seeds
  /// as the tangent pass applies them). The graph is run backwards: derivatives and quadratures
  /// first, then the output steps in reverse order, each step's outputs weighted by the adjoint
  /// its readers gave them. A signal the tangent pass seeds (set_signal_seeds) is a cut wire:
  /// no adjoint flows through it to its block.
  void adjoint(double t, const double* x, int nm, ConstDirView lambda, ConstDirView wq, DirView ax, DirView ap);
  /// The adjoint of the initial state: adds w^T dx0/dp along the sensitivity directions to ap
  /// (w: ld = num_states; ap as in adjoint()).
  void initial_state_adjoint(double t0, const double* x0, int nm, ConstDirView w, DirView ap);
  /// Signal adjoints of the last adjoint pass: element (i, m) at [m * num_signals + i].
  const std::vector<double>& signal_adjoints() const { return sbar_; }

  /// Signals whose tangents the tangent pass sets instead of computing them: signal offsets[j]
  /// gets seeds[d * offsets.size() + j] in direction d, whatever its block would give (the wire
  /// cut there, the signal a free input: a linearisation's inputs). Every tangents call must
  /// then have the seeds' number of directions. Empty offsets: none (the default).
  void set_signal_seeds(std::vector<int> offsets, std::vector<double> seeds);
  /// Signals whose values the value pass sets instead of computing them: (offset, value) pairs
  /// (a pad held still: its rate at 0). Their tangents are the caller's to hold at zero
  /// (set_signal_seeds). Empty: none (the default).
  void hold_signals(std::vector<std::pair<int, double>> values);

  /// Overwrites the diagonal block d(xdot_b)/dx_b of jac (column-major, leading dimension ld)
  /// for every block that provides Block::local_jacobian, at (t, x). False when none does.
  bool local_jacobians(double t, const double* x, double* jac, int ld);

  /// The states of the blocks that gave a local Jacobian in the last local_jacobians call:
  /// (first state, count) per block, in state order.
  const std::vector<std::pair<int, int>>& local_state_ranges() const { return local_ranges_; }
  /// For those blocks alone, at the states x (a whole state vector; other blocks' states are not
  /// read) with their inputs as the last value pass left them: their rows of xdot, their
  /// diagonal blocks of d(xdot)/dx (like local_jacobians), and their rows of the tangent for
  /// state seeds dx, the input seeds of the last tangent pass and, when with_params, the
  /// parameter seeds. Nothing else is evaluated, so a solver can iterate on these blocks' states
  /// at a fixed point of the rest (Rosenbrock-W's local stages, docs/engine.md).
  void local_derivatives(double t, const double* x, double* xdot);
  void local_jacobians_held(double t, const double* x, double* jac, int ld);
  void local_derivatives_tangent(double t, const double* x, int nd, ConstDirView dx, bool with_params, DirView dxdot);

  const std::vector<double>& signals() const { return sig_; }
  /// Signal tangents of the last tangent pass: element (i, d) at [d * num_signals + i].
  const std::vector<double>& signal_tangents() const { return dsig_; }

  /// Names the first block whose outputs or derivatives (xdot, may be null) are not finite;
  /// empty when all are.
  std::string find_nonfinite(const double* xdot) const;
  /// Fast check that every signal and xdot[0, num_states) is finite.
  bool all_finite(const double* xdot) const;

 private:
  /// The local Jacobians of blocks whose adjoints come from their tangents, kept for the value
  /// point they were built at (value_pass_): per output step, per node's derivatives and
  /// quadratures; columns: all states, all ready inputs, the sensitivity directions if driven.
  struct KeptJacobian {
    long pass = -1;
    LocalJacobian J;
  };
  Eval eval_for(const Node& n, int index, double t, const double* x) const;
  Seeds seeds_for(const Node& n, int index, int nd, ConstDirView dx, bool with_params);
  void seed_signals(const Node& n, const OutputStep& step, int nd);
  Adjoint adjoint_for(const Node& n, int index, int nm, DirView ax, DirView ap);
  const LocalJacobian& kept_jacobian(KeptJacobian& kept, const Node& n, int index, BlockFunction fn, const Eval& e);

  const Diagram& d_;
  int ns_ = 0;
  double segment_start_ = 0.0;
  std::vector<double> sig_, dsig_;
  std::vector<double> sbar_;           ///< signal adjoints of the last adjoint pass
  /// per output step, per node's derivatives and quadratures
  std::vector<KeptJacobian> kept_outputs_, kept_derivatives_, kept_quadratures_;
  long value_pass_ = 0;                ///< counts the value passes computed (not cached)
  std::vector<DirView> ubar_;          ///< scratch for a node's input adjoint views
  std::vector<ConstDirView> wy_;       ///< scratch for a node's output weight views
  std::vector<double> pseed_;          ///< per node np x ns, d-major, concatenated
  std::vector<int> pseed_offset_;
  std::vector<bool> driven_;           ///< node has a parameter driven by a direction
  std::vector<std::vector<double>> p_override_;  ///< per node, when use_parameter_values was called
  std::vector<bool> time_only_;        ///< node has neither inputs nor states: a source
  std::vector<bool> source_valid_;     ///< its outputs are those at source_t_
  std::vector<double> source_t_, source_segment_;
  std::vector<bool> zero_tangent_;     ///< per output port (at its signal offset): its tangents
                                       ///< are zero in this tangent pass
  std::vector<const double*> u_;       ///< input pointers, per node concatenated
  std::vector<int> u_offset_;
  std::vector<double*> y_;             ///< output pointers, per node concatenated
  std::vector<ConstDirView> du_;       ///< scratch for a node's input seed views
  std::vector<DirView> dy_;            ///< scratch for a node's output seed views
  std::vector<double> zero_x_;         ///< seeds for state-less evaluations
  bool valid_ = false;
  std::vector<std::pair<int, int>> local_ranges_;  ///< see local_state_ranges
  std::vector<int> local_nodes_;                   ///< their nodes
  double last_t_ = 0.0;
  std::vector<double> last_x_;
  std::vector<std::pair<int, double>> held_values_;  ///< see hold_signals
  std::vector<int> seeded_;            ///< per signal: its column in signal_seeds_, or -1
  std::vector<double> signal_seeds_;   ///< see set_signal_seeds
  int num_seeded_ = 0;
};

}  // namespace dydp::engine
