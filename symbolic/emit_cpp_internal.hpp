// Private to emit_cpp.cpp, emit_cpp_printer.cpp, emit_cpp_tangent.cpp and emit_cpp_files.cpp (the
// interface is emit_cpp.hpp): the expression printer and the pieces of a function's text that the
// plain and the tangent emitters share.
#pragma once

#include <cstddef>
#include <string>
#include <unordered_map>
#include <vector>

#include "symbolic/dag_walk.hpp"
#include "symbolic/emit_cpp.hpp"

namespace dydp::symbolic::emit_detail {

// Expressions in C++ syntax, with minimal parentheses.
class Printer {
 public:
  explicit Printer(const Context& ctx) : ctx_(ctx) {}
  // Nodes printed under another name where they are arithmetic operands (a tangent's primal
  // values broadcast to both lanes before its loop); conditions and function arguments keep
  // the plain names.
  Printer(const Context& ctx, const std::unordered_map<NodeId, std::string>* renamed) : ctx_(ctx), renamed_(renamed) {}

  void print(NodeId n, std::string& out) const;

 private:
  bool is_negative_term(NodeId t) const;
  void wrapped(NodeId n, int needed, std::string& out) const;
  void repeated(NodeId base, int times, std::string& out) const;
  void call(const char* function, NodeId n, std::string& out) const;
  // A term after the first of a sum: written as a subtraction when it is negative.
  void print_term(NodeId t, std::string& out) const;
  // c * f1 * f2 / (g1 * g2), the g being the factors with negative integer powers.
  void print_product(NodeId n, bool negate_coefficient, std::string& out) const;

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

std::string one_line(std::string s);

// Depth first over the nodes reachable from the list's assignments [first_assignment,
// end_assignment) and outputs [first_output, end_output), each once; visit(n) returns whether to
// go on into n's children.
template <typename Visit>
void walk_range(const EquationList& list, std::size_t first_assignment, std::size_t end_assignment,
                std::size_t first_output, std::size_t end_output, Visit visit) {
  DagWalk walk(list.context());
  for (std::size_t i = first_assignment; i < end_assignment; ++i) walk.walk(list.assignments()[i].value, visit);
  for (std::size_t j = first_output; j < end_output; ++j) walk.walk(list.outputs()[j].value, visit);
}

// The same from `first` to the end of the list.
template <typename Visit>
void walk_list(const EquationList& list, std::size_t first_assignment, std::size_t first_output, Visit visit) {
  walk_range(list, first_assignment, list.size(), first_output, list.outputs().size(), visit);
}

void check_size(const EquationList& list, const EmitOptions& options);
std::string input_parameters(const Context& ctx);

// A signature wrapped after its commas so that no line passes 100 characters.
std::string wrapped_signature(const std::string& signature);
std::string linkage(const EmitOptions& options);

// A definition's first lines: its linkage, the clones' attribute, its signature without the
// linkage (an attribute may not come before `extern "C"`).
std::string cloned_definition(const std::string& signature, const EmitOptions& options);
std::string summary(const EquationList& list, const std::string& name);

// The sines and cosines the list reads, one local each: read from the trig table
// (EmitOptions::trig_table) for the elements of its array, computed otherwise.
void write_prologue(const EquationList& list, const Printer& printer, const EmitOptions& options,
                    std::string& body);
// The list's assignments [begin, end), one local of `type` each, at `indent`.
void write_assignments(const EquationList& list, const Printer& printer, std::size_t begin,
                       std::size_t end, const std::string& indent, std::string& body,
                       const std::string& type = "double");

}  // namespace dydp::symbolic::emit_detail
