// In-extenso expansion computes the same outputs as the recursive list, and costs more.
#include "symbolic/expand.hpp"

#include <gtest/gtest.h>

#include "eval_helpers.hpp"
#include "random_list.hpp"
#include "symbolic/eliminate.hpp"
#include "symbolic/op_count.hpp"

namespace dydp::symbolic {
namespace {

TEST(Expand, SameOutputsAsTheRecursiveList) {
  for (unsigned seed = 1; seed <= 4; ++seed) {
    Context ctx;
    EquationList list(ctx);
    testing::make_random_list(list, 120, 4, seed);
    const EquationList expanded = expand(eliminate(list));
    EXPECT_EQ(expanded.size(), 0u);
    ASSERT_EQ(expanded.outputs().size(), list.outputs().size());
    testing::ArrayValues<double> x(ctx);
    for (auto& v : x.values) v = testing::random_values(v.size(), seed + 3);
    const auto a = testing::run(Tape(list), x);
    const auto b = testing::run(Tape(expanded), x);
    for (std::size_t j = 0; j < a.size(); ++j) {
      EXPECT_TRUE(testing::close(a[j], b[j], 1e-10)) << "output " << j << ": " << a[j] << " vs " << b[j];
    }
  }
}

// A chain of planar rotations: each angular velocity reuses the previous one. Expanded, every
// output repeats the whole chain, so the in-extenso form costs far more operations.
TEST(Expand, RecursionSavesOperationsOnAChain) {
  Context ctx;
  const ArrayId q = ctx.add_array("q", 8, SymbolKind::Input);
  const ArrayId qd = ctx.add_array("qd", 8, SymbolKind::Input);
  EquationList list(ctx);
  Expr wx = ctx.zero(), wy = ctx.zero();
  for (std::size_t i = 0; i < 8; ++i) {
    const Expr c = cos(ctx.element(q, i)), s = sin(ctx.element(q, i));
    const Expr nx = list.assign("OM1" + std::to_string(i + 1), c * wx + s * wy + ctx.element(qd, i));
    const Expr ny = list.assign("OM2" + std::to_string(i + 1), c * wy - s * wx);
    wx = nx;
    wy = ny;
  }
  list.add_output("omega_x", wx);
  list.add_output("omega_y", wy);
  const OpCount recursive = count_ops(list);
  const OpCount extenso = count_ops(expand(list));
  EXPECT_GT(extenso.total(), 4 * recursive.total());
  EXPECT_EQ(extenso.call, recursive.call) << "abbreviations are counted once in both forms";
}

TEST(OpCount, CountsWhatTheEmitterWrites) {
  Context ctx;
  const ArrayId q = ctx.add_array("q", 3, SymbolKind::Input);
  const Expr a = ctx.element(q, 0), b = ctx.element(q, 1), c = ctx.element(q, 2);
  EquationList list(ctx);
  list.add_output("y", a * b - c / (a * a) + sqrt(b) + sin(c) * cos(c));
  // a*b - c/(a*a) + sqrt(b) + S3*C3: 3 add, 3 mul, 1 div, 1 sqrt + S3 + C3
  const OpCount ops = count_ops(list);
  EXPECT_EQ(ops.add, 3u);
  EXPECT_EQ(ops.mul, 3u);
  EXPECT_EQ(ops.div, 1u);
  EXPECT_EQ(ops.call, 3u);
}

}  // namespace
}  // namespace dydp::symbolic
