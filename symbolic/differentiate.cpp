// Forward-mode differentiation of an equation list, assignment by assignment. Each expression
// node's derivative is memoised per direction, so the pass is linear in the list's size.
#include "symbolic/differentiate.hpp"

#include <stdexcept>
#include <string>
#include <utility>

#include "symbolic/eliminate.hpp"
#include "symbolic/node_builder.hpp"

namespace dydp::symbolic {
namespace {

constexpr NodeId kUnset = 0xFFFFFFFFu;

class Differentiator : NodeBuilder {
 public:
  // `list`, `suffix`: where the derivatives of the sin/cos abbreviations are assigned (see
  // compute()); null: they stay expressions.
  Differentiator(Context& ctx, std::size_t known_nodes, EquationList* list = nullptr, std::string suffix = "")
      : NodeBuilder(ctx), derivative_(known_nodes, kUnset),
        zero_(ctx.constant(0.0).id()), one_(ctx.constant(1.0).id()), list_(list), suffix_(std::move(suffix)) {}

  void set(NodeId symbol, NodeId derivative) { derivative_.at(symbol) = derivative; }
  NodeId zero() const { return zero_; }

  // d(n) along the current direction.
  NodeId d(NodeId n) {
    if (n < derivative_.size() && derivative_[n] != kUnset) return derivative_[n];
    const NodeId r = compute(n);
    if (n < derivative_.size()) derivative_[n] = r;
    return r;
  }

 private:

  NodeId compute(NodeId n) {
    const Op op = ctx_.op(n);
    if (op == Op::Constant || op == Op::Symbol) return zero_;  // seeded symbols are memoised
    // a copy: building derivative nodes may move the context's children storage
    const std::vector<NodeId> kids(ctx_.children(n).begin(), ctx_.children(n).end());
    std::vector<NodeId> dk(kids.size());
    bool all_zero = true;
    for (std::size_t i = 0; i < kids.size(); ++i) {
      dk[i] = d(kids[i]);
      all_zero = all_zero && dk[i] == zero_;
    }
    if (all_zero) return zero_;
    switch (op) {
      case Op::Add: return ctx_.make(Op::Add, dk);
      case Op::Mul: {
        // Product rule over the n-ary product: sum_i (prod_{j != i} f_j) f_i'.
        std::vector<NodeId> terms;
        std::vector<NodeId> factors;
        for (std::size_t i = 0; i < kids.size(); ++i) {
          if (dk[i] == zero_) continue;
          factors.clear();
          for (std::size_t j = 0; j < kids.size(); ++j) factors.push_back(j == i ? dk[i] : kids[j]);
          terms.push_back(ctx_.make(Op::Mul, factors));
        }
        return ctx_.make(Op::Add, terms);
      }
      case Op::Neg: return neg(dk[0]);
      case Op::Div: {
        // (a/b)' = (a' - (a/b) b') / b
        if (dk[1] == zero_) return div(dk[0], kids[1]);
        return div(sub(dk[0], mul(n, dk[1])), kids[1]);
      }
      case Op::Pow: {
        const NodeId x = kids[0], y = kids[1];
        if (ctx_.op(y) == Op::Constant) {
          // (x^e)' = e x^(e-1) x'
          const double e = ctx_.value(y);
          const NodeId k[2] = {x, constant(e - 1.0)};
          const NodeId f[3] = {constant(e), ctx_.make(Op::Pow, k), dk[0]};
          return ctx_.make(Op::Mul, f);
        }
        // (x^y)' = x^y (y' log x + y x' / x)
        NodeId inner = zero_;
        if (dk[1] != zero_) inner = add(inner, mul(dk[1], fn(Op::Log, x)));
        if (dk[0] != zero_) inner = add(inner, div(mul(y, dk[0]), x));
        return mul(n, inner);
      }
      case Op::Sin:
      case Op::Cos: {
        const NodeId rate = op == Op::Sin ? mul(fn(Op::Cos, kids[0]), dk[0]) : neg(mul(fn(Op::Sin, kids[0]), dk[0]));
        // An abbreviation's derivative (S3_d = C3*dq3) is an auxiliary of its own: products
        // that read it would otherwise absorb its two factors and multiply them again each.
        if (list_ && ctx_.is_abbreviation(n)) return list_->assign(ctx_.abbreviation_name(n) + "_" + suffix_, ctx_.expr(rate)).id();
        return rate;
      }
      case Op::Tan: return mul(add(one_, mul(n, n)), dk[0]);
      case Op::Atan2: {
        // atan2(y, x)' = (x y' - y x') / (x^2 + y^2)
        const NodeId y = kids[0], x = kids[1];
        const NodeId num = sub(mul(x, dk[0]), mul(y, dk[1]));
        return div(num, add(mul(x, x), mul(y, y)));
      }
      case Op::Sqrt: return div(dk[0], mul(constant(2.0), n));
      case Op::Exp: return mul(n, dk[0]);
      case Op::Log: return div(dk[0], kids[0]);
      case Op::Abs: return mul(fn(Op::Sign, kids[0]), dk[0]);
      case Op::Sign: return zero_;
      case Op::Min: {
        // the branch chosen: min(a, b) = a when a < b, i.e. when b - a > 0
        const NodeId k[3] = {sub(kids[1], kids[0]), dk[0], dk[1]};
        return ctx_.make(Op::Select, k);
      }
      case Op::Max: {
        const NodeId k[3] = {sub(kids[0], kids[1]), dk[0], dk[1]};
        return ctx_.make(Op::Select, k);
      }
      case Op::Select: {
        const NodeId k[3] = {kids[0], dk[1], dk[2]};
        return ctx_.make(Op::Select, k);
      }
      default: throw std::logic_error("symbolic: no derivative rule");
    }
  }

