// Writing equation lists as C++: an expression printer with minimal parentheses, and the
// function and file layouts documented in emit_cpp.hpp.
#include "symbolic/emit_cpp.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <stdexcept>
#include <unordered_map>

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

class Printer {
 public:
  explicit Printer(const Context& ctx) : ctx_(ctx) {}
  // Nodes printed under another name where they are arithmetic operands (a tangent's primal
  // values broadcast to both lanes before its loop); conditions and function arguments keep
  // the plain names.
  Printer(const Context& ctx, const std::unordered_map<NodeId, std::string>* renamed) : ctx_(ctx), renamed_(renamed) {}

  void print(NodeId n, std::string& out) const {
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

 private:
  bool is_negative_term(NodeId t) const {
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

  void wrapped(NodeId n, int needed, std::string& out) const {
    if (precedence(ctx_, n) >= needed) {
      print(n, out);
    } else {
      out += "(";
      print(n, out);
      out += ")";
    }
  }

  void repeated(NodeId base, int times, std::string& out) const {
    for (int i = 0; i < times; ++i) {
      if (i) out += "*";
      wrapped(base, 3, out);
    }
  }

  void call(const char* function, NodeId n, std::string& out) const {
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

  // A term after the first of a sum: written as a subtraction when it is negative.
  void print_term(NodeId t, std::string& out) const {
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

  // c * f1 * f2 / (g1 * g2), the g being the factors with negative integer powers.
  void print_product(NodeId n, bool negate_coefficient, std::string& out) const {
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

  // Renaming off for its lifetime (restored after).
  struct Plain {
    explicit Plain(const Printer& p) : printer(p), was(p.renaming_) { p.renaming_ = false; }
    ~Plain() { printer.renaming_ = was; }
    const Printer& printer;
    bool was;
  };

  const Context& ctx_;
  const std::unordered_map<NodeId, std::string>* renamed_ = nullptr;
  mutable bool renaming_ = true;
};

// Each emitted function is compiled twice, for any x86-64 processor and for one with AVX2, and
// the dynamic loader binds the one the processor runs (GCC's target_clones, an ifunc). AVX's
// three-operand instructions spare the register copies SSE2's two-operand ones need (a fifth of
// the sedan's velocity tangent's code). AVX2 does not imply FMA: no multiply and add is fused,
// so both clones round every operation alike and agree to the bit.
const char* const kClonesMacro = R"(#if !defined(DYDP_VECTOR_CLONES)
#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && defined(__linux__)
#define DYDP_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define DYDP_VECTOR_CLONES
#endif
#endif

)";

// The pair type of emit_tangent's two directions per pass, written once into a source file
// that holds a tangent: a GCC/Clang vector of two doubles (plain members elsewhere), which a
// double converts to in both lanes, so that a derivative reads primal values and constants as
// they are printed.
const char* const kLanes = R"(namespace {

struct Lanes {
#if defined(__GNUC__)
  typedef double Pair __attribute__((vector_size(16)));
  Pair v;
  Lanes(Pair x) : v(x) {}
  Lanes(double a, double b) : v(Pair{a, b}) {}
  double first() const { return v[0]; }
  double second() const { return v[1]; }
#else
  double a_, b_;
  Lanes(double a, double b) : a_(a), b_(b) {}
  double first() const { return a_; }
  double second() const { return b_; }
#endif
  Lanes(double x) : Lanes(x, x) {}  // NOLINT(google-explicit-constructor): constants and primal values
};
#if defined(__GNUC__)
[[maybe_unused]] inline Lanes operator+(Lanes x, Lanes y) { return Lanes(x.v + y.v); }
[[maybe_unused]] inline Lanes operator-(Lanes x, Lanes y) { return Lanes(x.v - y.v); }
[[maybe_unused]] inline Lanes operator*(Lanes x, Lanes y) { return Lanes(x.v * y.v); }
[[maybe_unused]] inline Lanes operator/(Lanes x, Lanes y) { return Lanes(x.v / y.v); }
[[maybe_unused]] inline Lanes operator-(Lanes x) { return Lanes(-x.v); }
#else
[[maybe_unused]] inline Lanes operator+(Lanes x, Lanes y) { return Lanes(x.a_ + y.a_, x.b_ + y.b_); }
[[maybe_unused]] inline Lanes operator-(Lanes x, Lanes y) { return Lanes(x.a_ - y.a_, x.b_ - y.b_); }
[[maybe_unused]] inline Lanes operator*(Lanes x, Lanes y) { return Lanes(x.a_ * y.a_, x.b_ * y.b_); }
[[maybe_unused]] inline Lanes operator/(Lanes x, Lanes y) { return Lanes(x.a_ / y.a_, x.b_ / y.b_); }
[[maybe_unused]] inline Lanes operator-(Lanes x) { return Lanes(-x.a_, -x.b_); }
#endif

// The seeds of two directions: element i of each.
struct LaneSeed {
  const double* a;
  const double* b;
  Lanes operator[](int i) const { return Lanes(a[i], b[i]); }
};

[[maybe_unused]] inline void store_lanes(double* a, double* b, int j, Lanes x) {
  a[j] = x.first();
  b[j] = x.second();
}

// One direction (an odd last one): the same derivative code on plain doubles, reading the
// primal values as they are.
struct One {
  double v;
  One(double x) : v(x) {}  // NOLINT(google-explicit-constructor): constants and primal values
};
[[maybe_unused]] inline One operator+(One x, One y) { return One(x.v + y.v); }
[[maybe_unused]] inline One operator-(One x, One y) { return One(x.v - y.v); }
[[maybe_unused]] inline One operator*(One x, One y) { return One(x.v * y.v); }
[[maybe_unused]] inline One operator/(One x, One y) { return One(x.v / y.v); }
[[maybe_unused]] inline One operator-(One x) { return One(-x.v); }

struct OneSeed {
  const double* a;
  One operator[](int i) const { return One(a[i]); }
};

// (dout_b is a null constant there: the overload is chosen by its type, so that a constant 0.0
// stores as One)
[[maybe_unused]] inline void store_lanes(double* a, decltype(nullptr), int j, One x) { a[j] = x.v; }

}  // namespace

)";

std::string one_line(std::string s) {
  for (char& c : s) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return s;
}

// Depth first over the nodes reachable from the list's assignments [first_assignment,
// end_assignment) and outputs [first_output, end_output), each once; visit(n) returns whether to
// go on into n's children.
template <typename Visit>
void walk_range(const EquationList& list, std::size_t first_assignment, std::size_t end_assignment,
                std::size_t first_output, std::size_t end_output, Visit visit) {
  const Context& ctx = list.context();
  std::vector<char> seen(ctx.size(), 0);
  std::vector<NodeId> stack;
  auto walk = [&](NodeId root) {
    stack.push_back(root);
    while (!stack.empty()) {
      const NodeId n = stack.back();
      stack.pop_back();
      if (seen[n]) continue;
      seen[n] = 1;
      if (!visit(n)) continue;
      for (NodeId c : ctx.children(n)) stack.push_back(c);
    }
  };
  for (std::size_t i = first_assignment; i < end_assignment; ++i) walk(list.assignments()[i].value);
  for (std::size_t j = first_output; j < end_output; ++j) walk(list.outputs()[j].value);
}

// The same from `first` to the end of the list.
template <typename Visit>
void walk_list(const EquationList& list, std::size_t first_assignment, std::size_t first_output, Visit visit) {
  walk_range(list, first_assignment, list.size(), first_output, list.outputs().size(), visit);
}

// Abbreviations (S3, C3) the list reads, in node order.
std::vector<NodeId> abbreviations_used(const EquationList& list) {
  const Context& ctx = list.context();
  std::vector<NodeId> found;
  walk_list(list, 0, 0, [&](NodeId n) {
    if (!ctx.is_abbreviation(n)) return true;
    found.push_back(n);
    return false;
  });
  // by argument, sine before cosine: S2, C2, S3, C3
  std::sort(found.begin(), found.end(), [&](NodeId a, NodeId b) {
    const NodeId xa = ctx.children(a)[0], xb = ctx.children(b)[0];
    if (xa != xb) return xa < xb;
    return ctx.op(a) == Op::Sin && ctx.op(b) != Op::Sin;
  });
  return found;
}

// The primal values (primal auxiliaries, sines and cosines, input and parameter elements) that a
// derivative part (the block's assignments and outputs) reads as arithmetic operands, each with
// its name as a pair (`lane_RJ12_8`); conditions (select, sign) and function arguments are not
// entered.
std::unordered_map<NodeId, std::string> primal_values_read(const EquationList& tangent, const TangentBlock& block) {
  const Context& ctx = tangent.context();
  std::vector<char> primal(ctx.size(), 0);
  for (std::size_t i = 0; i < tangent.primal_assignments(); ++i) primal[tangent.assignments()[i].target] = 1;
  std::unordered_map<NodeId, std::string> names;
  walk_range(tangent, block.assignments_begin, block.assignments_end, block.outputs_begin, block.outputs_end,
             [&](NodeId x) {
    const Op op = ctx.op(x);
    if (ctx.is_abbreviation(x)) {
      names.emplace(x, "lane_" + ctx.abbreviation_name(x));
      return false;
    }
    if (op == Op::Symbol) {
      const Symbol& sym = ctx.symbol(x);
      if (sym.kind == SymbolKind::Aux && primal[x]) names.emplace(x, "lane_" + sym.name);
      else if (sym.kind == SymbolKind::Input || sym.kind == SymbolKind::Parameter)
        names.emplace(x, "lane_" + ctx.array(sym.array).name + "_" + std::to_string(sym.index));
      return false;
    }
    return op == Op::Add || op == Op::Mul || op == Op::Neg || op == Op::Div;
  });
  return names;
}

void check_size(const EquationList& list, const EmitOptions& options) {
  const OpCount ops = count_ops(list);
  if (ops.total() > options.max_ops) {
    throw std::length_error("symbolic: " + options.function_name + " would be written with " +
                            std::to_string(ops.total()) + " operations (limit " +
                            std::to_string(options.max_ops) + ")");
  }
}

std::string input_parameters(const Context& ctx) {
  std::string s;
  for (ArrayId a = 0; a < ctx.array_count(); ++a) {
    if (ctx.array(a).kind == SymbolKind::Seed) continue;
    s += "[[maybe_unused]] const double* " + ctx.array(a).name + ", ";
  }
  return s;
}

// A signature wrapped after its commas so that no line passes 100 characters.
std::string wrapped_signature(const std::string& signature) {
  std::string s;
  std::size_t line = 0;
  std::size_t at = 0;
  while (at < signature.size()) {
    std::size_t next = signature.find(", ", at);
    const std::string piece = next == std::string::npos ? signature.substr(at) : signature.substr(at, next + 2 - at);
    if (line > 0 && line + piece.size() > 100) {
      s.back() = '\n';  // the space after the comma
      s += "    ";
      line = 4;
    }
    s += piece;
    line += piece.size();
    at = next == std::string::npos ? signature.size() : next + 2;
  }
  return s;
}

std::string linkage(const EmitOptions& options) { return options.extern_c ? "extern \"C\" " : ""; }

// A definition's first lines: its linkage, the clones' attribute, its signature without the
// linkage (an attribute may not come before `extern "C"`).
std::string cloned_definition(const std::string& signature, const EmitOptions& options) {
  const std::string l = linkage(options);
  return l + "DYDP_VECTOR_CLONES\n" + wrapped_signature(signature.substr(l.size()));
}

std::string summary(const EquationList& list, const std::string& name) {
  const OpCount ops = count_ops(list);
  return "// " + name + ": " + std::to_string(list.size()) + " assignments; " +
         std::to_string(ops.add) + " add, " + std::to_string(ops.mul) + " mul, " +
         std::to_string(ops.div) + " div, " + std::to_string(ops.call) + " call\n";
}

// The element index of node x in the input array named `name`, or -1.
long element_of(const Context& ctx, NodeId x, const std::string& name) {
  for (ArrayId a = 0; a < ctx.array_count(); ++a) {
    const Array& array = ctx.array(a);
    if (array.name != name || array.kind == SymbolKind::Seed) continue;
    for (std::size_t i = 0; i < array.elements.size(); ++i)
      if (array.elements[i] == x) return static_cast<long>(i);
  }
  return -1;
}

void write_prologue(const EquationList& list, const Printer& printer, const EmitOptions& options,
                    std::string& body) {
  const Context& ctx = list.context();
  bool table_read = false;
  for (NodeId n : abbreviations_used(list)) {
    const NodeId x = ctx.children(n)[0];
    const bool sine = ctx.op(n) == Op::Sin;
    const long i = options.trig_table.empty() ? -1 : element_of(ctx, x, options.trig_array);
    if (i >= 0) {
      if (!table_read) {
        body += "  const double* const trig = " + options.trig_table + "(" + options.trig_array + ");\n";
        table_read = true;
      }
      body += "  const double " + ctx.abbreviation_name(n) + " = trig[" + std::to_string(2 * i + (sine ? 0 : 1)) + "];\n";
      continue;
    }
    body += "  const double " + ctx.abbreviation_name(n) + " = " + (sine ? "std::sin(" : "std::cos(");
    printer.print(x, body);
    body += ");\n";
  }
}

void write_assignments(const EquationList& list, const Printer& printer, std::size_t begin,
                       std::size_t end, const std::string& indent, std::string& body,
                       const std::string& type = "double") {
  const Context& ctx = list.context();
  for (std::size_t i = begin; i < end; ++i) {
    const Assignment& a = list.assignments()[i];
    body += indent + "const " + type + " " + ctx.symbol(a.target).name + " = ";
    printer.print(a.value, body);
    body += ";\n";
  }
}

}  // namespace

std::string to_cpp(const Context& context, NodeId expression) {
  std::string s;
  Printer(context).print(expression, s);
  return s;
}

EmittedFunction emit_function(const EquationList& list, const EmitOptions& options) {
  check_size(list, options);
  const Context& ctx = list.context();
  const Printer printer(ctx);
  const std::string signature = linkage(options) + "void " + options.function_name + "(" +
                                input_parameters(ctx) + "double* out) noexcept";
  std::string body = summary(list, options.function_name) + cloned_definition(signature, options) + "\n{\n";
  write_prologue(list, printer, options, body);
  write_assignments(list, printer, 0, list.size(), "  ", body);
  for (std::size_t j = 0; j < list.outputs().size(); ++j) {
    const Output& o = list.outputs()[j];
    body += "  out[" + std::to_string(j) + "] = ";
    printer.print(o.value, body);
    body += ";  // " + one_line(o.name) + "\n";
  }
  body += "}\n";
  return EmittedFunction{options.function_name, wrapped_signature(signature) + ";\n", body};
}

namespace {

// A derivative part: its directions d = first .. first + count - 1 (C++ expressions), two at a
// time on pairs (Lanes, one SSE2 register), so that a direction costs about half the
// instructions. The primal values it reads are broadcast to both lanes once before the loop:
// read in the loop as a pair from memory, not loaded and unpacked once per pass. An odd last
// direction (a sensitivity pass has one) runs the same derivative code once more on plain
// doubles (One, OneSeed), reading the primal values as they are: with one direction, nothing is
// broadcast. Seed (i, d) of array x at seed_x[d*size + i], derivative (j, d) at dout[d*k + j].
void write_block(const EquationList& tangent, const TangentBlock& block, const std::string& count,
                 const std::string& first, const std::string& indent, std::string& body) {
  const Context& ctx = tangent.context();
  const Printer printer(ctx);
  const std::unordered_map<NodeId, std::string> lane_names = primal_values_read(tangent, block);
  std::vector<std::pair<NodeId, std::string>> sorted(lane_names.begin(), lane_names.end());
  std::sort(sorted.begin(), sorted.end());
  const Printer lane_printer(ctx, &lane_names);
  const std::string k = std::to_string(block.outputs_end - block.outputs_begin);
  // the derivative part for either lane type, at `in`
  auto derivative_part = [&](const Printer& p, const std::string& in) {
    std::string text;
    write_assignments(tangent, p, block.assignments_begin, block.assignments_end, in, text, "auto");
    for (std::size_t j = block.outputs_begin; j < block.outputs_end; ++j) {
      const Output& o = tangent.outputs()[j];
      text += in + "store_lanes(dout_a, dout_b, " + std::to_string(j - block.outputs_begin) + ", ";
      p.print(o.value, text);
      text += ");  // " + one_line(o.name) + "\n";
    }
    return text;
  };
  // each seed array as the pass reads it: `dq{seed_q + d*33, seed_q + (d + 1)*33}` for a pair,
  // `dq{seed_q + d*33}` for one direction
  auto declare_seeds = [&](const std::string& type, bool pair, const std::string& in) {
    for (const auto& [array, seed_array] : block.seeds) {
      const Array& seed = ctx.array(seed_array);
      const std::string size = std::to_string(seed.elements.size()), from = "seed_" + ctx.array(array).name;
      body += in + "[[maybe_unused]] const " + type + " " + seed.name + "{" + from + " + d*" + size;
      if (pair) body += ", " + from + " + (d + 1)*" + size;
      body += "};\n";
    }
  };
  const std::string end = first == "0" ? count : first + " + " + count;
  body += indent + "if (" + count + " >= 2) {\n";
  for (const auto& [x, name] : sorted) {
    body += indent + "  const Lanes " + name + " = ";
    printer.print(x, body);
    body += ";\n";
  }
  body += indent + "  for (int d = " + first + "; d + 1 < " + end + "; d += 2) {\n";
  declare_seeds("LaneSeed", true, indent + "    ");
  body += indent + "    double* const dout_a = dout + d*" + k + ";\n";
  body += indent + "    [[maybe_unused]] double* const dout_b = dout_a + " + k + ";\n";
  body += derivative_part(lane_printer, indent + "    ");
  body += indent + "  }\n";
  body += indent + "}\n";
  body += indent + "if (" + count + " % 2 == 1) {\n";
  body += indent + "  const int d = " + end + " - 1;\n";
  declare_seeds("OneSeed", false, indent + "  ");
  body += indent + "  double* const dout_a = dout + d*" + k + ";\n";
  body += indent + "  [[maybe_unused]] constexpr decltype(nullptr) dout_b = nullptr;\n";
  body += derivative_part(printer, indent + "  ");
  body += indent + "}\n";
}

// The prologue, the primal assignments and the primal outputs of a tangent list.
void write_primal(const EquationList& tangent, const EmitOptions& options, std::string& body) {
  const Printer printer(tangent.context());
  write_prologue(tangent, printer, options, body);
  write_assignments(tangent, printer, 0, tangent.primal_assignments(), "  ", body);
  for (std::size_t j = 0; j < tangent.primal_outputs(); ++j) {
    const Output& o = tangent.outputs()[j];
    body += "  out[" + std::to_string(j) + "] = ";
    printer.print(o.value, body);
    body += ";  // " + one_line(o.name) + "\n";
  }
}

std::string seed_parameters(const Context& ctx, std::span<const ArrayId> seeded_arrays) {
  std::string seeds;
  for (ArrayId a : seeded_arrays) seeds += "const double* seed_" + ctx.array(a).name + ", ";
  return seeds;
}

}  // namespace

EmittedFunction emit_tangent(const EquationList& tangent, std::span<const ArrayId> seeded_arrays,
                             const EmitOptions& options) {
  if (!tangent.has_split()) throw std::invalid_argument("symbolic: emit_tangent needs a list from tangent_list");
  check_size(tangent, options);
  Context& ctx = tangent.context();
  const std::string signature = linkage(options) + "void " + options.function_name + "(" +
                                input_parameters(ctx) + "int nd, " + seed_parameters(ctx, seeded_arrays) +
                                "double* out, double* dout) noexcept";
  TangentBlock block;
  for (ArrayId a : seeded_arrays) block.seeds.emplace_back(a, ctx.seed_array(a));
  block.assignments_begin = tangent.primal_assignments();
  block.assignments_end = tangent.size();
  block.outputs_begin = tangent.primal_outputs();
  block.outputs_end = tangent.outputs().size();
  std::string body = summary(tangent, options.function_name) +
                     "// primal once, then the derivative part once per direction d < nd;\n"
                     "// seed (i, d) at seed_x[d*n + i], derivative (j, d) at dout[d*" +
                     std::to_string(block.outputs_end - block.outputs_begin) + " + j]\n" +
                     cloned_definition(signature, options) + "\n{\n";
  write_primal(tangent, options, body);
  write_block(tangent, block, "nd", "0", "  ", body);
  body += "}\n";
  return EmittedFunction{options.function_name, wrapped_signature(signature) + ";\n", body, true};
}

GroupedTangentFunctions emit_grouped_tangent(const GroupedTangent& grouped, std::span<const ArrayId> seeded_arrays,
                                             const EmitOptions& options) {
  const EquationList& tangent = grouped.list;
  check_size(tangent, options);
  const Context& ctx = tangent.context();
  std::vector<char> primal(ctx.size(), 0);
  for (std::size_t i = 0; i < tangent.primal_assignments(); ++i) primal[tangent.assignments()[i].target] = 1;
  // per block, the primal auxiliaries and sines and cosines it reads anywhere (operands,
  // conditions, arguments), in node order; their union is the workspace, each at its slot
  std::vector<std::vector<NodeId>> reads(grouped.blocks.size());
  std::vector<long> slot(ctx.size(), -1);
  for (std::size_t b = 0; b < grouped.blocks.size(); ++b) {
    const TangentBlock& block = grouped.blocks[b];
    walk_range(tangent, block.assignments_begin, block.assignments_end, block.outputs_begin, block.outputs_end,
               [&](NodeId x) {
      const bool value = ctx.is_abbreviation(x) ||
                         (ctx.op(x) == Op::Symbol && ctx.symbol(x).kind == SymbolKind::Aux && primal[x]);
      if (value) reads[b].push_back(x);
      return !value && ctx.op(x) != Op::Symbol;
    });
    std::sort(reads[b].begin(), reads[b].end());
    for (NodeId x : reads[b]) slot[x] = 0;
  }
  std::vector<NodeId> workspace;
  for (NodeId x = 0; x < ctx.size(); ++x)
    if (slot[x] == 0) {
      slot[x] = static_cast<long>(workspace.size());
      workspace.push_back(x);
    }
  auto value_name = [&](NodeId x) { return ctx.is_abbreviation(x) ? ctx.abbreviation_name(x) : ctx.symbol(x).name; };

  GroupedTangentFunctions result;
  std::string inputs;  // the input arrays as arguments
  for (ArrayId a = 0; a < ctx.array_count(); ++a)
    if (ctx.array(a).kind != SymbolKind::Seed) inputs += ctx.array(a).name + ", ";
  std::string seeds;  // the seed arrays as arguments
  for (ArrayId a : seeded_arrays) seeds += "seed_" + ctx.array(a).name + ", ";
  std::string seed_declarations;
  for (ArrayId a : seeded_arrays) seed_declarations += "[[maybe_unused]] const double* seed_" + ctx.array(a).name + ", ";

  const std::string entry_signature = linkage(options) + "void " + options.function_name + "(" +
                                      input_parameters(ctx) + "const int* nd, " + seed_parameters(ctx, seeded_arrays) +
                                      "double* out, double* dout) noexcept";
  std::string entry = summary(tangent, options.function_name) +
                      "// primal once, the primal values the blocks read stored in a workspace, then each block's\n"
                      "// function once per direction of that block: nd[b] directions for block b, the blocks'\n"
                      "// directions one after the other; seed (i, d) at seed_x[d*n + i], derivative (j, d) at\n"
                      "// dout[d*k + j]\n" +
                      cloned_definition(entry_signature, options) + "\n{\n";
  write_primal(tangent, options, entry);
  entry += "  double work[" + std::to_string(std::max<std::size_t>(workspace.size(), 1)) + "];\n";
  for (std::size_t k = 0; k < workspace.size(); ++k)
    entry += "  work[" + std::to_string(k) + "] = " + value_name(workspace[k]) + ";\n";
  entry += "  int d0 = 0;\n";
  for (std::size_t b = 0; b < grouped.blocks.size(); ++b) {
    const TangentBlock& block = grouped.blocks[b];
    const std::string name = options.function_name + "_block_" + std::to_string(b);
    const std::string nb = "nd[" + std::to_string(b) + "]";
    entry += "  if (" + nb + " > 0) " + name + "(" + inputs + "work, " + nb + ", d0, " + seeds + "dout);\n";
    entry += "  d0 += " + nb + ";\n";

    std::string seeded;
    for (const auto& [array, seed] : block.seeds) seeded += " " + ctx.array(array).name;
    const std::string signature = linkage(options) + "void " + name + "(" + input_parameters(ctx) +
                                  "const double* work, int nb, int d0, " + seed_declarations + "double* dout) noexcept";
    std::string body = "// block " + std::to_string(b) + " of " + options.function_name + " (" +
                       std::to_string(block.assignments_end - block.assignments_begin) +
                       " assignments), seeded on" + seeded + ":\n// " + one_line(block.label) +
                       "; the primal values it reads come from work\n" + cloned_definition(signature, options) +
                       "\n{\n";
    for (NodeId x : reads[b])
      body += "  const double " + value_name(x) + " = work[" + std::to_string(slot[x]) + "];\n";
    write_block(tangent, block, "nb", "d0", "  ", body);
    body += "}\n";
    result.blocks.push_back(EmittedFunction{name, wrapped_signature(signature) + ";\n", body, true});
  }
  entry += "}\n";
  result.entry = EmittedFunction{options.function_name, wrapped_signature(entry_signature) + ";\n", entry, false};
  return result;
}

EmittedFunction emit_trig_table(std::size_t size, const EmitOptions& options) {
  const std::string n = std::to_string(size), x = options.trig_array;
  const std::string signature = linkage(options) + "const double* " + options.trig_table + "(const double* " + x + ") noexcept";
  std::string body = "// sin and cos of every " + x + "[i] at table[2*i] and table[2*i + 1], on this thread computed\n" +
                     "// again only for the entries that differ from the previous call's (a Newton iteration on the\n" +
                     "// constraints moves the dependent coordinates only)\n" + signature + "\n{\n";
  body += "  thread_local double last[" + n + "];\n";
  body += "  thread_local double table[2*" + n + "];\n";
  body += "  thread_local bool filled = false;\n";
  body += "  if (filled && std::memcmp(last, " + x + ", sizeof last) == 0) return table;\n";
  body += "  for (int i = 0; i < " + n + "; ++i) {\n";
  body += "    const double v = " + x + "[i];  // read once: the compiler pairs sin and cos into one sincos\n";
  body += "    if (filled && v == last[i] && std::signbit(v) == std::signbit(last[i])) continue;  // the same bits\n";
  body += "    table[2*i] = std::sin(v);\n";
  body += "    table[2*i + 1] = std::cos(v);\n";
  body += "    last[i] = v;\n";
  body += "  }\n";
  body += "  filled = true;\n";
  body += "  return table;\n}\n";
  return EmittedFunction{options.trig_table, signature + ";\n", body};
}

std::string emit_header_file(std::span<const EmittedFunction> functions, const EmitOptions& options) {
  std::string s = "// Generated by dydp-gen; do not edit.\n// Source: " + one_line(options.origin) +
                  "\n#pragma once\n\n";
  if (!options.namespace_name.empty()) s += "namespace " + options.namespace_name + " {\n\n";
  for (const EmittedFunction& f : functions) s += f.declaration;
  if (!options.namespace_name.empty()) s += "\n}  // namespace " + options.namespace_name + "\n";
  return s;
}

std::string emit_source_file(std::span<const EmittedFunction> functions, const std::string& header_name,
                             const EmitOptions& options) {
  std::string s = "// Generated by dydp-gen; do not edit.\n// Source: " + one_line(options.origin) +
                  "\n";
  if (!header_name.empty()) s += "#include \"" + header_name + "\"\n\n";
  s += "#include <cmath>\n#include <cstring>\n#include <limits>\n\n";
  s += kClonesMacro;
  if (std::any_of(functions.begin(), functions.end(), [](const EmittedFunction& f) { return f.uses_lanes; }))
    s += kLanes;
  if (!options.namespace_name.empty()) s += "namespace " + options.namespace_name + " {\n\n";
  for (const EmittedFunction& f : functions) s += f.definition + "\n";
  if (!options.namespace_name.empty()) s += "}  // namespace " + options.namespace_name + "\n";
  return s;
}

}  // namespace dydp::symbolic
