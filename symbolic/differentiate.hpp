// Recursive differentiation: for a direction P, every assignment A = f(B, C) yields
// A_P = (df/dB) B_P + (df/dC) C_P + (df/dP), built with the simplifying constructors, so zero
// derivatives vanish and are never emitted. Differentiating a differentiated list gives second order.
#pragma once

#include <span>
#include <string>
#include <utility>
#include <vector>

#include "symbolic/equation_list.hpp"

namespace dydp::symbolic {

// A direction of differentiation: the derivative of each listed symbol along it (every other
// input, parameter or seed symbol has derivative zero).
struct Direction {
  std::string suffix;  // derivative auxiliaries are named `A_<suffix>`
  std::string label;   // derivative outputs are named `d(y)/d(<label>)`; the suffix when empty
  std::vector<std::pair<NodeId, NodeId>> seeds;  // (symbol, its derivative)
};

// d/d(symbol): the symbol has derivative 1; named after the symbol.
Direction along(Expr symbol);
// The generic direction of a tangent function: element i of each array has derivative
// `d<array>[i]`, element i of the array's Seed array (see Context::seed_array). Suffix "d",
// label "seed".
Direction seeded(Context& context, std::span<const ArrayId> arrays);

// The input list (all of it, as the primal part) followed by the derivative assignments, one
// block per direction in the given order. Outputs: the input's outputs, then for each direction
// the derivative of every input output, direction-major (output j of direction k at
// primal_outputs + k * n + j with n the number of input outputs). The result is not eliminated.
EquationList differentiate(const EquationList& list, std::span<const Direction> directions);

// The list a tangent function evaluates: the primal once, then one seeded direction over
// `arrays`, whose derivative part is repeated per direction at run time. Eliminated.
EquationList tangent_list(const EquationList& list, std::span<const ArrayId> arrays);

}  // namespace dydp::symbolic
