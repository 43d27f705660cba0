// Compaction in three sweeps over the list (see compact.hpp):
//  1. resolve: every right-hand side is rebuilt with the auxiliaries already found equal to an
//     earlier one (or trivial) substituted, so equal right-hand sides become one node; the
//     repeated ones are dropped;
//  2. count: how many parents (and list roots) read each node of the rebuilt graph, and which
//     nodes depend on the seeds of a tangent list;
//  3. write: the assignments again, each right-hand side printed bottom-up; a node read more than
//     once becomes its own auxiliary (once, the first time it is met), and a node that would make
//     its line longer than max_line_ops operations is given its own auxiliary too.
#include "symbolic/compact.hpp"

#include "symbolic/dag_walk.hpp"
#include "symbolic/op_count.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <string>
#include <vector>

namespace dydp::symbolic {
namespace {

constexpr NodeId kNone = 0xFFFFFFFFu;

// A map from node ids to node ids (kNone when unset), dense: node ids are small integers.
class NodeMap {
 public:
  NodeId get(NodeId n) const { return n < values_.size() ? values_[n] : kNone; }
  void set(NodeId n, NodeId value) {
    if (n >= values_.size()) values_.resize(std::max<std::size_t>(n + 1, 2 * values_.size()), kNone);
    values_[n] = value;
  }

 private:
  std::vector<NodeId> values_;
};

bool is_atom(const Context& ctx, NodeId n) {
  const Op op = ctx.op(n);
  return op == Op::Constant || op == Op::Symbol || ctx.is_abbreviation(n);
}

bool small_integer_power(const Context& ctx, NodeId n, double* exponent) {
  if (ctx.op(n) != Op::Pow || ctx.op(ctx.children(n)[1]) != Op::Constant) return false;
  const double e = ctx.value(ctx.children(n)[1]);
  if (e != std::nearbyint(e) || std::fabs(e) > kMaxInlinePower) return false;
  *exponent = e;
  return true;
}

// Operations a node costs on a line when its children are printed inline, as count_ops counts
// them: x^n (small n) is n-1 multiplications, a product's inverse powers go below one division.
std::size_t own_line_ops(const Context& ctx, NodeId n) {
  if (is_atom(ctx, n)) return 0;
  const auto kids = ctx.children(n);
  double e = 0.0;
  switch (ctx.op(n)) {
    case Op::Add: return kids.size() - 1;
    case Op::Mul: {
      std::size_t numerator = 0, denominator = 0;
      for (NodeId f : kids) {
        double fe = 0.0;
        (small_integer_power(ctx, f, &fe) && fe < 0.0 ? denominator : numerator) += 1;
      }
      return (numerator ? numerator - 1 : 0) + (denominator ? denominator : 0);
    }
    case Op::Neg: return 0;
    case Op::Pow:
      if (small_integer_power(ctx, n, &e)) return static_cast<std::size_t>(std::fabs(e)) - 1 + (e < 0.0 ? 1 : 0);
      return 1;
    default: return 1;
  }
}

// Children that are printed more than once by the printer, or whose repetition would cost
// operations, must be atoms: sign(x) prints x twice, x^n (small n) prints x n times.
bool needs_atom_children(const Context& ctx, NodeId n) {
  const Op op = ctx.op(n);
  if (op == Op::Sign) return true;
  if (op == Op::Pow) {
    const NodeId e = ctx.children(n)[1];
    return ctx.op(e) == Op::Constant;
  }
  return false;
}

class Compactor {
 public:
  Compactor(const EquationList& list, const CompactOptions& options, CompactStats* stats)
      : in_(list), ctx_(list.context()), options_(options), stats_(stats) {}

  EquationList run() {
    resolve();
    count();
    write();
    EquationList result(ctx_);
    for (const Assignment& a : primal_) result.append(a);
    for (const Assignment& a : derivative_) result.append(a);
    for (Output& o : outputs_) result.add_output(std::move(o));
    if (in_.has_split()) result.set_primal_split(primal_.size(), in_.primal_outputs());
    if (stats_) {
      stats_->assignments_before = in_.size();
      stats_->assignments_after = result.size();
    }
    return result;
  }

