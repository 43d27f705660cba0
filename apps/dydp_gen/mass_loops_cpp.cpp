// The mass matrix's loops as C++ (see mass_loops_cpp.hpp).
#include "mass_loops_cpp.hpp"

#include <algorithm>
#include <unordered_map>

#include "symbolic/dag_walk.hpp"
#include "symbolic/op_count.hpp"

namespace dydp::gen {
namespace {

using namespace dydp::symbolic;

const char* const kLaneNames[6] = {"F1", "F2", "F3", "N1", "N2", "N3"};

// The operations of one sweep's body for one lane (sin and cos are read, not called).
OpCount body_ops(Context& ctx, const mbs::MassLoops& loops, const mbs::MassLoops::Sweep& sweep) {
  EquationList body(ctx);
  for (int a = 0; a < 6; ++a)
    if (sweep.moved[a] != loops.lane[a]) body.add_output("moved", ctx.expr(sweep.moved[a]));
  body.add_output("entry", ctx.expr(sweep.entry));
  OpCount ops = count_ops(body);
  ops.call = 0;
  return ops;
}

}  // namespace

void mass_loops_entries(const mbs::MassLoops& loops, std::vector<int>& rows, std::vector<int>& cols) {
  rows.clear();
  cols.clear();
  for (int j : loops.lane_joint) {
    rows.push_back(j);
    cols.push_back(j);
  }
  for (const auto& sweep : loops.sweeps)
    for (int t = sweep.begin; t < sweep.end; ++t) {
      rows.push_back(loops.lane_joint[t]);
      cols.push_back(sweep.parent);
    }
}

std::vector<EmittedFunction> emit_mass_loops(const mbs::MassLoops& loops, const std::string& name,
                                             const std::vector<std::string>& joints, EmitOptions emit,
                                             std::vector<FunctionStats>& stats) {
  Context& ctx = loops.start->context();
  const std::size_t n = loops.lane_joint.size();
  const std::string start_name = name + "_mass_start";
  std::vector<EmittedFunction> functions;

  emit.function_name = start_name;
  functions.push_back(emit_function(*loops.start, emit));
  FunctionStats start_stats{start_name, loops.start->size(), loops.start->size(), count_ops(*loops.start)};
  measure_text(functions.back().definition, start_stats);

  emit.function_name = name + "_mass_matrix";
  EmittedFunction f = emit_function(EquationList(ctx), emit);  // the signature
  FunctionStats stats_loops{f.name, 0, loops.sweeps.size(), start_stats.ops};
  const std::string total = std::to_string(7 * n + loops.reads.size());
  const std::string lanes_type = name + "_lanes", load = name + "_load", store = name + "_store";
  std::string body;
  // One small function per loop: a compiler's time on one function with every loop grows
  // faster than linearly (clang with AddressSanitizer took minutes on chain200's).
  body += "// " + f.name + "'s loops: two lanes at a time, or one (the other zero) at the end of an odd loop\n";
  body += "typedef double " + lanes_type + " __attribute__((vector_size(16)));\n";
  body += "static inline " + lanes_type + " " + load + "(const double* x, bool two) noexcept\n{\n"
          "  " + lanes_type + " v = {x[0], 0.0};\n"
          "  if (two) __builtin_memcpy(&v, x, sizeof v);\n"
          "  return v;\n}\n";
  body += "static inline void " + store + "(double* x, " + lanes_type + " v, bool two) noexcept\n{\n"
          "  if (two) __builtin_memcpy(x, &v, sizeof v);\n"
          "  else x[0] = v[0];\n}\n";
  std::unordered_map<NodeId, std::size_t> read_index;
  for (std::size_t r = 0; r < loops.reads.size(); ++r) read_index[loops.reads[r]] = r;
  std::string calls;
  std::size_t at = n;  // the next entry
  DagWalk walk(ctx);
  for (std::size_t k = 0; k < loops.sweeps.size(); ++k) {
    const auto& sweep = loops.sweeps[k];
    const std::string b = std::to_string(sweep.begin), e = std::to_string(sweep.end);
    const std::string sweep_name = name + "_mass_sweep" + std::to_string(k + 1);
    const std::size_t lanes = static_cast<std::size_t>(sweep.end - sweep.begin);
    body += "// " + joints[sweep.joint] + "'s subtree, lanes " + b + " to " + std::to_string(sweep.end - 1) + ", to " +
            joints[sweep.parent] + "'s frame: M(., " + joints[sweep.parent] + ")\n";
    body += "static void " + sweep_name + "(double* start, double* out) noexcept\n{\n";
    // the values this loop reads besides its lanes
    std::vector<std::size_t> used;
    auto read = [&](NodeId x) {
      const auto it = read_index.find(x);
      if (it == read_index.end()) return true;
      used.push_back(it->second);
      return false;
    };
    walk.restart();
    for (NodeId m : sweep.moved) walk.walk(m, read);
    walk.walk(sweep.entry, read);
    std::sort(used.begin(), used.end());
    for (std::size_t r : used)
      body += "  const double " + to_cpp(ctx, loops.reads[r]) + " = start[" + std::to_string(7 * n + r) + "];\n";
    for (int a = 0; a < 6; ++a)
      body += "  double* const " + std::string(kLaneNames[a]) + " = start + " + std::to_string(a * n) + ";\n";
    body += "  for (int t = " + b + "; t < " + e + "; t += 2) {\n";
    body += "    const bool two = t + 1 < " + e + ";\n";
    for (int a = 0; a < 6; ++a)
      body += "    const " + lanes_type + " " + ctx.symbol(loops.lane[a]).name + " = " + load + "(" + kLaneNames[a] + " + t, two);\n";
    for (int a = 0; a < 6; ++a)
      body += "    const " + lanes_type + " " + ctx.symbol(loops.moved_lane[a]).name + " = " + to_cpp(ctx, sweep.moved[a]) + ";\n";
    for (int a = 0; a < 6; ++a)
      if (sweep.moved[a] != loops.lane[a])
        body += "    " + store + "(" + std::string(kLaneNames[a]) + " + t, " + ctx.symbol(loops.moved_lane[a]).name + ", two);\n";
    body += "    " + store + "(out + " + std::to_string(at) + " + (t - " + b + "), " + to_cpp(ctx, sweep.entry) + ", two);\n";
    body += "  }\n}\n";
    calls += "  " + sweep_name + "(start, out);\n";
    at += lanes;
    const OpCount ops = body_ops(ctx, loops, sweep);
    stats_loops.ops.add += ops.add * lanes;
    stats_loops.ops.mul += ops.mul * lanes;
    stats_loops.ops.div += ops.div * lanes;
  }
  body += "// " + f.name + ": M by composite inertias, from " + start_name +
          "'s lanes (one joint's unit-acceleration\n"
          "// wrench each, in depth-first order) carried to each ancestor's frame by one loop per joint,\n"
          "// deepest first. Entries: M(j, j) by lane, then each loop's, as listed in mass_rows and mass_cols.\n";
  body += f.declaration.substr(0, f.declaration.size() - 2) + "\n{\n";
  body += "  double start[" + total + "];\n";
  body += "  " + start_name + "(";
  for (ArrayId a = 0; a < ctx.array_count(); ++a)
    if (ctx.array(a).kind != SymbolKind::Seed) body += ctx.array(a).name + ", ";
  body += "start);\n";
  body += "  for (int t = 0; t < " + std::to_string(n) + "; ++t) out[t] = start[" + std::to_string(6 * n) + " + t];\n";
  body += calls;
  body += "}\n";
  f.definition = body;
  measure_text(f.definition, stats_loops);
  stats.push_back(start_stats);
  stats.push_back(stats_loops);
  functions.push_back(f);
  return functions;
}

}  // namespace dydp::gen
