// Expression nodes built by id, simplified as Context::make builds them: what the two
// differentiation passes (differentiate.cpp forward, reverse.cpp reverse) write their rules with.
#pragma once

#include <span>

#include "symbolic/expr.hpp"

namespace dydp::symbolic {

class NodeBuilder {
 public:
  explicit NodeBuilder(Context& ctx) : ctx_(ctx) {}

 protected:
  NodeId add(NodeId a, NodeId b) { const NodeId k[2] = {a, b}; return ctx_.make(Op::Add, k); }
  NodeId sub(NodeId a, NodeId b) { return add(a, neg(b)); }
  NodeId mul(NodeId a, NodeId b) { const NodeId k[2] = {a, b}; return ctx_.make(Op::Mul, k); }
  NodeId div(NodeId a, NodeId b) { const NodeId k[2] = {a, b}; return ctx_.make(Op::Div, k); }
  NodeId neg(NodeId a) { return ctx_.make(Op::Neg, std::span<const NodeId>(&a, 1)); }
  NodeId fn(Op op, NodeId a) { return ctx_.make(op, std::span<const NodeId>(&a, 1)); }
  NodeId constant(double v) { return ctx_.constant(v).id(); }
  NodeId select(NodeId c, NodeId a, NodeId b) { const NodeId k[3] = {c, a, b}; return ctx_.make(Op::Select, k); }

  Context& ctx_;
};

}  // namespace dydp::symbolic
