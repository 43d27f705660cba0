// Reverse-mode differentiation of an equation list: forward sweeps mark what depends on the
// differentiated arrays and which expression nodes several right-hand sides share, one backward
// sweep over the assignments accumulates the adjoints. Each right-hand side is walked in reverse
// topological order of its own nodes; the adjoints of auxiliaries, inputs, sin/cos abbreviations
// and shared nodes are lists of contributions, summed when they are complete. The pass is linear
// in the size of the list and its expressions (an n-ary product costs n^2, as in forward mode).
#include "symbolic/reverse.hpp"

#include "symbolic/dag_walk.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "symbolic/eliminate.hpp"
#include "symbolic/node_builder.hpp"

namespace dydp::symbolic {
namespace {

constexpr std::uint32_t kNone = 0xFFFFFFFFu;

class Adjoint : NodeBuilder {
 public:
  // `known_nodes`: the context's size when the primal list was complete (every node it reads).
  Adjoint(Context& ctx, EquationList& out, std::size_t known_nodes)
      : NodeBuilder(ctx), out_(out), active_(known_nodes, 0), stamp_(known_nodes, 0), position_(known_nodes, kNone),
        search_(ctx), first_root_(known_nodes, kNone), shared_(known_nodes, 0), zero_(ctx.constant(0.0).id()),
        one_(ctx.constant(1.0).id()) {}

  // --- activity: does a node depend on the differentiated arrays? ------------------------------
  void set_active(NodeId symbol, bool active) { active_.at(symbol) = active ? kActive : kInactive; }
  // Marks the nodes of `root` (call in list order, so that the auxiliaries it reads are marked).
  bool mark(NodeId root) {
    order(root, false);
    for (NodeId n : order_) {
      bool any = false;
      for (NodeId c : ctx_.children(n)) any = any || active(c);
      active_[n] = any ? kActive : kInactive;
    }
    return active(root);
  }
  bool active(NodeId n) const {
    if (n >= active_.size()) return false;
    if (ctx_.is_abbreviation(n)) return active(ctx_.children(n)[0]);
    return active_[n] == kActive;
  }

  // --- nodes shared between right-hand sides ----------------------------------------------------
  // A node that several right-hand sides read (hash-consing shares equal subexpressions) collects
  // its adjoint from all of them, as an auxiliary does, and is propagated once, after the first of
  // them in list order: otherwise each reader would propagate its own share through it again.
  // Call with every root (right-hand side, then output) in list order; `index`: the root's.
  void find_shared(NodeId root, std::uint32_t index) {
    if (!active(root) || is_leaf(root)) return;
    if (pending_.size() <= index) pending_.resize(index + 1);
    search_.restart();
    search_.walk(root, [&](NodeId n) {
      if (!active(n) || is_leaf(n)) return false;
      if (first_root_[n] != kNone && first_root_[n] != index) {
        // read by an earlier root: its operands are reached through it
        if (!shared_[n]) pending_[first_root_[n]].push_back(n);
        shared_[n] = 1;
        return false;
      }
      first_root_[n] = index;
      return true;
    });
  }

  // Propagates the shared nodes first read by root `index`, whose adjoints are now complete;
  // parents (larger ids) before their operands.
  void propagate_shared(std::uint32_t index, const std::string& name) {
    if (index >= pending_.size()) return;
    std::vector<NodeId> nodes = std::move(pending_[index]);
    std::sort(nodes.begin(), nodes.end(), [](NodeId a, NodeId b) { return a > b; });
    for (NodeId n : nodes) {
      const NodeId g = take(n);
      if (g != zero_) walk(n, g, name);
    }
  }

  // --- the backward sweep ----------------------------------------------------------------------
  // The completed adjoint of a leaf (auxiliary, input, abbreviation): the sum of its contributions.
  NodeId take(NodeId leaf) {
    auto it = terms_.find(leaf);
    if (it == terms_.end()) return zero_;
    const NodeId sum = ctx_.make(Op::Add, it->second);
    terms_.erase(it);
    return sum;
  }

