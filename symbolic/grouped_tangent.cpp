#include "symbolic/grouped_tangent.hpp"

#include <algorithm>
#include <stdexcept>

#include "symbolic/compact.hpp"
#include "symbolic/differentiate.hpp"
#include "symbolic/eliminate.hpp"

namespace dydp::symbolic {
namespace {

constexpr int kPrimal = -1;
constexpr int kUnknown = -2;

// The block whose seeds each node reads (kPrimal for none), memoised per node. Symbols are set
// beforehand: the blocks' Seed elements, then each derivative auxiliary as it is classified.
class BlockOf {
 public:
  explicit BlockOf(const Context& ctx) : ctx_(ctx), block_(ctx.size(), kUnknown) {}

  void set(NodeId n, int block) { block_.at(n) = block; }

  int operator()(NodeId n) {
    int& known = block_.at(n);
    if (known != kUnknown) return known;
    int found = kPrimal;
    if (ctx_.op(n) != Op::Symbol) {
      for (NodeId c : ctx_.children(n)) {  // no node is built here: the span stays valid
        const int b = (*this)(c);
        if (b == kPrimal) continue;
        if (found != kPrimal && found != b)
          throw std::logic_error("symbolic: a derivative reads the seeds of two blocks");
        found = b;
      }
    }
    return known = found;  // nor does block_ grow
  }

 private:
  const Context& ctx_;
  std::vector<int> block_;
};

}  // namespace

GroupedTangent grouped_tangent(const EquationList& list, std::span<const BlockSeeds> specs) {
  Context& ctx = list.context();
  std::vector<Direction> directions;
  std::vector<TangentBlock> blocks;
  for (std::size_t b = 0; b < specs.size(); ++b) {
    const std::string suffix = "b" + std::to_string(b);
    Direction dir{suffix, specs[b].label, {}};
    TangentBlock block;
    block.label = specs[b].label;
    for (const BlockSeeds::Seeded& s : specs[b].seeds) {
      // a Seed array of this block's own (the array's first Seed array stays the generic one)
      const ArrayId seed = ctx.add_seed_array(s.array, suffix);
      block.seeds.emplace_back(s.array, seed);
      const std::size_t size = ctx.array(s.array).elements.size();
      std::vector<std::uint32_t> all;
      const std::vector<std::uint32_t>* elements = &s.elements;
      if (s.elements.empty()) {
        for (std::uint32_t i = 0; i < size; ++i) all.push_back(i);
        elements = &all;
      }
      for (std::uint32_t i : *elements) dir.seeds.emplace_back(ctx.array(s.array).elements.at(i), ctx.array(seed).elements.at(i));
    }
    directions.push_back(std::move(dir));
    blocks.push_back(std::move(block));
  }
  const EquationList compacted = compact(eliminate(differentiate(compact(list), directions)));

  // Each derivative assignment's block, from the seeds it reads (directly or through earlier
  // derivative auxiliaries); then the derivative part stably ordered by block, which keeps every
  // assignment after those it reads (a block reads only the primal part and itself).
  BlockOf block_of(ctx);
  for (std::size_t b = 0; b < blocks.size(); ++b)
    for (const auto& [array, seed] : blocks[b].seeds)
      for (NodeId e : ctx.array(seed).elements) block_of.set(e, static_cast<int>(b));
  const std::size_t primal = compacted.primal_assignments();
  std::vector<std::vector<Assignment>> by_block(blocks.size());
  for (std::size_t i = primal; i < compacted.size(); ++i) {
    const Assignment& a = compacted.assignments()[i];
    const int b = block_of(a.value);
    if (b == kPrimal) throw std::logic_error("symbolic: a seed-free assignment in a derivative part");
    block_of.set(a.target, b);
    by_block[static_cast<std::size_t>(b)].push_back(a);
  }
  GroupedTangent result{EquationList(ctx), std::move(blocks)};
  for (std::size_t i = 0; i < primal; ++i) result.list.append(compacted.assignments()[i]);
  for (std::size_t b = 0; b < by_block.size(); ++b) {
    result.blocks[b].assignments_begin = result.list.size();
    for (const Assignment& a : by_block[b]) result.list.append(a);
    result.blocks[b].assignments_end = result.list.size();
  }
  for (const Output& o : compacted.outputs()) result.list.add_output(o);
  const std::size_t per_block = list.outputs().size();
  const std::size_t primal_outputs = compacted.primal_outputs();
  for (std::size_t b = 0; b < result.blocks.size(); ++b) {
    result.blocks[b].outputs_begin = primal_outputs + b * per_block;
    result.blocks[b].outputs_end = primal_outputs + (b + 1) * per_block;
    // an output reads no other block's derivatives
    for (std::size_t j = result.blocks[b].outputs_begin; j < result.blocks[b].outputs_end; ++j) {
      const int r = block_of(compacted.outputs()[j].value);
      if (r != kPrimal && r != static_cast<int>(b)) throw std::logic_error("symbolic: an output reads another block");
    }
  }
  result.list.set_primal_split(primal, primal_outputs);
  return result;
}

}  // namespace dydp::symbolic
