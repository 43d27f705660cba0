// The Jacobian df/dx of a diagram from its structure. Which states reach which derivatives:
// a block's states reach its own derivatives and quadratures and every one of its outputs; an
// output reaches the inputs its connections feed, hence those blocks' derivatives and
// quadratures and the outputs that read that input directly (Block::output_reads). Columns
// whose rows do not meet are seeded together (greedy colouring in state order), so that a
// Jacobian costs one tangent pass per colour; the compressed tangents are then scattered back
// over each column's rows.
#pragma once

#include <vector>

#include "engine/evaluation/evaluator.hpp"
#include "engine/framework/block.hpp"
#include "engine/framework/diagram.hpp"

namespace dydp::engine {

class JacobianColouring {
 public:
  explicit JacobianColouring(const Diagram& d);

  int columns() const { return nx_; }
  int colours() const { return colours_; }
  int colour_of(int column) const { return colour_[column]; }
  /// Whether derivative row `row` of state column `column` can be nonzero: a state row
  /// (row < num_states) or a quadrature row (num_states + its index).
  bool reaches(int column, int row) const;

  /// df/dx (J: num_states rows) and dqdot/dx (JQ: num_quadratures rows; null data: not wanted)
  /// at (t, x), every column written: one tangent pass over the colours, or over the identity
  /// when no two columns share a colour (the same pass as before colouring, bit for bit).
  void evaluate(Evaluator& ev, double t, const double* x, DirView J, DirView JQ);

 private:
  int nx_ = 0, nq_ = 0, colours_ = 0;
  std::vector<int> colour_;
  std::vector<std::vector<int>> rows_;  // per column, sorted: state rows, then nx + quadrature rows
  std::vector<double> seeds_;           // nx x colours (the identity when colours == nx)
  std::vector<double> compressed_x_, compressed_q_;
};

}  // namespace dydp::engine