  // Passes `adjoint`, the adjoint of `root`, to the leaves and shared nodes `root` reads.
  // `name`: of the auxiliaries that hold intermediate adjoints.
  void propagate(NodeId root, NodeId adjoint, const std::string& name) {
    if (adjoint == zero_ || !active(root)) return;
    if (is_leaf(root) || shared_[root]) {
      give(root, adjoint);
      return;
    }
    walk(root, adjoint, name);
  }

  // The abbreviations' adjoints, passed to their arguments (once every contribution is in).
  void propagate_abbreviations() {
    std::sort(abbreviations_.begin(), abbreviations_.end());
    for (NodeId s : abbreviations_) {
      const NodeId g = take(s);
      if (g == zero_) continue;
      const NodeId x = ctx_.children(s)[0];
      give(x, ctx_.op(s) == Op::Sin ? mul(g, fn(Op::Cos, x)) : neg(mul(g, fn(Op::Sin, x))));
    }
    abbreviations_.clear();
  }

 private:
  // Reverse accumulation over the nodes of `root` (a non-leaf) down to leaves and shared nodes.
  void walk(NodeId root, NodeId adjoint, const std::string& name) {
    order(root, true);
    const std::vector<NodeId> nodes = order_;  // a copy: order() is not reentrant
    node_terms_.assign(nodes.size(), {});
    for (std::size_t k = 0; k < nodes.size(); ++k) position_[nodes[k]] = static_cast<std::uint32_t>(k);
    node_terms_.back().push_back(adjoint);  // the root is last in post-order
    for (std::size_t k = nodes.size(); k-- > 0;) {
      if (node_terms_[k].empty()) continue;
      const NodeId g = ctx_.make(Op::Add, node_terms_[k]);
      if (g != zero_) rule(nodes[k], g, name);
    }
    for (NodeId n : nodes) position_[n] = kNone;
  }

  // An adjoint read more than once: an auxiliary, unless trivial.
  NodeId share(NodeId value, const std::string& name) { return out_.assign(name, ctx_.expr(value)).id(); }

  // Symbols and abbreviations collect their adjoints across right-hand sides; constants have none.
  bool is_leaf(NodeId n) const {
    return ctx_.op(n) == Op::Constant || ctx_.op(n) == Op::Symbol || ctx_.is_abbreviation(n);
  }

  // A contribution to the adjoint of `n`, an operand of the node being propagated.
  void give(NodeId n, NodeId term) {
    if (term == zero_ || !active(n)) return;
    if (position_[n] != kNone) {
      node_terms_[position_[n]].push_back(term);
      return;
    }
    auto [it, inserted] = terms_.try_emplace(n);
    if (inserted && ctx_.is_abbreviation(n)) abbreviations_.push_back(n);
    it->second.push_back(term);
  }

  // The nodes of `root` above its leaves in post-order (operands first) into order_: when
  // `active_only`, the active ones down to the shared nodes (but `root`), else those not marked
  // yet.
  void order(NodeId root, bool active_only) {
    order_.clear();
    if (is_leaf(root)) return;
    ++current_stamp_;
    auto eligible = [&](NodeId n) {
      if (is_leaf(n) || stamp_[n] == current_stamp_) return false;
      return active_only ? active_[n] == kActive && (!shared_[n] || n == root) : active_[n] == kUnknown;
    };
    if (!eligible(root)) return;
    stamp_[root] = current_stamp_;
    stack_.assign(1, {root, 0});
    while (!stack_.empty()) {
      const NodeId n = stack_.back().first;
      const std::uint32_t i = stack_.back().second;
      const auto kids = ctx_.children(n);
      if (i < kids.size()) {
        ++stack_.back().second;
        const NodeId c = kids[i];
        if (eligible(c)) {
          stamp_[c] = current_stamp_;
          stack_.emplace_back(c, 0);
        }
      } else {
        order_.push_back(n);
        stack_.pop_back();
      }
    }
  }

