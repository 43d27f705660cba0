// Tree operation counts of every right-hand side, memoised per node: a node's tree count is a
// function of the node alone, and children always have smaller ids than their parents, so one
// ascending sweep over the reachable nodes computes them all.
#include "symbolic/op_count.hpp"

#include "symbolic/dag_walk.hpp"

#include <cmath>
#include <limits>
#include <vector>

namespace dydp::symbolic {
namespace {

std::uint64_t sat_add(std::uint64_t a, std::uint64_t b) {
  const std::uint64_t s = a + b;
  return s < a ? std::numeric_limits<std::uint64_t>::max() : s;
}

OpCount& operator+=(OpCount& a, const OpCount& b) {
  a.add = sat_add(a.add, b.add);
  a.mul = sat_add(a.mul, b.mul);
  a.div = sat_add(a.div, b.div);
  a.call = sat_add(a.call, b.call);
  return a;
}

// The operations of one node itself, as emit_cpp writes it.
OpCount own_ops(const Context& ctx, NodeId n) {
  OpCount c;
  const auto kids = ctx.children(n);
  switch (ctx.op(n)) {
    case Op::Constant:
    case Op::Symbol:
    case Op::Neg: break;
    case Op::Add: c.add = kids.size() - 1; break;
    case Op::Mul: {
      // written as numerator/denominator: inverse powers go below the line
      std::uint64_t numerator = 0, denominator = 0;
      for (NodeId f : kids) {
        const bool inverse = ctx.op(f) == Op::Pow && ctx.op(ctx.children(f)[1]) == Op::Constant &&
                             ctx.value(ctx.children(f)[1]) < 0.0;
        (inverse ? denominator : numerator) += 1;
      }
      c.mul = (numerator > 0 ? numerator - 1 : 0) + (denominator > 0 ? denominator - 1 : 0);
      c.div = denominator > 0 ? 1 : 0;
      break;
    }
    case Op::Div: c.div = 1; break;
    case Op::Pow: {
      const NodeId e = kids[1];
      if (ctx.op(e) == Op::Constant) {
        const double v = ctx.value(e);
        if (v == std::nearbyint(v) && std::fabs(v) <= kMaxInlinePower) {
          c.mul = static_cast<std::uint64_t>(std::fabs(v)) - 1;
          break;  // a negative power's division is counted by the product or written 1.0/(...)
        }
      }
      c.call = 1;
      break;
    }
    default: c.call = ctx.is_abbreviation(n) ? 0 : 1; break;
  }
  return c;
}

bool is_inverse_power(const Context& ctx, NodeId n) {
  if (ctx.op(n) != Op::Pow || ctx.op(ctx.children(n)[1]) != Op::Constant) return false;
  const double v = ctx.value(ctx.children(n)[1]);
  return v < 0.0 && v == std::nearbyint(v) && std::fabs(v) <= kMaxInlinePower;
}

}  // namespace

std::uint64_t OpCount::total() const {
  return sat_add(sat_add(add, mul), sat_add(div, call));
}

OpCount count_ops(const EquationList& list) {
  const Context& ctx = list.context();
  DagWalk reachable(ctx);
  std::uint64_t abbreviations = 0;
  auto mark = [&](NodeId root) {
    reachable.walk(root, [&](NodeId n) {
      if (!ctx.is_abbreviation(n)) return true;
      ++abbreviations;
      return false;
    });
  };
  for (const Assignment& a : list.assignments()) mark(a.value);
  for (const Output& o : list.outputs()) mark(o.value);

  std::vector<OpCount> tree(ctx.size());
  for (NodeId n = 0; n < ctx.size(); ++n) {
    if (!reachable.seen(n) || ctx.is_abbreviation(n)) continue;
    OpCount c = own_ops(ctx, n);
    for (NodeId k : ctx.children(n)) c += tree[k];
    // A standalone inverse power is written 1.0/(x*...), one division; inside a product it goes
    // below the product's single division line instead.
    if (is_inverse_power(ctx, n)) c.div = sat_add(c.div, 1);
    if (ctx.op(n) == Op::Mul) {
      for (NodeId k : ctx.children(n)) {
        if (is_inverse_power(ctx, k) && c.div > 0 && c.div != std::numeric_limits<std::uint64_t>::max()) --c.div;
      }
    }
    tree[n] = c;
  }
  OpCount total;
  total.call = abbreviations;
  auto add_root = [&](NodeId root) { total += tree[root]; };
  for (const Assignment& a : list.assignments()) add_root(a.value);
  for (const Output& o : list.outputs()) add_root(o.value);
  return total;
}

}  // namespace dydp::symbolic
