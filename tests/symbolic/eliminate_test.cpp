// Elimination keeps exactly the transitive needs of the outputs.
#include "symbolic/eliminate.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <set>
#include <unordered_map>

#include "eval_helpers.hpp"
#include "random_list.hpp"

namespace dydp::symbolic {
namespace {

// Independent oracle: the auxiliaries an expression reads, by plain recursion over the tree.
void reads(const Context& ctx, NodeId n, std::set<NodeId>& found) {
  if (ctx.is_symbol(n, SymbolKind::Aux)) {
    found.insert(n);
    return;
  }
  for (NodeId c : ctx.children(n)) reads(ctx, c, found);
}

std::set<NodeId> transitive_needs(const EquationList& list) {
  const Context& ctx = list.context();
  std::unordered_map<NodeId, NodeId> definition;
  for (const Assignment& a : list.assignments()) definition[a.target] = a.value;
  std::set<NodeId> needed, frontier;
  for (const Output& o : list.outputs()) reads(ctx, o.value, frontier);
  while (!frontier.empty()) {
    const NodeId v = *frontier.begin();
    frontier.erase(frontier.begin());
    if (!needed.insert(v).second) continue;
    std::set<NodeId> more;
    reads(ctx, definition.at(v), more);
    for (NodeId m : more) {
      if (!needed.count(m)) frontier.insert(m);
    }
  }
  return needed;
}

TEST(Eliminate, KeepsExactlyTheTransitiveNeedsOfRandomLists) {
  for (unsigned seed = 1; seed <= 6; ++seed) {
    Context ctx;
    EquationList list(ctx);
    testing::make_random_list(list, 400, 1 + seed % 4, seed);
    EliminationStats stats;
    const EquationList kept = eliminate(list, &stats);
    std::set<NodeId> kept_targets;
    for (const Assignment& a : kept.assignments()) kept_targets.insert(a.target);
    EXPECT_EQ(kept_targets, transitive_needs(list)) << "seed " << seed;
    EXPECT_EQ(stats.before, list.size());
    EXPECT_EQ(stats.after, kept.size());
    EXPECT_LT(stats.after, stats.before) << "random lists have dead assignments";
    // Order is preserved: kept assignments appear in the original relative order.
    std::unordered_map<NodeId, std::size_t> position;
    for (std::size_t i = 0; i < list.size(); ++i) position[list.assignments()[i].target] = i;
    for (std::size_t i = 1; i < kept.size(); ++i) {
      EXPECT_LT(position[kept.assignments()[i - 1].target], position[kept.assignments()[i].target]);
    }
    // Same outputs, bit for bit.
    testing::ArrayValues<double> x(ctx);
    for (auto& v : x.values) v = testing::random_values(v.size(), seed + 100);
    EXPECT_EQ(testing::run(Tape(list), x), testing::run(Tape(kept), x));
  }
}

TEST(Eliminate, DropsWhatNoOutputReads) {
  Context ctx;
  const ArrayId q = ctx.add_array("q", 2, SymbolKind::Input);
  EquationList list(ctx);
  const Expr a = list.assign("A", ctx.element(q, 0) * ctx.element(q, 1));
  const Expr b = list.assign("B", sin(a) + ctx.element(q, 0));
  list.assign("DEAD", cos(b) * a);
  const Expr c = list.assign("C", a * a + 1.0);
  list.add_output("c", c);
  EliminationStats stats;
  const EquationList kept = eliminate(list, &stats);
  EXPECT_EQ(stats.before, 4u);
  EXPECT_EQ(stats.after, 2u);
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_EQ(kept.assignments()[0].target, a.id());
  EXPECT_EQ(kept.assignments()[1].target, c.id());
  const EquationList nothing = eliminate(EquationList(ctx));
  EXPECT_EQ(nothing.size(), 0u);
}

}  // namespace
}  // namespace dydp::symbolic
