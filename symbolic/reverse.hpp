// Reverse-mode (adjoint) differentiation: for output weights w, every assignment A = f(B, C),
// taken in reverse order, gives its readers' contributions to A_b, the adjoint of A (assigned
// once), and passes A_b (df/dB) to B_b and A_b (df/dC) to C_b. The list evaluates the
// vector-Jacobian product w^T J of all outputs at the cost of a few primal evaluations, whatever
// the number of inputs. Zero adjoints vanish and are never emitted, as in symbolic/differentiate.hpp.
#pragma once

#include <span>

#include "symbolic/equation_list.hpp"

namespace dydp::symbolic {

// The list an adjoint function evaluates: the primal once (all of it, as the primal part), then
// the reverse sweep. It reads the weights w, one per output of `list`, from the context's
// weight_array(list.outputs().size()). Outputs: the outputs of `list`, then w^T d(outputs)/dx
// for every element x of `arrays`, in array order, named `bar(x)`. Within each right-hand side,
// the adjoints of its expression nodes are accumulated in reverse topological order; those that
// feed more than one operand are auxiliaries of their own (`A_b_1`, ...). A node shared by several
// right-hand sides is propagated once, with the sum of their contributions. Branches follow
// differentiate.hpp (min, max and select pass the adjoint to the operand chosen; sign passes
// none). Eliminated.
EquationList adjoint_list(const EquationList& list, std::span<const ArrayId> arrays);

}  // namespace dydp::symbolic
