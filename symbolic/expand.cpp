// Substitution of auxiliaries by their (already substituted) definitions, in list order,
// memoised per node so shared subexpressions are rebuilt once.
#include "symbolic/expand.hpp"

#include "symbolic/dag_walk.hpp"

#include <stdexcept>
#include <vector>

namespace dydp::symbolic {

EquationList expand(const EquationList& list) {
  Context& ctx = list.context();
  constexpr NodeId kUnset = 0xFFFFFFFFu;
  const std::size_t known = ctx.size();
  std::vector<NodeId> substituted(known, kUnset);
  std::vector<NodeId> stack;
  std::vector<NodeId> kids;

  // children first; a leaf (constant, symbol not assigned yet) stands for itself
  auto rebuild = [&](NodeId root) -> NodeId {
    walk_post_order(ctx, root, stack, [&](NodeId n) { return substituted[n] != kUnset; }, [&](NodeId n) {
      kids.clear();
      bool same = true;
      for (NodeId c : ctx.children(n)) {
        kids.push_back(substituted[c]);
        same = same && substituted[c] == c;
      }
      substituted[n] = same ? n : ctx.make(ctx.op(n), kids);
    });
    return substituted[root];
  };

  for (const Assignment& a : list.assignments()) {
    if (substituted[a.target] != kUnset) {
      throw std::invalid_argument("symbolic: expand: auxiliary '" + ctx.symbol(a.target).name +
                                  "' is read before it is assigned or assigned twice");
    }
    substituted[a.target] = rebuild(a.value);
  }
  EquationList result(ctx);
  for (const Output& o : list.outputs()) result.add_output(Output{o.name, rebuild(o.value)});
  if (list.has_split()) result.set_primal_split(0, list.primal_outputs());
  return result;
}

}  // namespace dydp::symbolic
