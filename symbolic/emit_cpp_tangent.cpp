// Writing tangent lists as C++: emit_tangent (the primal once, then one derivative part over
// every direction, two at a time) and emit_grouped_tangent (an entry, then one function per
// block); the layouts are documented in emit_cpp.hpp.
#include "symbolic/emit_cpp.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "symbolic/emit_cpp_internal.hpp"

namespace dydp::symbolic {

using namespace emit_detail;

namespace {

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

}  // namespace dydp::symbolic
