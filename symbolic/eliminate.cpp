// Backward marking from the outputs: an assignment is kept when its target is needed; its
// right-hand side then makes the auxiliaries it reads needed. Each expression node is visited at
// most once over the whole sweep, since the auxiliaries a node reads never change.
#include "symbolic/eliminate.hpp"

#include "symbolic/dag_walk.hpp"

#include <vector>

namespace dydp::symbolic {

EquationList eliminate(const EquationList& list, EliminationStats* stats) {
  const Context& ctx = list.context();
  std::vector<char> needed(ctx.size(), 0);
  DagWalk walk(ctx);
  auto mark_from = [&](NodeId root) {
    walk.walk(root, [&](NodeId n) {
      if (ctx.op(n) != Op::Symbol) return true;
      if (ctx.symbol(n).kind == SymbolKind::Aux) needed[n] = 1;
      return false;
    });
  };
  for (const Output& o : list.outputs()) mark_from(o.value);
  const auto& assignments = list.assignments();
  std::vector<char> keep(assignments.size(), 0);
  for (std::size_t i = assignments.size(); i-- > 0;) {
    if (!needed[assignments[i].target]) continue;
    keep[i] = 1;
    mark_from(assignments[i].value);
  }

  EquationList result(list.context());
  std::size_t kept_primal = 0;
  for (std::size_t i = 0; i < assignments.size(); ++i) {
    if (!keep[i]) continue;
    result.append(assignments[i]);
    if (list.has_split() && i < list.primal_assignments()) ++kept_primal;
  }
  for (const Output& o : list.outputs()) result.add_output(o);
  if (list.has_split()) result.set_primal_split(kept_primal, list.primal_outputs());
  if (stats) *stats = EliminationStats{assignments.size(), result.size()};
  return result;
}

}  // namespace dydp::symbolic
