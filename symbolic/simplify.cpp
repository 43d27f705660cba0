// The simplifying constructors of Context: every node is built through these, so constant
// folding, the 0 and 1 rules, x - x = 0, x * x^-1 = 1 and canonical ordering of sums and products
// hold for every expression, and equal expressions are one node.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "symbolic/expr.hpp"

namespace dydp::symbolic {
namespace {

bool is_integer(double v) { return std::isfinite(v) && v == std::nearbyint(v); }

// Folding is only done when the result is a finite number: log(0) or 1/0 stay as written.
bool foldable(double v) { return std::isfinite(v); }

}  // namespace

std::tuple<int, NodeId, NodeId> Context::order_key(NodeId n) const {
  NodeId lead = n;
  for (;;) {
    const Op o = op(lead);
    if (o == Op::Neg) lead = children(lead)[0];
    else if (o == Op::Pow) lead = children(lead)[0];
    else if (o == Op::Mul) {
      auto kids = children(lead);
      lead = op(kids[0]) == Op::Constant ? kids[1] : kids[0];
    } else break;
  }
  const int rank = op(lead) == Op::Symbol ? 0 : is_abbreviation(lead) ? 1 : op(lead) == Op::Constant ? 3 : 2;
  return {rank, lead, n};
}

// --- sums ----------------------------------------------------------------------------------------
// A sum is kept as c0 + sum_i c_i * t_i with the t_i distinct and sorted by node id; the
// constant c0 is the last child. Terms with equal t_i are merged, zero coefficients dropped.
NodeId Context::make_add(std::span<const NodeId> input) {
  std::vector<std::pair<NodeId, double>> terms;  // (rest, coefficient)
  double constant_sum = 0.0;
  std::vector<NodeId> pending(input.begin(), input.end());
  for (std::size_t k = 0; k < pending.size(); ++k) {
    const NodeId t = pending[k];
    switch (op(t)) {
      case Op::Constant: constant_sum += value(t); break;
      case Op::Add: {
        auto kids = children(t);
        pending.insert(pending.end(), kids.begin(), kids.end());
        break;
      }
      case Op::Neg: terms.emplace_back(children(t)[0], -1.0); break;
      case Op::Mul: {
        auto kids = children(t);
        if (op(kids[0]) == Op::Constant) {
          const double c = value(kids[0]);
          const NodeId rest = kids.size() == 2 ? kids[1] : intern(Op::Mul, kids.subspan(1), 0);
          terms.emplace_back(rest, c);
        } else {
          terms.emplace_back(t, 1.0);
        }
        break;
      }
      default: terms.emplace_back(t, 1.0);
    }
  }
  std::sort(terms.begin(), terms.end(), [this](const auto& a, const auto& b) {
    return order_key(a.first) < order_key(b.first);
  });
  std::vector<NodeId> kids;
  for (std::size_t i = 0; i < terms.size();) {
    double c = 0.0;
    std::size_t j = i;
    for (; j < terms.size() && terms[j].first == terms[i].first; ++j) c += terms[j].second;
    const NodeId rest = terms[i].first;
    if (c == 1.0) kids.push_back(rest);
    else if (c == -1.0) kids.push_back(make_neg(rest));
    else if (c != 0.0) {
      const NodeId coeff = make_constant(c);
      const NodeId pair[2] = {coeff, rest};
      kids.push_back(make_mul(pair));
    }
    i = j;
  }
  if (constant_sum != 0.0 || kids.empty()) kids.push_back(make_constant(constant_sum));
  if (kids.size() == 1) return kids[0];
  return intern(Op::Add, kids, 0);
}

// --- products ------------------------------------------------------------------------------------
// A product is kept as c * prod_i b_i^e_i with distinct bases sorted by node id, the constant
// first (and never +-1: -1 becomes a Neg around the product). Powers of equal bases merge.
NodeId Context::make_mul(std::span<const NodeId> input) {
  std::vector<std::pair<NodeId, double>> factors;  // (base, exponent)
  double coefficient = 1.0;
  std::vector<NodeId> pending(input.begin(), input.end());
  for (std::size_t k = 0; k < pending.size(); ++k) {
    const NodeId f = pending[k];
    switch (op(f)) {
      case Op::Constant: coefficient *= value(f); break;
      case Op::Mul: {
        auto kids = children(f);
        pending.insert(pending.end(), kids.begin(), kids.end());
        break;
      }
      case Op::Neg:
        coefficient = -coefficient;
        pending.push_back(children(f)[0]);
        break;
      case Op::Pow: {
        auto kids = children(f);
        if (op(kids[1]) == Op::Constant) factors.emplace_back(kids[0], value(kids[1]));
        else factors.emplace_back(f, 1.0);
        break;
      }
      default: factors.emplace_back(f, 1.0);
    }
  }
  if (coefficient == 0.0) return make_constant(0.0);
  std::sort(factors.begin(), factors.end(), [this](const auto& a, const auto& b) {
    return order_key(a.first) < order_key(b.first);
  });
  std::vector<NodeId> kids;
  if (coefficient != 1.0 && coefficient != -1.0) kids.push_back(make_constant(coefficient));
  for (std::size_t i = 0; i < factors.size();) {
    double e = 0.0;
    std::size_t j = i;
    for (; j < factors.size() && factors[j].first == factors[i].first; ++j) e += factors[j].second;
    const NodeId base = factors[i].first;
    if (e == 1.0) kids.push_back(base);
    else if (e != 0.0) kids.push_back(make_pow(base, make_constant(e)));
    i = j;
  }
  NodeId product;
  if (kids.empty()) product = make_constant(1.0);
  else if (kids.size() == 1) product = kids[0];
  else {
    // make_pow may have returned a constant or a product; re-sort only if that happened.
    bool plain = true;
    for (std::size_t i = 0; i < kids.size(); ++i) {
      const Op o = op(kids[i]);
      if ((o == Op::Constant && i > 0) || o == Op::Mul || o == Op::Neg) plain = false;
    }
    if (!plain) {
      if (coefficient == -1.0) kids.push_back(make_constant(-1.0));
      return make_mul(kids);
    }
    product = intern(Op::Mul, kids, 0);
  }
  return coefficient == -1.0 ? make_neg(product) : product;
}

NodeId Context::make_neg(NodeId a) {
  switch (op(a)) {
    case Op::Constant: return make_constant(-value(a));
    case Op::Neg: return children(a)[0];
    case Op::Mul: {
      auto kids = children(a);
      if (op(kids[0]) == Op::Constant) {
        std::vector<NodeId> k(kids.begin(), kids.end());
        k[0] = make_constant(-value(kids[0]));
        return make_mul(k);
      }
      return intern(Op::Neg, std::span<const NodeId>(&a, 1), 0);
    }
    case Op::Add: {
      // -(a + b) = -a - b keeps one canonical form for every sum.
      // copied first: building nodes may move the children storage
      std::vector<NodeId> k(children(a).begin(), children(a).end());
      for (NodeId& t : k) t = make_neg(t);
      return make_add(k);
    }
    default: return intern(Op::Neg, std::span<const NodeId>(&a, 1), 0);
  }
}

NodeId Context::make_div(NodeId a, NodeId b) {
  if (a == b) return make_constant(1.0);
  const bool ca = op(a) == Op::Constant, cb = op(b) == Op::Constant;
  if (ca && cb && foldable(value(a) / value(b))) return make_constant(value(a) / value(b));
  if (cb && value(b) == 1.0) return a;
  if (cb && value(b) == -1.0) return make_neg(a);
  if (ca && value(a) == 0.0) return a;
  if (op(a) == Op::Neg) return make_neg(make_div(children(a)[0], b));
  if (op(b) == Op::Neg) return make_neg(make_div(a, children(b)[0]));
  if (op(a) == Op::Mul) {
    // (x * y) / y = x
    auto kids = children(a);
    auto it = std::find(kids.begin(), kids.end(), b);
    if (it != kids.end()) {
      std::vector<NodeId> rest(kids.begin(), it);
      rest.insert(rest.end(), it + 1, kids.end());
      return make_mul(rest);
    }
  }
  const NodeId pair[2] = {a, b};
  return intern(Op::Div, pair, 0);
}

NodeId Context::make_pow(NodeId base, NodeId exponent) {
  const bool cb = op(base) == Op::Constant, ce = op(exponent) == Op::Constant;
  if (ce) {
    const double e = value(exponent);
    if (e == 0.0) return make_constant(1.0);
    if (e == 1.0) return base;
    if (cb && foldable(std::pow(value(base), e))) return make_constant(std::pow(value(base), e));
    if (is_integer(e)) {
      // (x^a)^n = x^(a n) for integer n; (c x)^n = c^n x^n; (-x)^n = +-x^n.
      if (op(base) == Op::Pow && op(children(base)[1]) == Op::Constant) {
        return make_pow(children(base)[0], make_constant(value(children(base)[1]) * e));
      }
      if (op(base) == Op::Neg) {
        const NodeId p = make_pow(children(base)[0], exponent);
        return std::fmod(std::fabs(e), 2.0) == 1.0 ? make_neg(p) : p;
      }
      if (op(base) == Op::Mul) {
        std::vector<NodeId> k(children(base).begin(), children(base).end());
        for (NodeId& f : k) f = make_pow(f, exponent);
        return make_mul(k);
      }
    }
  }
  if (cb && value(base) == 1.0) return base;
  const NodeId pair[2] = {base, exponent};
  return intern(Op::Pow, pair, 0);
}

NodeId Context::make_function(Op o, NodeId a) {
  if (op(a) == Op::Constant) {
    const double x = value(a);
    double r = 0.0;
    switch (o) {
      case Op::Sin: r = std::sin(x); break;
      case Op::Cos: r = std::cos(x); break;
      case Op::Tan: r = std::tan(x); break;
      case Op::Sqrt: r = std::sqrt(x); break;
      case Op::Exp: r = std::exp(x); break;
      case Op::Log: r = std::log(x); break;
      case Op::Abs: r = std::fabs(x); break;
      case Op::Sign: r = x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0); break;
      default: throw std::logic_error("symbolic: make_function of a non-function op");
    }
    if (foldable(r)) return make_constant(r);
  }
  switch (o) {
    case Op::Sin:
    case Op::Tan:
      if (op(a) == Op::Neg) return make_neg(make_function(o, children(a)[0]));
      break;
    case Op::Cos:
    case Op::Abs:
      if (op(a) == Op::Neg) return make_function(o, children(a)[0]);
      if (o == Op::Abs && (op(a) == Op::Abs || op(a) == Op::Exp)) return a;
      break;
    case Op::Sign:
      if (op(a) == Op::Neg) return make_neg(make_function(o, children(a)[0]));
      if (op(a) == Op::Sign) return a;
      break;
    case Op::Log:
      if (op(a) == Op::Exp) return children(a)[0];
      break;
    case Op::Exp:
      if (op(a) == Op::Log) break;  // exp(log x) = x only for x > 0: keep as written
      break;
    default: break;
  }
  const NodeId n = intern(o, std::span<const NodeId>(&a, 1), 0);
  // sin and cos of an input or parameter are the trigonometric abbreviations (S3, C3).
  if ((o == Op::Sin || o == Op::Cos) && op(a) == Op::Symbol && !is_symbol(a, SymbolKind::Aux) &&
      abbreviations_.count(n) == 0) {
    const Symbol& s = symbol(a);
    const Array& arr = arrays_[s.array];
    const std::string letter = o == Op::Sin ? "S" : "C";
    const std::string wanted = arr.name == "q" ? letter + std::to_string(s.index + 1)
                                               : letter + "_" + s.name;
    abbreviations_.emplace(n, unique_name(wanted));
    if (abbreviation_flags_.size() <= n) abbreviation_flags_.resize(n + 1, 0);
    abbreviation_flags_[n] = 1;
  }
  return n;
}

