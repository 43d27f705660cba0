// A tangent in blocks: one primal, then several derivative parts, each seeded on its own subset
// of the inputs. A multibody direction that moves one suspension corner seeds only that corner's
// coordinates; differentiated with every other seed known to be zero, its derivative part keeps
// only what that corner reaches (on the sedan a fifth of a full direction's operations). The
// emitter (emit_grouped_tangent) writes the primal once and loops each block over its own
// directions.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "symbolic/equation_list.hpp"

namespace dydp::symbolic {

// What one block is seeded on: for each seeded array, the elements that may move (all of them
// when `elements` is empty); the others have derivative zero in this block.
struct BlockSeeds {
  std::string label;  // for comments and statistics: "full", "velocity", "group 2 position"
  struct Seeded {
    ArrayId array;
    std::vector<std::uint32_t> elements;  // empty: every element
  };
  std::vector<Seeded> seeds;
};

// A block of the built list: the Seed array it reads for each seeded array (its own, so that no
// derivative node is shared with another block), and its ranges in the list.
struct TangentBlock {
  std::string label;
  std::vector<std::pair<ArrayId, ArrayId>> seeds;  // (seeded array, this block's Seed array)
  std::size_t assignments_begin = 0, assignments_end = 0;  // derivative assignments
  std::size_t outputs_begin = 0, outputs_end = 0;          // derivative outputs
};

struct GroupedTangent {
  EquationList list;  // primal part, then the blocks' derivative assignments in block order
  std::vector<TangentBlock> blocks;
};

// The list's primal once, then for each block the derivatives of every output of `list` along
// that block's seeds; eliminated and compacted (seed-free parts hoisted into the primal), the
// derivative assignments grouped by block. Outputs: the list's own, then block by block the
// derivative of each of them.
GroupedTangent grouped_tangent(const EquationList& list, std::span<const BlockSeeds> blocks);

}  // namespace dydp::symbolic
