// A block function's local Jacobian from the block's own tangent, and its transpose applied to
// weights: what Block's default adjoints do (block_adjoint.cpp), and what the evaluator keeps
// per value point so that the adjoint passes at one (t, x) (a backward Newton iteration, then
// the gradient's quadrature) build each block's Jacobian once.
#pragma once

#include <functional>
#include <vector>

#include "engine/framework/block.hpp"

namespace dydp::engine {

enum class BlockFunction { outputs, derivatives, quadratures, initial_state };

/// J: rows of the function (output ports' elements in port order, or xdot, qdot, x0) by columns
/// [the block's states | the elements of the chosen inputs | parameter columns], column c at
/// values + c * rows.
struct LocalJacobian {
  int rows = 0;
  int state_columns = 0;           ///< 0 or the block's states
  std::vector<int> input_first;    ///< per input port: its first column, or -1
  int parameter_first = 0;
  int parameter_columns = 0;
  std::vector<double> values;
  int columns() const { return parameter_first + parameter_columns; }
};

/// J of function fn of b at e along: its states (with `states`), the inputs with inputs[k]
/// (and ready at e), and the p_columns columns of parameter seeds p_seeds (ld = the block's
/// parameter count; none when p_columns == 0 or p_seeds is zero).
LocalJacobian local_jacobian(const Block& b, BlockFunction fn, const Eval& e, bool states,
                             const std::vector<bool>& inputs, int p_columns, ConstDirView p_seeds);

/// a += w^T J for every wanted view of a that J has columns for; weight(r, m): row r's weight in
/// adjoint direction m.
void add_transpose_product(const Block& b, const LocalJacobian& J, const std::function<double(int, int)>& weight,
                           const Adjoint& a);

/// The rows of an outputs Jacobian weighted by per-port views (null data: zero), as `weight`.
std::function<double(int, int)> output_weights(const Block& b, const ConstDirView* w);

}  // namespace dydp::engine