NodeId Context::make_atan2(NodeId y, NodeId x) {
  if (op(y) == Op::Constant && op(x) == Op::Constant) {
    return make_constant(std::atan2(value(y), value(x)));
  }
  const NodeId pair[2] = {y, x};
  return intern(Op::Atan2, pair, 0);
}

NodeId Context::make_min_max(Op o, NodeId a, NodeId b) {
  if (a == b) return a;
  if (op(a) == Op::Constant && op(b) == Op::Constant) {
    return o == Op::Min ? make_constant(std::fmin(value(a), value(b)))
                        : make_constant(std::fmax(value(a), value(b)));
  }
  if (b < a) std::swap(a, b);  // min and max are symmetric: one order
  const NodeId pair[2] = {a, b};
  return intern(o, pair, 0);
}

NodeId Context::make_select(NodeId c, NodeId a, NodeId b) {
  if (a == b) return a;
  if (op(c) == Op::Constant) return value(c) > 0.0 ? a : b;
  const NodeId triple[3] = {c, a, b};
  return intern(Op::Select, triple, 0);
}

NodeId Context::make(Op o, std::span<const NodeId> k) {
  const std::size_t arity = o == Op::Select ? 3
                            : (o == Op::Div || o == Op::Pow || o == Op::Atan2 || o == Op::Min ||
                               o == Op::Max) ? 2
                            : (o == Op::Add || o == Op::Mul) ? k.size() : 1;
  if (k.size() != arity || k.empty()) {
    throw std::invalid_argument(std::string("symbolic: wrong number of operands for ") + op_name(o));
  }
  switch (o) {
    case Op::Add: return make_add(k);
    case Op::Mul: return make_mul(k);
    case Op::Neg: return make_neg(k[0]);
    case Op::Div: return make_div(k[0], k[1]);
    case Op::Pow: return make_pow(k[0], k[1]);
    case Op::Atan2: return make_atan2(k[0], k[1]);
    case Op::Min:
    case Op::Max: return make_min_max(o, k[0], k[1]);
    case Op::Select: return make_select(k[0], k[1], k[2]);
    case Op::Constant:
    case Op::Symbol: throw std::logic_error("symbolic: make() of a leaf");
    default: return make_function(o, k[0]);
  }
}

