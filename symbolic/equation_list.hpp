// The recursive scheme: a flat list of assignments `AUX = expr` in evaluation order, each
// right-hand side small and referring to earlier auxiliaries, plus the flagged outputs. Every
// pass (elimination, differentiation, expansion, interpretation, emission, op counting) walks it.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "symbolic/expr.hpp"

namespace dydp::symbolic {

struct Assignment {
  NodeId target;  // an Aux symbol, assigned exactly once
  NodeId value;
};

struct Output {
  std::string name;  // what the value means (`omega_z`, `d(omega_z)/d(k)`)
  NodeId value;      // usually an Aux symbol; any expression is allowed
};

class EquationList {
 public:
  explicit EquationList(Context& context) : context_(&context) {}

  // Appends `name = value` and returns the new auxiliary, or returns `value` itself when it is
  // trivial (a constant, a symbol, an abbreviation, or the negation of one): those are inlined.
  Expr assign(std::string_view name, Expr value);
  // Appends `name = value` even when the value is trivial.
  Expr assign_always(std::string_view name, Expr value);
  // Appends an assignment to an existing auxiliary (used by passes that copy lists).
  void append(Assignment a) { assignments_.push_back(a); }
  void add_output(std::string name, Expr value);
  void add_output(Output o) { outputs_.push_back(std::move(o)); }

  Context& context() const { return *context_; }
  const std::vector<Assignment>& assignments() const { return assignments_; }
  const std::vector<Output>& outputs() const { return outputs_; }
  std::size_t size() const { return assignments_.size(); }

  // A differentiated list is its primal list followed by the derivative assignments; these mark
  // where the primal part ends (assignments and outputs). Equal to the sizes for a plain list.
  std::size_t primal_assignments() const { return primal_assignments_; }
  std::size_t primal_outputs() const { return primal_outputs_; }
  void set_primal_split(std::size_t assignments, std::size_t outputs) {
    primal_assignments_ = assignments;
    primal_outputs_ = outputs;
  }
  bool has_split() const { return primal_assignments_ != kNoSplit; }

  static constexpr std::size_t kNoSplit = static_cast<std::size_t>(-1);

 private:
  Context* context_;
  std::vector<Assignment> assignments_;
  std::vector<Output> outputs_;
  std::size_t primal_assignments_ = kNoSplit;
  std::size_t primal_outputs_ = kNoSplit;
};

// True for values that are inlined instead of assigned (see EquationList::assign).
bool is_trivial(const Context& context, NodeId value);

}  // namespace dydp::symbolic
