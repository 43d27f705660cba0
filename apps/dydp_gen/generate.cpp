// The generation pipeline of dydp-gen: eliminate, (expand), differentiate, emit, count.
#include "generate.hpp"

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <unordered_set>

#include "symbolic/compact.hpp"
#include "symbolic/differentiate.hpp"
#include "symbolic/eliminate.hpp"
#include "symbolic/emit_cpp.hpp"
#include "symbolic/expand.hpp"

namespace dydp::gen {

using namespace dydp::symbolic;

void write_atomically(const std::filesystem::path& path, const std::string& text) {
  // A file that already holds the text keeps its time stamp, so that the build (ninja's restat)
  // recompiles only the generated files that changed when the generator is rebuilt.
  {
    std::ifstream in(path, std::ios::binary);
    if (in) {
      std::ostringstream existing;
      existing << in.rdbuf();
      if (existing.str() == text) return;
    }
  }
  const std::filesystem::path temporary = path.string() + ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot write " + temporary.string());
    out << text;
    out.flush();
    if (!out) throw std::runtime_error("cannot write " + temporary.string());
  }
  std::filesystem::rename(temporary, path);
}

void measure_text(const std::string& definition, FunctionStats& stats) {
  std::istringstream lines(definition);
  std::unordered_set<std::string> right_hand_sides;
  std::string line;
  stats.longest_line = 0;
  stats.repeated_right_hand_sides = 0;
  while (std::getline(lines, line)) {
    stats.longest_line = std::max(stats.longest_line, line.size());
    const std::size_t start = line.find_first_not_of(' ');
    if (start == std::string::npos || line.compare(start, 13, "const double ") != 0) continue;
    const std::size_t equals = line.find(" = ", start);
    if (equals == std::string::npos) continue;
    if (!right_hand_sides.insert(line.substr(equals + 3)).second) ++stats.repeated_right_hand_sides;
  }
}

std::vector<FunctionStats> generate(const GenerationInput& input, const GenerationOptions& options) {
  if (!input.list) throw std::invalid_argument("generate: no equation list");
  EliminationStats elimination;
  EquationList kept = eliminate(*input.list, &elimination);
  const std::size_t before = elimination.before;

  EmitOptions emit;
  emit.origin = input.origin;
  emit.namespace_name = "dydp::generated";
  std::vector<EmittedFunction> functions;
  std::vector<FunctionStats> stats;

  // In the in-extenso form there are no assignments: the equations are the output expressions.
  auto record = [&](const std::string& name, std::size_t equations_before, const EquationList& list) {
    const std::size_t after = options.expand ? list.outputs().size() : list.size();
    stats.push_back(FunctionStats{name, equations_before, after, count_ops(list)});
  };

  emit.function_name = input.name;
  const EquationList primal = options.expand ? expand(kept) : compact(kept);
  functions.push_back(emit_function(primal, emit));
  record(input.name, before, primal);
  measure_text(functions.back().definition, stats.back());

  if (!input.tangent_arrays.empty()) {
    // as tangent_list, keeping the size before elimination for the statistics
    const Direction direction = seeded(kept.context(), input.tangent_arrays);
    EliminationStats tangent_elimination;
    // the recursive form differentiates the compact scheme, so the tangent's size follows it
    const EquationList source = options.expand ? kept : compact(kept);
    const EquationList tangent =
        eliminate(differentiate(source, std::span<const Direction>(&direction, 1)), &tangent_elimination);
    const EquationList written = options.expand ? expand(tangent) : compact(tangent);
    emit.function_name = input.name + "_tangent";
    functions.push_back(emit_tangent(written, input.tangent_arrays, emit));
    record(emit.function_name, tangent_elimination.before, written);
    measure_text(functions.back().definition, stats.back());
  }

  std::filesystem::create_directories(options.out_dir);
  const std::string header = input.name + ".hpp";
  write_atomically(options.out_dir / header, emit_header_file(functions, emit));
  write_atomically(options.out_dir / (input.name + ".cpp"), emit_source_file(functions, header, emit));
  return stats;
}

std::string stats_json(const std::vector<FunctionStats>& functions, double seconds, std::size_t scheme_assignments,
                       const std::vector<FunctionStats>& parts) {
  std::ostringstream s;
  s << "{\n  \"functions\": {";
  for (std::size_t i = 0; i < functions.size(); ++i) {
    const FunctionStats& f = functions[i];
    s << (i ? ",\n" : "\n") << "    \"" << f.name << "\": {\"equations_before\": " << f.equations_before
      << ", \"equations_after\": " << f.equations_after << ", \"ops\": {\"add\": " << f.ops.add
      << ", \"mul\": " << f.ops.mul << ", \"div\": " << f.ops.div << ", \"call\": " << f.ops.call
      << "}, \"ops_total\": " << f.ops.total() << ", \"longest_line\": " << f.longest_line
      << ", \"repeated_right_hand_sides\": " << f.repeated_right_hand_sides;
    if (f.ops_per_direction) s << ", \"ops_per_direction\": " << f.ops_per_direction;
    s << "}";
  }
  s << "\n  },\n";
  if (!parts.empty()) {
    s << "  \"parts\": {";
    for (std::size_t i = 0; i < parts.size(); ++i) {
      const FunctionStats& f = parts[i];
      s << (i ? ",\n" : "\n") << "    \"" << f.name << "\": {\"equations\": " << f.equations_after
        << ", \"ops\": {\"add\": " << f.ops.add << ", \"mul\": " << f.ops.mul << ", \"div\": " << f.ops.div
        << ", \"call\": " << f.ops.call << "}, \"ops_total\": " << f.ops.total();
      if (f.ops_per_direction) s << ", \"ops_per_direction\": " << f.ops_per_direction;
      s << "}";
    }
    s << "\n  },\n";
  }
  s.precision(6);
  if (scheme_assignments) s << "  \"scheme_assignments\": " << scheme_assignments << ",\n";
  s << "  \"seconds\": " << std::fixed << seconds << "\n}\n";
  return s.str();
}

}  // namespace dydp::gen