 private:
  // --- 1. resolve -------------------------------------------------------------------------
  NodeId rebuild(NodeId n) {
    if (n < rebuilt_.size() && rebuilt_[n] != kNone) return rebuilt_[n];
    NodeId r = n;
    if (ctx_.op(n) == Op::Symbol) {
      if (const NodeId to = substitute_.get(n); to != kNone) r = to;
    } else if (!is_atom(ctx_, n)) {
      const std::vector<NodeId> kids(ctx_.children(n).begin(), ctx_.children(n).end());
      std::vector<NodeId> next(kids.size());
      bool changed = false;
      for (std::size_t i = 0; i < kids.size(); ++i) {
        next[i] = rebuild(kids[i]);
        changed = changed || next[i] != kids[i];
      }
      if (changed) r = ctx_.make(ctx_.op(n), next);
    }
    if (n >= rebuilt_.size()) rebuilt_.resize(ctx_.size(), kNone);
    rebuilt_[n] = r;
    return r;
  }

  void resolve() {
    rebuilt_.assign(ctx_.size(), kNone);
    NodeMap target_of_value;
    const std::size_t primal_end = in_.has_split() ? in_.primal_assignments() : in_.size();
    for (std::size_t i = 0; i < in_.size(); ++i) {
      const Assignment& a = in_.assignments()[i];
      const NodeId v = rebuild(a.value);
      if (is_trivial(ctx_, v)) {
        substitute_.set(a.target, v);
        continue;
      }
      if (const NodeId earlier = target_of_value.get(v); earlier != kNone) {
        substitute_.set(a.target, earlier);
        if (stats_) ++stats_->merged;
        continue;
      }
      target_of_value.set(v, a.target);
      resolved_.push_back({a.target, v});
      resolved_primal_ += i < primal_end ? 1 : 0;
    }
    for (std::size_t j = 0; j < in_.outputs().size(); ++j) resolved_outputs_.push_back(rebuild(in_.outputs()[j].value));
  }

  // --- 2. count ---------------------------------------------------------------------------
  void count() {
    readers_.assign(ctx_.size(), 0);
    seeded_.assign(ctx_.size(), 0);
    DagWalk walk(ctx_);
    auto visit = [&](NodeId root) {
      ++readers_[root];
      walk.walk(root, [&](NodeId n) {
        if (is_atom(ctx_, n)) return false;
        for (NodeId c : ctx_.children(n)) ++readers_[c];
        return true;
      });
    };
    for (const Assignment& a : resolved_) visit(a.value);
    for (NodeId o : resolved_outputs_) visit(o);
    // Seed dependence of the auxiliaries, in list order (a value reads earlier auxiliaries only).
    for (const Assignment& a : resolved_) seeded_[a.target] = seeded_of(a.value);
  }

  // Seed dependence with auxiliaries resolved (their flags are set in list order).
  char seeded_of(NodeId n) {
    if (ctx_.op(n) == Op::Symbol) {
      const Symbol& s = ctx_.symbol(n);
      return s.kind == SymbolKind::Seed || (s.kind == SymbolKind::Aux && n < seeded_.size() && seeded_[n]);
    }
    if (is_atom(ctx_, n)) return 0;
    if (seeded_known_.size() < ctx_.size()) seeded_known_.resize(ctx_.size(), -1);
    if (seeded_known_[n] >= 0) return seeded_known_[n];
    char s = 0;
    // seeded_of builds no nodes, so the children's span stays valid
    for (NodeId c : ctx_.children(n)) {
      s = seeded_of(c);
      if (s) break;
    }
    seeded_known_[n] = s;
    return s;
  }

  // --- 3. write ---------------------------------------------------------------------------
  // A new auxiliary holding `value` (built from written children), in the part it belongs to.
  NodeId materialize(NodeId value, bool seeded, const std::string& name) {
    // a value built twice (hash-consed: the same node) is one auxiliary
    if (const NodeId existing = materialized_.get(value); existing != kNone) return existing;
    const Expr target = ctx_.aux(name);
    materialized_.set(value, target.id());
    if (seeded_.size() < ctx_.size()) seeded_.resize(ctx_.size(), 0);
    seeded_[target.id()] = seeded;
    (seeded && in_.has_split() ? derivative_ : primal_).push_back({target.id(), value});
    return target.id();
  }

