// Compaction against the list it came from: the same outputs (interpreter, random lists and a
// tangent list), every right-hand side within the line limit, no two assignments with equal
// right-hand sides, no node written twice, and seed-free derivative work moved to the primal part.
#include <gtest/gtest.h>

#include <unordered_set>

#include "eval_helpers.hpp"
#include "random_list.hpp"
#include "symbolic/compact.hpp"
#include "symbolic/differentiate.hpp"
#include "symbolic/eliminate.hpp"
#include "symbolic/op_count.hpp"

namespace dydp::symbolic {
namespace {

using testing::ArrayValues;
using testing::close;
using testing::make_random_list;
using testing::random_values;
using testing::run;

// Operations of one right-hand side as a tree (what one emitted line holds).
std::size_t line_ops(const Context& ctx, NodeId value) {
  EquationList one(const_cast<Context&>(ctx));
  one.add_output(Output{"v", value});
  return count_ops(one).total() - 0;
}

// Every non-atom node reached from more than one right-hand side or output, in a compacted list,
// is an error: compaction must have given it an auxiliary.
std::size_t nodes_written_twice(const EquationList& list) {
  const Context& ctx = list.context();
  std::vector<int> owner(ctx.size(), -1);
  std::size_t twice = 0;
  std::vector<NodeId> stack;
  auto walk = [&](NodeId root, int line) {
    stack.push_back(root);
    while (!stack.empty()) {
      const NodeId n = stack.back();
      stack.pop_back();
      const Op op = ctx.op(n);
      if (op == Op::Constant || op == Op::Symbol || ctx.is_abbreviation(n)) continue;
      // a negation or a constant coefficient times an atom costs nothing to repeat
      if (owner[n] >= 0 && owner[n] != line) {
        if (op != Op::Neg) ++twice;
        continue;
      }
      if (owner[n] == line) continue;
      owner[n] = line;
      for (NodeId c : ctx.children(n)) stack.push_back(c);
    }
  };
  int line = 0;
  for (const Assignment& a : list.assignments()) walk(a.value, line++);
  for (const Output& o : list.outputs()) walk(o.value, line++);
  return twice;
}

void expect_same_outputs(const EquationList& a, const EquationList& b, const ArrayValues<double>& values) {
  const std::vector<double> ya = run(Tape(a), values), yb = run(Tape(b), values);
  ASSERT_EQ(ya.size(), yb.size());
  for (std::size_t j = 0; j < ya.size(); ++j) EXPECT_TRUE(close(ya[j], yb[j], 1e-12)) << j << ": " << ya[j] << " " << yb[j];
}

TEST(Compact, RandomListsKeepTheirValuesAndBecomeSmallLines) {
  for (unsigned seed : {1u, 2u, 3u, 4u}) {
    Context ctx;
    EquationList list(ctx);
    make_random_list(list, 300, 12, seed);
    const EquationList plain = eliminate(list);
    CompactStats stats;
    const CompactOptions options{4};
    const EquationList c = compact(plain, options, &stats);
    ArrayValues<double> values(ctx);
    for (ArrayId a = 0; a < ctx.array_count(); ++a) values.values[a] = random_values(ctx.array(a).elements.size(), seed + 10 * a);
    expect_same_outputs(plain, c, values);
    std::unordered_set<NodeId> rhs;
    for (const Assignment& a : c.assignments()) {
      EXPECT_LE(line_ops(ctx, a.value), options.max_line_ops + 1) << ctx.symbol(a.target).name;
      EXPECT_TRUE(rhs.insert(a.value).second) << "two assignments read " << ctx.symbol(a.target).name;
    }
    EXPECT_EQ(nodes_written_twice(c), 0u);
    EXPECT_LE(count_ops(c).total(), count_ops(plain).total());
  }
}

TEST(Compact, SharedSubexpressionsBecomeOneAuxiliaryAndEqualAssignmentsMerge) {
  Context ctx;
  const ArrayId x = ctx.add_array("x", 3, SymbolKind::Input);
  const Expr a = ctx.element(x, 0), b = ctx.element(x, 1), c = ctx.element(x, 2);
  EquationList list(ctx);
  const Expr d = sin(a * b + c);  // printed inside both lengths below
  const Expr l1 = list.assign("L1", sqrt(d * d + 1.0));
  const Expr l2 = list.assign("L2", sqrt(d * d + 1.0));  // equal to L1
  const Expr s = list.assign("S", l1 * l2 + d);
  list.add_output("s", s);
  CompactStats stats;
  const EquationList out = compact(list, {}, &stats);
  EXPECT_EQ(stats.merged, 1u);
  EXPECT_EQ(nodes_written_twice(out), 0u);
  ArrayValues<double> values(ctx);
  values.values[x] = {0.3, -0.7, 1.1};
  expect_same_outputs(list, out, values);
  // sin(a*b + c) is computed once: one call for it, one sqrt
  EXPECT_EQ(count_ops(out).call, 2u);
}

TEST(Compact, TangentListsHoistSeedFreeWorkAndKeepTheirDerivatives) {
  Context ctx;
  EquationList list(ctx);
  const auto model = make_random_list(list, 200, 6, 7);
  const std::vector<ArrayId> arrays{model.q, model.qd};
  const EquationList t = tangent_list(list, arrays);
  CompactStats stats;
  const EquationList c = compact(t, {}, &stats);
  ASSERT_TRUE(c.has_split());
  EXPECT_EQ(c.primal_outputs(), t.primal_outputs());
  // the derivative part reads seeds in every assignment (the rest is primal work)
  for (std::size_t i = c.primal_assignments(); i < c.size(); ++i) {
    std::vector<NodeId> stack{c.assignments()[i].value};
    bool seeded = false;
    std::unordered_set<NodeId> derivative_targets;
    for (std::size_t k = c.primal_assignments(); k < i; ++k) derivative_targets.insert(c.assignments()[k].target);
    while (!stack.empty() && !seeded) {
      const NodeId n = stack.back();
      stack.pop_back();
      if (ctx.op(n) == Op::Symbol) {
        seeded = ctx.symbol(n).kind == SymbolKind::Seed || derivative_targets.count(n);
        continue;
      }
      for (NodeId k : ctx.children(n)) stack.push_back(k);
    }
    EXPECT_TRUE(seeded) << ctx.symbol(c.assignments()[i].target).name << " needs no seed";
  }
  ArrayValues<double> values(ctx);
  for (ArrayId a = 0; a < ctx.array_count(); ++a) values.values[a] = random_values(ctx.array(a).elements.size(), 40 + a);
  expect_same_outputs(t, c, values);
}

}  // namespace
}  // namespace dydp::symbolic
