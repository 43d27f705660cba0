// Tangents in blocks (symbolic/grouped_tangent) on random lists, against complex-step
// derivatives of the interpreter: each block's outputs are the derivatives along its own seeds,
// restricted to its elements (seeds written into the other elements are not read); its
// derivative assignments are contiguous, in block order after the primal, and read no other
// block's seeds or auxiliaries.
#include "symbolic/grouped_tangent.hpp"

#include <gtest/gtest.h>

#include <set>

#include "eval_helpers.hpp"
#include "random_list.hpp"

namespace dydp::symbolic {
namespace {

using testing::ArrayValues;
using cplx = std::complex<double>;
constexpr double kStep = 1e-30;

TEST(GroupedTangent, EachBlockIsTheDerivativeAlongItsOwnSeedsOnly) {
  for (unsigned seed = 31; seed <= 34; ++seed) {
    Context ctx;
    EquationList list(ctx);
    const auto model = testing::make_random_list(list, 300, 5, seed);
    const BlockSeeds specs[] = {{"all of q and p", {{model.q, {}}, {model.p, {}}}},
                                {"q1 and q3", {{model.q, {1, 3}}}},
                                {"qd2 and p0", {{model.qd, {2}}, {model.p, {0}}}}};
    const GroupedTangent grouped = grouped_tangent(list, specs);
    ASSERT_EQ(grouped.blocks.size(), 3u);
    const std::size_t n = list.outputs().size();
    ASSERT_EQ(grouped.list.outputs().size(), 4 * n);
    ASSERT_EQ(grouped.list.primal_outputs(), n);

    // layout: the blocks follow the primal and each other; a block reads only its own seeds
    // and derivative auxiliaries
    std::size_t at = grouped.list.primal_assignments();
    std::vector<int> block_of_aux(ctx.size(), -1);
    for (std::size_t b = 0; b < grouped.blocks.size(); ++b) {
      const TangentBlock& block = grouped.blocks[b];
      EXPECT_EQ(block.assignments_begin, at);
      EXPECT_EQ(block.outputs_begin, n + b * n);
      EXPECT_EQ(block.outputs_end, n + (b + 1) * n);
      at = block.assignments_end;
      std::set<ArrayId> own;
      for (const auto& [array, seed_array] : block.seeds) own.insert(seed_array);
      for (std::size_t k = block.assignments_begin; k < block.assignments_end; ++k) {
        const Assignment& a = grouped.list.assignments()[k];
        block_of_aux[a.target] = static_cast<int>(b);
        std::vector<NodeId> stack{a.value};
        while (!stack.empty()) {
          const NodeId x = stack.back();
          stack.pop_back();
          if (ctx.op(x) == Op::Symbol) {
            const Symbol& s = ctx.symbol(x);
            if (s.kind == SymbolKind::Seed) EXPECT_TRUE(own.count(s.array)) << "block " << b << " reads " << s.name;
            if (s.kind == SymbolKind::Aux && block_of_aux[x] >= 0) EXPECT_EQ(block_of_aux[x], static_cast<int>(b)) << s.name;
            continue;
          }
          for (NodeId c : ctx.children(x)) stack.push_back(c);
        }
      }
    }
    EXPECT_EQ(at, grouped.list.size());

    // values: every seed element random, the blocks' restrictions decide what is read
    ArrayValues<double> x(ctx);
    for (std::size_t a = 0; a < x.values.size(); ++a)
      x.values[a] = testing::random_values(x.values[a].size(), seed * 37 + static_cast<unsigned>(a), 1.2);
    const Tape tape(grouped.list), primal(list);
    const std::vector<double> values = testing::run(tape, x);
    for (std::size_t b = 0; b < grouped.blocks.size(); ++b) {
      ArrayValues<cplx> xc = testing::to_complex(x);
      for (const BlockSeeds::Seeded& s : specs[b].seeds) {
        const ArrayId seed_array = grouped.blocks[b].seeds[&s - specs[b].seeds.data()].second;
        std::vector<std::uint32_t> elements = s.elements;
        if (elements.empty())
          for (std::uint32_t i = 0; i < ctx.array(s.array).elements.size(); ++i) elements.push_back(i);
        for (std::uint32_t i : elements) xc.values[s.array][i] += cplx(0.0, kStep * x.values[seed_array][i]);
      }
      const auto cs = testing::run(primal, xc);
      for (std::size_t j = 0; j < n; ++j) {
        EXPECT_TRUE(testing::close(values[j], cs[j].real(), 1e-13));
        EXPECT_TRUE(testing::close(values[grouped.blocks[b].outputs_begin + j], cs[j].imag() / kStep, 1e-12))
            << "seed " << seed << ", block " << b << ", output " << j << ": " << values[grouped.blocks[b].outputs_begin + j]
            << " against " << cs[j].imag() / kStep;
      }
    }
  }
}

}  // namespace
}  // namespace dydp::symbolic
