// In-extenso expansion: every auxiliary substituted back into the outputs, giving the classical
// non-recursive form of the same quantities, to count (op_count.hpp) what recursion saves.
#pragma once

#include "symbolic/equation_list.hpp"

namespace dydp::symbolic {

// A list without assignments whose outputs are the input's outputs with all auxiliaries
// substituted. In memory the result shares subexpressions (a DAG, linear in the input's size);
// written out or counted as trees it may be exponentially larger.
EquationList expand(const EquationList& list);

}  // namespace dydp::symbolic