  std::string fresh_name() { return current_name_ + "_" + std::to_string(++name_counter_); }

  std::size_t line_ops(NodeId n) {
    if (n < line_ops_.size() && line_ops_[n] != kNone) return line_ops_[n];
    std::size_t c = own_line_ops(ctx_, n);
    if (!is_atom(ctx_, n))
      for (NodeId k : ctx_.children(n)) c += line_ops(k);  // builds no nodes: the span stays valid
    if (n >= line_ops_.size()) line_ops_.resize(ctx_.size(), kNone);
    line_ops_[n] = static_cast<NodeId>(c);
    return c;
  }

  // Written children of n, rebuilt into a node whose line stays within max_line_ops: the
  // costliest inline children are given auxiliaries first, then a long sum or product is split
  // into chunks.
  NodeId build_small(NodeId n, std::vector<NodeId> kids, bool seeded) {
    const Op op = ctx_.op(n);
    const std::size_t limit = std::max<std::size_t>(options_.max_line_ops, 2);
    if (needs_atom_children(ctx_, n)) {
      for (NodeId& k : kids)
        if (!is_atom(ctx_, k)) k = split_off(k, seeded);
    }
    auto cost = [&] {
      std::size_t c = 0;
      if (op == Op::Add) c = kids.size() - 1;
      else if (op == Op::Mul) {
        std::size_t numerator = 0, denominator = 0;
        for (NodeId f : kids) {
          double fe = 0.0;
          (small_integer_power(ctx_, f, &fe) && fe < 0.0 ? denominator : numerator) += 1;
        }
        c = (numerator ? numerator - 1 : 0) + denominator;
      } else if (op != Op::Neg) {
        double e = 0.0;
        c = op == Op::Pow && small_integer_power(ctx_, n, &e) ? static_cast<std::size_t>(std::fabs(e)) : 1;
      }
      for (NodeId k : kids) c += line_ops(k);
      return c;
    };
    while (cost() > limit) {
      std::size_t worst = kids.size();
      for (std::size_t i = 0; i < kids.size(); ++i)
        if (!is_atom(ctx_, kids[i]) && (worst == kids.size() || line_ops(kids[i]) > line_ops(kids[worst]))) worst = i;
      if (worst == kids.size() || line_ops(kids[worst]) == 0) break;
      kids[worst] = split_off(kids[worst], seeded);
    }
    if ((op == Op::Add || op == Op::Mul) && kids.size() > limit + 1) {
      // chunks of limit + 1 atoms, each one auxiliary
      std::vector<NodeId> chunks;
      for (std::size_t i = 0; i < kids.size(); i += limit + 1) {
        const std::size_t end = std::min(kids.size(), i + limit + 1);
        std::vector<NodeId> part(kids.begin() + i, kids.begin() + end);
        chunks.push_back(part.size() == 1 ? part[0] : split_off(ctx_.make(op, part), seeded));
      }
      return build_small(n, chunks, seeded);
    }
    return ctx_.make(op, kids);
  }

  NodeId split_off(NodeId value, bool seeded) {
    if (stats_) ++stats_->split;
    return materialize(value, seeded && seeded_of(value), fresh_name());
  }

  // -A when the negation of the sum r is the value of an auxiliary A already written.
  NodeId negation_of_written(NodeId r) {
    if (ctx_.op(r) != Op::Add) return kNone;
    const NodeId negated = ctx_.make(Op::Neg, std::span<const NodeId>(&r, 1));
    const NodeId target = materialized_.get(negated);
    if (target == kNone) return kNone;
    return ctx_.make(Op::Neg, std::span<const NodeId>(&target, 1));
  }