// --- handle-level constructors --------------------------------------------------------------------

Expr Context::constant(double v) { return Expr(this, make_constant(v)); }
Expr Context::add(Expr a, Expr b) {
  const NodeId k[2] = {a.id(), b.id()};
  return Expr(this, make_add(k));
}
Expr Context::sub(Expr a, Expr b) {
  const NodeId k[2] = {a.id(), make_neg(b.id())};
  return Expr(this, make_add(k));
}
Expr Context::mul(Expr a, Expr b) {
  const NodeId k[2] = {a.id(), b.id()};
  return Expr(this, make_mul(k));
}
Expr Context::div(Expr a, Expr b) { return Expr(this, make_div(a.id(), b.id())); }
Expr Context::neg(Expr a) { return Expr(this, make_neg(a.id())); }
Expr Context::pow(Expr a, Expr b) { return Expr(this, make_pow(a.id(), b.id())); }
Expr Context::sum(std::span<const Expr> terms) {
  std::vector<NodeId> k;
  for (Expr e : terms) k.push_back(e.id());
  return Expr(this, make_add(k));
}
Expr Context::product(std::span<const Expr> factors) {
  std::vector<NodeId> k;
  for (Expr e : factors) k.push_back(e.id());
  return Expr(this, make_mul(k));
}
Expr Context::unary(Op o, Expr a) {
  return Expr(this, o == Op::Neg ? make_neg(a.id()) : make_function(o, a.id()));
}
Expr Context::binary(Op o, Expr a, Expr b) {
  const NodeId k[2] = {a.id(), b.id()};
  return Expr(this, make(o, k));
}
Expr Context::select(Expr c, Expr a, Expr b) {
  return Expr(this, make_select(c.id(), a.id(), b.id()));
}

}  // namespace dydp::symbolic
