// The Block interface: what every element of a dydp diagram declares (ports, states,
// quadratures, parameters) and computes (outputs, state derivatives, and their tangents).
// Blocks are stateless code over the numbers the engine hands them (Eval, Seeds).
#pragma once

#include <algorithm>
#include <optional>
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

/// Unit of an output that carries its first input's unit (demux, sum, lag, ...): the engine
/// resolves it from whatever drives that input (Diagram::signal_unit).
inline constexpr const char* kUnitOfFirstInput = "=";

/// A port as a block instance declares it.
struct PortDecl {
  std::string name;
  int width = 1;
  std::string unit;  ///< SI unit, "" when unknown or dimensionless, kUnitOfFirstInput
  /// Input: the outputs that do not list their inputs (`reads`) read this input directly
  /// (without a state in between).
  /// Output: this output reads some input directly. Algebraic loops are cycles through
  /// input -> output pairs where the output reads the input; an output that reads states only
  /// breaks the cycle.
  bool feedthrough = true;
  /// Output only, set by Block::set_output_reads: the inputs this output reads directly (sorted).
  /// Unset: a feedthrough output reads every feedthrough input, any other output none.
  std::optional<std::vector<int>> reads;
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
  /// Which inputs are computed for this point, per input port (null: all of them when
  /// inputs_ready, none otherwise). Output passes call a block once per group of outputs that
  /// read the same inputs, in dependency order; at each call the block sets (at least) the
  /// outputs whose inputs are all ready (Block::output_ready) and reads no other input.
  const unsigned char* ready = nullptr;
  /// True when every input that some output reads is ready (the block's last output call,
  /// and always for derivatives, quadratures and initial states). False in the call for the
  /// state-only outputs of a block that also has feedthrough outputs.
  bool inputs_ready = true;

  bool input_ready(int k) const { return ready ? ready[k] != 0 : inputs_ready; }

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

/// Reverse-mode (adjoint) products for `directions` adjoint directions: given weights w on a
/// function's values (outputs, xdot, qdot or x0), a block adds w^T g_x, w^T g_u and w^T g_p S to
/// these views, column m for adjoint direction m. Results accumulate (+=); a view with null data
/// is not wanted (its product is neither computed nor written). Block's defaults
/// (engine/framework/block_adjoint.cpp) take the function's small local Jacobian from the block's
/// own tangent, one unit seed per wanted state, input element and parameter column, and multiply
/// its transpose: every block has a correct adjoint; a block may write a cheaper one.
struct Adjoint {
  int directions = 0;
  DirView x;                   ///< += w^T g_x [num_states x directions]
  const DirView* u = nullptr;  ///< u[k] += w^T g_{u_k} [width of port k x directions]; null: none
  /// The parameter part is wanted along p_columns combinations of the block's parameters, the
  /// columns of p_seeds (element (j, c): parameter j in column c; ld = the block's parameter
  /// count), as the tangent's parameter seeds Seeds::p: p(c, m) += sum_j (w^T g_{p_j}) S(j, c).
  int p_columns = 0;
  ConstDirView p_seeds;
  DirView p;                   ///< [p_columns x directions]
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
  /// Nominal magnitude of each state, in the state's unit: the size of its typical excursion
  /// (a chamber pressure 1e6 Pa, a wheel travel 0.01 m). The solvers hold state i to the
  /// absolute tolerance atol * nominal[i], so one atol means the same in every unit. Default 1.
  const std::vector<double>& state_nominals() const { return state_nominals_; }
  /// Nominal magnitude of each quadrature (the integral's unit), default 1.
  const std::vector<double>& quadrature_nominals() const { return quadrature_nominals_; }

  /// Initial state x(t0) and its tangent dx(t0) for the parameter seeds in s.p.
  virtual void initial_state(const Eval& e, double* x0) const {}
  virtual void initial_state_tangent(const Eval& e, const Seeds& s, DirView dx0) const {}
  /// w^T dx0/dp S into a.p (the initial state reads parameters only: a.x and a.u are untouched).
  virtual void initial_state_adjoint(const Eval& e, ConstDirView w, const Adjoint& a) const;

  /// Inputs that output k reads directly, sorted: those given to set_output_reads, else every
  /// feedthrough input for a feedthrough output, none for a state-only one.
  std::vector<int> output_reads(int k) const {
    const PortDecl& out = outputs_[k];
    if (out.reads) return *out.reads;
    std::vector<int> reads;
    if (out.feedthrough)
      for (int i = 0; i < static_cast<int>(inputs_.size()); ++i)
        if (inputs_[i].feedthrough) reads.push_back(i);
    return reads;
  }
  /// Whether output k is to be set in this evaluation: every input it reads is ready.
  bool output_ready(const Eval& e, int k) const {
    const PortDecl& out = outputs_[k];
    if (out.reads) {
      for (int i : *out.reads)
        if (!e.input_ready(i)) return false;
      return true;
    }
    if (!out.feedthrough) return true;
    for (int i = 0; i < static_cast<int>(inputs_.size()); ++i)
      if (inputs_[i].feedthrough && !e.input_ready(i)) return false;
    return true;
  }