  std::vector<NodeId> derivative_;
  NodeId zero_, one_;
  EquationList* list_;
  std::string suffix_;
};

}  // namespace

Direction along(Expr symbol) {
  if (symbol.op() != Op::Symbol) throw std::invalid_argument("symbolic: along() needs a symbol");
  const std::string& name = symbol.context().symbol(symbol.id()).name;
  return Direction{name, name, {{symbol.id(), symbol.context().one().id()}}};
}

Direction seeded(Context& context, std::span<const ArrayId> arrays) {
  Direction dir{"d", "seed", {}};
  for (ArrayId a : arrays) {
    const ArrayId s = context.seed_array(a);
    const auto& elements = context.array(a).elements;
    for (std::size_t i = 0; i < elements.size(); ++i) {
      dir.seeds.emplace_back(elements[i], context.array(s).elements[i]);
    }
  }
  return dir;
}

EquationList differentiate(const EquationList& list, std::span<const Direction> directions) {
  Context& ctx = list.context();
  EquationList result(ctx);
  for (const Assignment& a : list.assignments()) result.append(a);
  for (const Output& o : list.outputs()) result.add_output(o);
  const std::size_t primal_size = list.size();
  const std::size_t primal_outputs = list.outputs().size();

  std::vector<Output> derivative_outputs;
  for (const Direction& dir : directions) {
    Differentiator diff(ctx, ctx.size(), &result, dir.suffix);
    for (const auto& [symbol, seed] : dir.seeds) diff.set(symbol, seed);
    for (const Assignment& a : list.assignments()) {
      const NodeId da = diff.d(a.value);
      const std::string name = ctx.symbol(a.target).name + "_" + dir.suffix;
      const NodeId target = result.assign(name, ctx.expr(da)).id();
      diff.set(a.target, target);
    }
    for (const Output& o : list.outputs()) {
      const std::string& label = dir.label.empty() ? dir.suffix : dir.label;
      derivative_outputs.push_back(Output{"d(" + o.name + ")/d(" + label + ")", diff.d(o.value)});
    }
  }
  for (Output& o : derivative_outputs) result.add_output(std::move(o));
  result.set_primal_split(primal_size, primal_outputs);
  return result;
}

EquationList tangent_list(const EquationList& list, std::span<const ArrayId> arrays) {
  const Direction dir = seeded(list.context(), arrays);
  EquationList t = differentiate(eliminate(list), std::span<const Direction>(&dir, 1));
  return eliminate(t);
}

}  // namespace dydp::symbolic