  // Passes g, the complete adjoint of the non-leaf node n, to its operands.
  void rule(NodeId n, NodeId g, const std::string& name) {
    const Op op = ctx_.op(n);
    // a copy: building nodes may move the context's children storage
    const std::vector<NodeId> kids(ctx_.children(n).begin(), ctx_.children(n).end());
    std::size_t readers = 0;  // operands that receive a contribution
    for (std::size_t i = 0; i < kids.size(); ++i) {
      if (!(op == Op::Select && i == 0) && op != Op::Sign && active(kids[i])) ++readers;
    }
    const bool both = readers == 2 && kids.size() == 2;
    switch (op) {
      case Op::Add: {
        if (readers > 1) g = share(g, name);
        for (NodeId k : kids) give(k, g);
        return;
      }
      case Op::Mul: {
        // d(prod f_j)/d f_i = prod_{j != i} f_j
        if (readers > 1) g = share(g, name);
        std::vector<NodeId> factors;
        for (std::size_t i = 0; i < kids.size(); ++i) {
          if (!active(kids[i])) continue;
          factors.assign(1, g);
          for (std::size_t j = 0; j < kids.size(); ++j) {
            if (j != i) factors.push_back(kids[j]);
          }
          give(kids[i], ctx_.make(Op::Mul, factors));
        }
        return;
      }
      case Op::Neg: give(kids[0], neg(g)); return;
      case Op::Div: {
        // a/b: a_b += g/b, b_b -= (g/b) (a/b)
        const NodeId a = kids[0], b = kids[1];
        const NodeId t = both ? share(div(g, b), name) : div(g, b);
        give(a, t);
        give(b, neg(mul(t, n)));
        return;
      }
      case Op::Pow: {
        const NodeId x = kids[0], y = kids[1];
        if (ctx_.op(y) == Op::Constant) {
          // e x^(e-1)
          const double e = ctx_.value(y);
          const NodeId k[2] = {x, constant(e - 1.0)};
          const NodeId f[3] = {constant(e), ctx_.make(Op::Pow, k), g};
          give(x, ctx_.make(Op::Mul, f));
          return;
        }
        // x^y: x_b += g x^y y / x, y_b += g x^y log x
        const NodeId t = both ? share(mul(g, n), name) : mul(g, n);
        if (active(x)) give(x, div(mul(t, y), x));
        if (active(y)) give(y, mul(t, fn(Op::Log, x)));
        return;
      }
      case Op::Sin: give(kids[0], mul(g, fn(Op::Cos, kids[0]))); return;
      case Op::Cos: give(kids[0], neg(mul(g, fn(Op::Sin, kids[0])))); return;
      case Op::Tan: give(kids[0], mul(g, add(one_, mul(n, n)))); return;
      case Op::Atan2: {
        // atan2(y, x): y_b += g x / (x^2 + y^2), x_b -= g y / (x^2 + y^2)
        const NodeId y = kids[0], x = kids[1];
        const NodeId r = div(g, add(mul(x, x), mul(y, y)));
        const NodeId t = both ? share(r, name) : r;
        if (active(y)) give(y, mul(t, x));
        if (active(x)) give(x, neg(mul(t, y)));
        return;
      }
      case Op::Sqrt: give(kids[0], div(g, mul(constant(2.0), n))); return;
      case Op::Exp: give(kids[0], mul(g, n)); return;
      case Op::Log: give(kids[0], div(g, kids[0])); return;
      case Op::Abs: give(kids[0], mul(fn(Op::Sign, kids[0]), g)); return;
      case Op::Sign: return;
      case Op::Min:
      case Op::Max: {
        // the branch chosen: min(a, b) = a when b - a > 0, max(a, b) = a when a - b > 0
        if (readers > 1) g = share(g, name);
        const NodeId a = kids[0], b = kids[1];
        const NodeId c = op == Op::Min ? sub(b, a) : sub(a, b);
        if (active(a)) give(a, select(c, g, zero_));
        if (active(b)) give(b, select(c, zero_, g));
        return;
      }
      case Op::Select: {
        if (readers > 1) g = share(g, name);
        if (active(kids[1])) give(kids[1], select(kids[0], g, zero_));
        if (active(kids[2])) give(kids[2], select(kids[0], zero_, g));
        return;
      }
      default: throw std::logic_error("symbolic: no adjoint rule");
    }
  }