  /// y = g(t, x, u, p) for every output port: y[k] has the width of output port k.
  /// A block whose outputs read different inputs is called once per group of outputs with the
  /// same reads, in dependency order (see Eval::ready): it sets the outputs that are
  /// output_ready(e, k) and may set them again, with the same values, in later calls. With the
  /// default reads that is two calls for a block with outputs of both kinds: first with
  /// e.inputs_ready == false (set the state-only outputs), then with the inputs ready.
  virtual void outputs(const Eval& e, double* const* y) const = 0;
  /// dy = g_x dx + g_u du + g_p dp, for every output port and direction; called like outputs
  /// (the same ready inputs), reading the seeds of ready inputs only.
  virtual void outputs_tangent(const Eval& e, const Seeds& s, const DirView* dy) const = 0;
  /// The transpose of outputs_tangent: w[k] weights output port k (null data: zero), and
  /// w^T g_x, w^T g_u, w^T g_p S go into a. Called like outputs (the same ready inputs): only
  /// the outputs that are output_ready may carry weights, and only ready inputs get products.
  virtual void outputs_adjoint(const Eval& e, const ConstDirView* w, const Adjoint& a) const;

  /// xdot = f(t, x, u, p).
  virtual void derivatives(const Eval& e, double* xdot) const {}
  /// dxdot = f_x dx + f_u du + f_p dp.
  virtual void derivatives_tangent(const Eval& e, const Seeds& s, DirView dxdot) const {}
  /// w^T f_x, w^T f_u, w^T f_p S for weights w on xdot.
  virtual void derivatives_adjoint(const Eval& e, ConstDirView w, const Adjoint& a) const;
  /// Optional: d(xdot)/dx over the block's own states with its inputs held, column j at
  /// jac.data + j * jac.ld. Blocks whose derivatives are cheap but strongly nonlinear in their
  /// own states (hydraulic chambers) provide it, so that an implicit solver can refresh this
  /// diagonal block of its iteration matrix without a whole Jacobian, and Rosenbrock-W solves
  /// the block's rows of each stage exactly (Newton on its own states, its inputs held at the
  /// stage's base point: the block's inputs must not depend on its own states within one
  /// evaluation). False: not provided.
  virtual bool local_jacobian(const Eval& e, DirView jac) const { return false; }

  /// Integrands of the block's quadratures (objective integrals), and their tangents.
  virtual void quadratures(const Eval& e, double* qdot) const {}
  virtual void quadratures_tangent(const Eval& e, const Seeds& s, DirView dqdot) const {}
  /// w^T of the integrands' derivatives, for weights w on qdot.
  virtual void quadratures_adjoint(const Eval& e, ConstDirView w, const Adjoint& a) const;

  /// True when the block's adjoints are Block's defaults (the transposed local Jacobians of its
  /// tangent): the evaluator then builds those Jacobians once per value point and keeps them for
  /// every adjoint pass at that point. A block that writes its own *_adjoint returns false.
  virtual bool adjoint_from_tangent() const { return true; }

  /// Times in (t0, t1] where the block's laws are discontinuous; the solvers stop there.
  virtual std::vector<double> breakpoints(const double* p, double t0, double t1) const { return {}; }

 protected:
  void declare_input(std::string name, int width, std::string unit = "", bool feedthrough = true) {
    inputs_.push_back({std::move(name), width, std::move(unit), feedthrough, std::nullopt});
  }
  void declare_output(std::string name, int width, std::string unit = "", bool feedthrough = true) {
    outputs_.push_back({std::move(name), width, std::move(unit), feedthrough, std::nullopt});
  }
  /// Output `output` reads directly exactly the inputs `inputs` (indices of input ports; empty:
  /// it reads states only). Overrides the output's feedthrough flag and the inputs' defaults.
  void set_output_reads(int output, std::vector<int> inputs) {
    std::sort(inputs.begin(), inputs.end());
    inputs.erase(std::unique(inputs.begin(), inputs.end()), inputs.end());
    outputs_[output].feedthrough = !inputs.empty();
    outputs_[output].reads = std::move(inputs);
  }
  /// States and their nominal magnitudes (empty: 1 for each).
  void declare_states(std::vector<std::string> names, std::vector<double> nominals = {}) {
    num_states_ = static_cast<int>(names.size());
    state_names_ = std::move(names);
    if (nominals.empty()) nominals.assign(state_names_.size(), 1.0);
    state_nominals_ = std::move(nominals);
  }
  void declare_quadratures(int n, std::vector<double> nominals = {}) {
    num_quadratures_ = n;
    if (nominals.empty()) nominals.assign(n, 1.0);
    quadrature_nominals_ = std::move(nominals);
  }

 private:
  std::vector<PortDecl> inputs_;
  std::vector<PortDecl> outputs_;
  std::vector<std::string> state_names_;
  std::vector<double> state_nominals_;
  std::vector<double> quadrature_nominals_;
  int num_states_ = 0;
  int num_quadratures_ = 0;
};

}  // namespace dydp::engine
