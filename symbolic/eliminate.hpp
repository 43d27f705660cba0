// Elimination: keeps exactly the assignments the flagged outputs need, transitively, by one
// backward marking sweep over the list (linear in the size of the list and its expressions).
#pragma once

#include <cstddef>

#include "symbolic/equation_list.hpp"

namespace dydp::symbolic {

struct EliminationStats {
  std::size_t before = 0;  // assignments in the input list
  std::size_t after = 0;   // assignments kept
};

// The list restricted to what its outputs need, in the original order. The primal split of a
// differentiated list is carried over.
EquationList eliminate(const EquationList& list, EliminationStats* stats = nullptr);

}  // namespace dydp::symbolic