  EquationList& out_;
  enum Activity : char { kUnknown, kInactive, kActive };
  std::vector<char> active_;             // by node (symbols and nodes above them; see active())
  std::vector<std::uint32_t> stamp_;     // by node: visited by the current order()
  std::uint32_t current_stamp_ = 0;
  std::vector<std::uint32_t> position_;  // by node: in the right-hand side being propagated
  std::vector<std::pair<NodeId, std::uint32_t>> stack_;
  DagWalk search_;                       // find_shared()'s, restarted for each root
  std::vector<std::uint32_t> first_root_;    // by node: the first root (in list order) reading it
  std::vector<char> shared_;                 // by node: read by more than one root
  std::vector<std::vector<NodeId>> pending_; // by root: the shared nodes it reads first
  std::vector<NodeId> order_;
  std::vector<std::vector<NodeId>> node_terms_;  // contributions to the nodes being propagated
  std::unordered_map<NodeId, std::vector<NodeId>> terms_;  // contributions to leaves
  std::vector<NodeId> abbreviations_;    // those with contributions
  NodeId zero_, one_;
};

}  // namespace

EquationList adjoint_list(const EquationList& list, std::span<const ArrayId> arrays) {
  Context& ctx = list.context();
  const EquationList primal = eliminate(list);
  const ArrayId weights = ctx.weight_array(primal.outputs().size());
  EquationList result(ctx);
  for (const Assignment& a : primal.assignments()) result.append(a);
  for (const Output& o : primal.outputs()) result.add_output(o);

  Adjoint adj(ctx, result, ctx.size());
  for (ArrayId a : arrays) {
    for (NodeId x : ctx.array(a).elements) adj.set_active(x, true);
  }
  for (const Assignment& a : primal.assignments()) adj.set_active(a.target, adj.mark(a.value));
  for (const Output& o : primal.outputs()) adj.mark(o.value);
  const auto& assignments = primal.assignments();
  const auto& outputs = primal.outputs();
  // the roots, in list order: the right-hand sides, then the outputs
  const auto m = static_cast<std::uint32_t>(assignments.size());
  for (std::uint32_t i = 0; i < m; ++i) adj.find_shared(assignments[i].value, i);
  for (std::uint32_t j = 0; j < outputs.size(); ++j) adj.find_shared(outputs[j].value, m + j);

  for (std::uint32_t j = 0; j < outputs.size(); ++j) {
    adj.propagate(outputs[j].value, ctx.array(weights).elements[j], "bar_" + outputs[j].name);
  }
  for (std::uint32_t j = static_cast<std::uint32_t>(outputs.size()); j-- > 0;) {
    adj.propagate_shared(m + j, "bar_" + outputs[j].name);
  }
  for (std::size_t i = assignments.size(); i-- > 0;) {
    const Assignment& a = assignments[i];
    const std::string name = ctx.symbol(a.target).name + "_b";
    const NodeId sum = adj.take(a.target);
    if (sum != ctx.zero().id()) adj.propagate(a.value, result.assign(name, ctx.expr(sum)).id(), name);
    adj.propagate_shared(static_cast<std::uint32_t>(i), name);
  }
  adj.propagate_abbreviations();
  for (ArrayId a : arrays) {
    for (NodeId x : ctx.array(a).elements) {
      result.add_output(Output{"bar(" + ctx.symbol(x).name + ")", adj.take(x)});
    }
  }
  result.set_primal_split(primal.size(), primal.outputs().size());
  return eliminate(result);
}

}  // namespace dydp::symbolic
