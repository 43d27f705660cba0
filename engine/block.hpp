// The Block interface: what every element of a dydp diagram declares (ports, states,
// quadratures, parameters) and computes (outputs, state derivatives, and their tangents).
// Blocks are stateless code over the numbers the engine hands them (Eval, Seeds).
#pragma once

#include <string>
#include <vector>

namespace dydp::engine {

/// Column-per-direction view of tangent seeds: element (i, d) lives at data[d * ld + i].
/// A null data pointer means "all seeds are zero" (read-only views only).
struct ConstDirView {
  const double* data = nullptr;
  int ld = 0;
  double operator()(int i, int d) const { return data ? data[d * ld + i] : 0.0; }
  bool zero() const { return data == nullptr; }
};

struct DirView {
  double* data = nullptr;
  int ld = 0;
  double& operator()(int i, int d) const { return data[d * ld + i]; }
  operator ConstDirView() const { return {data, ld}; }
};

/// A port as a block instance declares it.
struct PortDecl {
  std::string name;
  int width = 1;
  std::string unit;
  /// Input: some output reads this input directly (without a state in between).
  /// Output: this output reads some input directly. Algebraic loops are cycles through such
  /// input -> output pairs; an output that reads states only breaks the cycle.
  bool feedthrough = true;
};

/// The numbers a block sees at one evaluation.
struct Eval {
  double t = 0.0;
  /// Start of the integration segment being taken; piecewise-in-time laws choose their branch
  /// with reached(), so that a breakpoint at the end of a segment is not yet "passed".
  double segment_start = 0.0;
  const double* x = nullptr;          ///< the block's states [num_states]
  const double* const* u = nullptr;   ///< u[k]: input port k, [width of port k]
  const double* p = nullptr;          ///< parameter values, in the order of the block's ParamSpecs
  /// False in the first output pass, where only outputs declared without feedthrough need be
  /// computed and inputs must not be read (they are not yet computed for this point).
  bool inputs_ready = true;

  /// Whether time has passed the breakpoint tb: true after it, and at it when the current
  /// segment started there.
  bool reached(double tb) const { return t > tb || (t == tb && segment_start >= tb); }
};

/// Forward-mode seeds for one tangent evaluation over `directions` directions.
struct Seeds {
  int directions = 0;
  ConstDirView x;                       ///< seeds of the block's states
  const ConstDirView* u = nullptr;      ///< u[k]: seeds of input port k
  ConstDirView p;                       ///< seeds of the block's parameters (zero for Jacobians)
};

/// Thrown by a block whose input left its domain (negative volume, lift-off misuse, ...).
/// The solver treats it as a recoverable failure and retries with a smaller step.
struct OutOfDomain {
  std::string reason;
};

class Block {
 public:
  virtual ~Block() = default;

  const std::vector<PortDecl>& inputs() const { return inputs_; }
  const std::vector<PortDecl>& outputs() const { return outputs_; }
  int num_states() const { return num_states_; }
  int num_quadratures() const { return num_quadratures_; }
  const std::vector<std::string>& state_names() const { return state_names_; }

  /// Initial state x(t0) and its tangent dx(t0) for the parameter seeds in s.p.
  virtual void initial_state(const Eval& e, double* x0) const {}
  virtual void initial_state_tangent(const Eval& e, const Seeds& s, DirView dx0) const {}

  /// y = g(t, x, u, p) for every output port: y[k] has the width of output port k.
  /// A block with outputs of both kinds is called twice per point: first with
  /// e.inputs_ready == false (set the state-only outputs), then with all inputs ready.
  virtual void outputs(const Eval& e, double* const* y) const = 0;
  /// dy = g_x dx + g_u du + g_p dp, for every output port and direction.
  virtual void outputs_tangent(const Eval& e, const Seeds& s, const DirView* dy) const = 0;

  /// xdot = f(t, x, u, p).
  virtual void derivatives(const Eval& e, double* xdot) const {}
  /// dxdot = f_x dx + f_u du + f_p dp.
  virtual void derivatives_tangent(const Eval& e, const Seeds& s, DirView dxdot) const {}

  /// Integrands of the block's quadratures (objective integrals), and their tangents.
  virtual void quadratures(const Eval& e, double* qdot) const {}
  virtual void quadratures_tangent(const Eval& e, const Seeds& s, DirView dqdot) const {}

  /// Times in (t0, t1] where the block's laws are discontinuous; the solvers stop there.
  virtual std::vector<double> breakpoints(const double* p, double t0, double t1) const { return {}; }

 protected:
  void declare_input(std::string name, int width, std::string unit = "", bool feedthrough = true) {
    inputs_.push_back({std::move(name), width, std::move(unit), feedthrough});
  }
  void declare_output(std::string name, int width, std::string unit = "", bool feedthrough = true) {
    outputs_.push_back({std::move(name), width, std::move(unit), feedthrough});
  }
  void declare_states(std::vector<std::string> names) {
    num_states_ = static_cast<int>(names.size());
    state_names_ = std::move(names);
  }
  void declare_quadratures(int n) { num_quadratures_ = n; }

 private:
  std::vector<PortDecl> inputs_;
  std::vector<PortDecl> outputs_;
  std::vector<std::string> state_names_;
  int num_states_ = 0;
  int num_quadratures_ = 0;
};

}  // namespace dydp::engine
