// Writing equation lists as C++: the pieces of a function's text that every emitter shares (see
// emit_cpp_internal.hpp), the plain function and the trig table. The layouts are documented in
// emit_cpp.hpp.
#include "symbolic/emit_cpp.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "symbolic/emit_cpp_internal.hpp"
#include "symbolic/op_count.hpp"

namespace dydp::symbolic {
namespace emit_detail {
namespace {

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

}  // namespace

std::string one_line(std::string s) {
  for (char& c : s) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return s;
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
                       const std::string& type) {
  const Context& ctx = list.context();
  for (std::size_t i = begin; i < end; ++i) {
    const Assignment& a = list.assignments()[i];
    body += indent + "const " + type + " " + ctx.symbol(a.target).name + " = ";
    printer.print(a.value, body);
    body += ";\n";
  }
}

}  // namespace emit_detail

using namespace emit_detail;

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

}  // namespace dydp::symbolic
