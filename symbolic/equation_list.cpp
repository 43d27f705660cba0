// Appending to an equation list, with trivial values inlined.
#include "symbolic/equation_list.hpp"

#include <stdexcept>

namespace dydp::symbolic {

bool is_trivial(const Context& context, NodeId value) {
  const Op op = context.op(value);
  if (op == Op::Neg) value = context.children(value)[0];
  return context.op(value) == Op::Constant || context.op(value) == Op::Symbol ||
         context.is_abbreviation(value);
}

Expr EquationList::assign(std::string_view name, Expr value) {
  if (&value.context() != context_) throw std::invalid_argument("symbolic: value from another context");
  if (is_trivial(*context_, value.id())) return value;
  return assign_always(name, value);
}

Expr EquationList::assign_always(std::string_view name, Expr value) {
  if (&value.context() != context_) throw std::invalid_argument("symbolic: value from another context");
  Expr target = context_->aux(name);
  assignments_.push_back(Assignment{target.id(), value.id()});
  return target;
}

void EquationList::add_output(std::string name, Expr value) {
  if (&value.context() != context_) throw std::invalid_argument("symbolic: value from another context");
  outputs_.push_back(Output{std::move(name), value.id()});
}

}  // namespace dydp::symbolic
