// Writing equation lists as C++: the expression printer with minimal parentheses (Printer, see
// emit_cpp_internal.hpp) and to_cpp.
#include "symbolic/emit_cpp_internal.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "symbolic/op_count.hpp"

namespace dydp::symbolic {
namespace {

// Binding strength of what a node prints as: 0 sum, 1 product or quotient, 2 unary minus, 3 atom.
int precedence(const Context& ctx, NodeId n) {
  switch (ctx.op(n)) {
    case Op::Constant: return ctx.value(n) < 0.0 ? 2 : 3;
    case Op::Symbol: return 3;
    case Op::Add: return 0;
    case Op::Mul:
    case Op::Div: return 1;
    case Op::Neg: return 2;
    case Op::Pow: {
      const NodeId e = ctx.children(n)[1];
      if (ctx.op(e) == Op::Constant) {
        const double v = ctx.value(e);
        if (v == std::nearbyint(v) && std::fabs(v) <= kMaxInlinePower) return 1;
      }
      return 3;
    }
    default: return 3;
  }
}

// Shortest decimal that reads back as the same double, always with a '.' or an exponent.
std::string number(double v) {
  if (std::isnan(v)) return "std::numeric_limits<double>::quiet_NaN()";
  if (std::isinf(v)) return v > 0 ? "std::numeric_limits<double>::infinity()"
                                   : "(-std::numeric_limits<double>::infinity())";
  char buffer[40];
  for (int digits = 15; digits <= 17; ++digits) {
    std::snprintf(buffer, sizeof buffer, "%.*g", digits, v);
    if (std::strtod(buffer, nullptr) == v) break;
  }
  std::string s = buffer;
  if (s.find_first_of(".en") == std::string::npos) s += ".0";
  return s;
}

bool small_integer_power(const Context& ctx, NodeId n, int* exponent) {
  if (ctx.op(n) != Op::Pow || ctx.op(ctx.children(n)[1]) != Op::Constant) return false;
  const double v = ctx.value(ctx.children(n)[1]);
  if (v != std::nearbyint(v) || std::fabs(v) > kMaxInlinePower) return false;
  *exponent = static_cast<int>(v);
  return true;
}

}  // namespace

namespace emit_detail {

void Printer::print(NodeId n, std::string& out) const {
  if (renamed_ && renaming_) {
    const auto it = renamed_->find(n);
    if (it != renamed_->end()) {
      out += it->second;
      return;
    }
  }
  switch (ctx_.op(n)) {
    case Op::Constant: {
      const double v = ctx_.value(n);
      if (v < 0.0) out += '-';
      out += number(std::fabs(v));
      return;
    }
    case Op::Symbol: {
      const Symbol& s = ctx_.symbol(n);
      if (s.kind == SymbolKind::Aux) out += s.name;
      else out += ctx_.array(s.array).name + "[" + std::to_string(s.index) + "]";
      return;
    }
    case Op::Add: {
      // `b - a` rather than `-a + b`: swapping the first two terms leaves the sum unchanged.
      std::vector<NodeId> terms(ctx_.children(n).begin(), ctx_.children(n).end());
      if (is_negative_term(terms[0]) && !is_negative_term(terms[1])) std::swap(terms[0], terms[1]);
      print(terms[0], out);
      for (std::size_t i = 1; i < terms.size(); ++i) print_term(terms[i], out);
      return;
    }
    case Op::Mul: print_product(n, false, out); return;
    case Op::Neg:
      // -a*b: (-a)*b and -(a*b) are the same double
      out += "-";
      wrapped(ctx_.children(n)[0], 1, out);
      return;
    case Op::Div:
      wrapped(ctx_.children(n)[0], 1, out);
      out += "/";
      wrapped(ctx_.children(n)[1], 3, out);
      return;
    case Op::Pow: {
      int e = 0;
      if (small_integer_power(ctx_, n, &e)) {
        if (e < 0) {
          out += "1.0/";
          if (e == -1) wrapped(ctx_.children(n)[0], 3, out);
          else {
            out += "(";
            repeated(ctx_.children(n)[0], -e, out);
            out += ")";
          }
        } else {
          repeated(ctx_.children(n)[0], e, out);
        }
        return;
      }
      call("std::pow", n, out);
      return;
    }
    case Op::Sin:
    case Op::Cos:
      if (ctx_.is_abbreviation(n)) {
        out += ctx_.abbreviation_name(n);
        return;
      }
      call(ctx_.op(n) == Op::Sin ? "std::sin" : "std::cos", n, out);
      return;
    case Op::Tan: call("std::tan", n, out); return;
    case Op::Atan2: call("std::atan2", n, out); return;
    case Op::Sqrt: call("std::sqrt", n, out); return;
    case Op::Exp: call("std::exp", n, out); return;
    case Op::Log: call("std::log", n, out); return;
    case Op::Abs: call("std::fabs", n, out); return;
    case Op::Min: call("std::fmin", n, out); return;
    case Op::Max: call("std::fmax", n, out); return;
    case Op::Sign: {
      std::string x;
      const Plain plain(*this);
      wrapped(ctx_.children(n)[0], 3, x);
      out += "(" + x + " > 0.0 ? 1.0 : (" + x + " < 0.0 ? -1.0 : 0.0))";
      return;
    }
    case Op::Select: {
      auto k = ctx_.children(n);
      out += "(";
      {
        const Plain plain(*this);
        wrapped(k[0], 1, out);
      }
      out += " > 0.0 ? ";
      print(k[1], out);
      out += " : ";
      print(k[2], out);
      out += ")";
      return;
    }
  }
}

bool Printer::is_negative_term(NodeId t) const {
  switch (ctx_.op(t)) {
    case Op::Neg: return true;
    case Op::Constant: return ctx_.value(t) < 0.0;
    case Op::Mul: {
      const NodeId c = ctx_.children(t)[0];
      return ctx_.op(c) == Op::Constant && ctx_.value(c) < 0.0;
    }
    default: return false;
  }
}

void Printer::wrapped(NodeId n, int needed, std::string& out) const {
  if (precedence(ctx_, n) >= needed) {
    print(n, out);
  } else {
    out += "(";
    print(n, out);
    out += ")";
  }
}

void Printer::repeated(NodeId base, int times, std::string& out) const {
  for (int i = 0; i < times; ++i) {
    if (i) out += "*";
    wrapped(base, 3, out);
  }
}

void Printer::call(const char* function, NodeId n, std::string& out) const {
  const Plain plain(*this);
  out += function;
  out += "(";
  bool first = true;
  for (NodeId c : ctx_.children(n)) {
    if (!first) out += ", ";
    print(c, out);
    first = false;
  }
  out += ")";
}

void Printer::print_term(NodeId t, std::string& out) const {
  switch (ctx_.op(t)) {
    case Op::Neg:
      out += " - ";
      wrapped(ctx_.children(t)[0], 1, out);
      return;
    case Op::Constant:
      if (ctx_.value(t) < 0.0) {
        out += " - ";
        out += number(-ctx_.value(t));
        return;
      }
      break;
    case Op::Mul: {
      const NodeId c = ctx_.children(t)[0];
      if (ctx_.op(c) == Op::Constant && ctx_.value(c) < 0.0) {
        out += " - ";
        print_product(t, true, out);
        return;
      }
      break;
    }
    default: break;
  }
  out += " + ";
  wrapped(t, 1, out);
}

void Printer::print_product(NodeId n, bool negate_coefficient, std::string& out) const {
  std::string numerator, denominator;
  int denominator_factors = 0;
  for (NodeId f : ctx_.children(n)) {
    int e = 0;
    if (ctx_.op(f) == Op::Constant) {
      const double c = negate_coefficient ? -ctx_.value(f) : ctx_.value(f);
      if (!numerator.empty()) numerator += "*";
      if (c < 0.0) numerator += '-';
      numerator += number(std::fabs(c));
    } else if (small_integer_power(ctx_, f, &e) && e < 0) {
      if (!denominator.empty()) denominator += "*";
      repeated(ctx_.children(f)[0], -e, denominator);
      denominator_factors += -e;
    } else {
      if (!numerator.empty()) numerator += "*";
      wrapped(f, 2, numerator);
    }
  }
  out += numerator.empty() ? "1.0" : numerator;
  if (denominator_factors == 1) out += "/" + denominator;
  else if (denominator_factors > 1) out += "/(" + denominator + ")";
}

}  // namespace emit_detail

std::string to_cpp(const Context& context, NodeId expression) {
  std::string s;
  emit_detail::Printer(context).print(expression, s);
  return s;
}

}  // namespace dydp::symbolic
