// Turning one model's equation list into generated C++ and statistics: elimination, optional
// in-extenso expansion, the tangent, emission, op counts. Independent of the model format, so
// each front end (.eqs now, .mbs.yaml later) only has to produce a GenerationInput.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "symbolic/equation_list.hpp"
#include "symbolic/op_count.hpp"

namespace dydp::gen {

struct GenerationInput {
  std::string name;    // function name; the files are NAME.hpp and NAME.cpp
  std::string origin;  // for the header comment: source file and options
  const symbolic::EquationList* list = nullptr;
  std::vector<symbolic::ArrayId> tangent_arrays;  // empty: no tangent function
};

struct FunctionStats {
  std::string name;
  std::size_t equations_before = 0;
  std::size_t equations_after = 0;
  symbolic::OpCount ops;
  // Read off the emitted text: the longest line, and assignments whose right-hand side repeats
  // an earlier assignment's in the same function.
  std::size_t longest_line = 0;
  std::size_t repeated_right_hand_sides = 0;
  // Tangents: the operations of the loop over directions (what each direction costs; the
  // seed-free part is evaluated once with the primal).
  std::uint64_t ops_per_direction = 0;
};

// longest_line and repeated_right_hand_sides of one emitted function's text.
void measure_text(const std::string& definition, FunctionStats& stats);

struct GenerationOptions {
  std::filesystem::path out_dir;
  bool expand = false;  // emit the in-extenso form instead of the recursive one
};

// Writes NAME.hpp and NAME.cpp into out_dir (each through a temporary name, then renamed) and
// returns the statistics of every emitted function.
std::vector<FunctionStats> generate(const GenerationInput& input, const GenerationOptions& options);

// stats.json as in the CLI contract of docs (DESIGN.md, section 5).
// `scheme_assignments` (multibody models): the whole recursive scheme before elimination;
// `parts`: parts of functions measured alone ("parts", same fields without the text measures).
std::string stats_json(const std::vector<FunctionStats>& functions, double seconds,
                       std::size_t scheme_assignments = 0, const std::vector<FunctionStats>& parts = {});

// Writes `text` to `path` through a temporary file in the same folder, then renames it.
void write_atomically(const std::filesystem::path& path, const std::string& text);

}  // namespace dydp::gen
