// Compaction: an equation list rewritten as a recursive scheme in the strict sense, the form the
// emitter prints. Every expression node used more than once over the whole list becomes one
// auxiliary, assignments with equal right-hand sides are one, and no right-hand side exceeds a
// few operations (`OM23 = OM22*C3 + OM32*S3`). For a differentiated list, what does not depend on
// the seeds is moved into the primal part, so that it is evaluated once and not per direction.
#pragma once

#include <cstddef>

#include "symbolic/equation_list.hpp"

namespace dydp::symbolic {

struct CompactOptions {
  // Largest number of operations written on one line; larger right-hand sides are split.
  std::size_t max_line_ops = 6;
};

struct CompactStats {
  std::size_t assignments_before = 0;
  std::size_t assignments_after = 0;
  std::size_t merged = 0;  // assignments whose right-hand side equalled an earlier one's
  std::size_t shared = 0;  // auxiliaries introduced for nodes used more than once
  std::size_t split = 0;   // auxiliaries introduced to keep lines small
  std::size_t hoisted = 0; // seed-free derivative assignments moved into the primal part
};

// The same function (equal outputs for every input, up to the rounding of a different
// association of sums and products), written compactly. Outputs keep their names and order;
// the primal split of a differentiated list is carried over.
EquationList compact(const EquationList& list, const CompactOptions& options = {},
                     CompactStats* stats = nullptr);

}  // namespace dydp::symbolic