  // n written: an atom, an auxiliary, or a small inline expression of written children.
  NodeId write_node(NodeId n) {
    if (ctx_.op(n) == Op::Symbol) {
      const NodeId to = alias_.get(n);
      return to == kNone ? n : to;
    }
    if (is_atom(ctx_, n)) return n;
    if (const NodeId done = written_.get(n); done != kNone) return done;
    const std::vector<NodeId> kids(ctx_.children(n).begin(), ctx_.children(n).end());
    std::vector<NodeId> next;
    next.reserve(kids.size());
    for (NodeId k : kids) next.push_back(write_node(k));
    const bool seeded = seeded_of(n);
    NodeId r = build_small(n, std::move(next), seeded);
    if (const NodeId negated = negation_of_written(r); negated != kNone) {
      written_.set(n, negated);  // -(a + b) of an a + b already written: the derivative of a rotation
      return negated;
    }
    if (readers_[n] > 1 && !is_atom(ctx_, r)) {
      if (stats_) ++stats_->shared;
      r = materialize(r, seeded, fresh_name());
    }
    written_.set(n, r);
    return r;
  }

  // The root of an assignment keeps the assignment's own auxiliary.
  void write_assignment(const Assignment& a) {
    current_name_ = ctx_.symbol(a.target).name;
    name_counter_ = 0;
    if (const NodeId done = written_.get(a.value); done != kNone && !is_atom(ctx_, done)) {
      alias_.set(a.target, done);  // met before inside another right-hand side
      if (stats_) ++stats_->merged;
      return;
    }
    const std::vector<NodeId> kids(ctx_.children(a.value).begin(), ctx_.children(a.value).end());
    std::vector<NodeId> next;
    for (NodeId k : kids) next.push_back(write_node(k));
    const bool seeded = seeded_of(a.value);
    const NodeId r = build_small(a.value, std::move(next), seeded);
    if (is_trivial(ctx_, r)) {  // cannot happen after resolve, but stay safe
      alias_.set(a.target, r);
      return;
    }
    if (const NodeId existing = materialized_.get(r); existing != kNone) {
      alias_.set(a.target, existing);  // the same line was written for another node
      if (stats_) ++stats_->merged;
      return;
    }
    if (const NodeId negated = negation_of_written(r); negated != kNone) {
      alias_.set(a.target, negated);
      if (stats_) ++stats_->merged;
      return;
    }
    materialized_.set(r, a.target);
    if (seeded && in_.has_split()) derivative_.push_back({a.target, r});
    else {
      if (!seeded && in_.has_split() && assignment_index_ >= resolved_primal_ && stats_) ++stats_->hoisted;
      primal_.push_back({a.target, r});
    }
    written_.set(a.value, a.target);
  }

  void write() {
    const std::size_t primal_outputs = in_.has_split() ? in_.primal_outputs() : in_.outputs().size();
    for (assignment_index_ = 0; assignment_index_ < resolved_.size(); ++assignment_index_) {
      if (assignment_index_ == resolved_primal_) write_outputs(0, primal_outputs);
      write_assignment(resolved_[assignment_index_]);
    }
    if (resolved_primal_ == resolved_.size()) write_outputs(0, primal_outputs);
    write_outputs(primal_outputs, in_.outputs().size());
  }

  void write_outputs(std::size_t begin, std::size_t end) {
    for (std::size_t j = begin; j < end; ++j) {
      current_name_ = "out" + std::to_string(j);
      name_counter_ = 0;
      const NodeId v = resolved_outputs_[j];
      NodeId r = write_node(v);
      if (!is_atom(ctx_, r) && line_ops(r) > options_.max_line_ops) r = split_off(r, seeded_of(r));
      outputs_.push_back(Output{in_.outputs()[j].name, r});
    }
  }

  const EquationList& in_;
  Context& ctx_;
  CompactOptions options_;
  CompactStats* stats_;

  std::vector<NodeId> rebuilt_;
  NodeMap substitute_;
  std::vector<Assignment> resolved_;
  std::size_t resolved_primal_ = 0;
  std::vector<NodeId> resolved_outputs_;

  std::vector<std::uint32_t> readers_;
  std::vector<char> seeded_;
  std::vector<signed char> seeded_known_;
  std::vector<NodeId> line_ops_;

  NodeMap written_, alias_, materialized_;
  std::vector<Assignment> primal_, derivative_;
  std::vector<Output> outputs_;
  std::string current_name_;
  std::size_t name_counter_ = 0;
  std::size_t assignment_index_ = 0;
};

}  // namespace

EquationList compact(const EquationList& list, const CompactOptions& options, CompactStats* stats) {
  if (stats) *stats = CompactStats{};
  return Compactor(list, options, stats).run();
}

}  // namespace dydp::symbolic
