// C++ emission: an equation list becomes a self-contained function (noexcept, no heap, arrays
// in and out, one local per assignment, outputs named in comments); a tangent list becomes a
// function that evaluates the primal once and the derivative part once per direction.
//
// Signatures. Every function of a Context takes its Input and Parameter arrays in creation order:
//   void NAME(const double* q, const double* qd, const double* p, double* out) noexcept;
// A tangent function (list from tangent_list) additionally takes the number of directions and
// one seed block per seeded array, then writes the primal outputs and their derivatives:
//   void NAME(const double* q, const double* qd, const double* p, int nd,
//             const double* seed_q, const double* seed_qd, double* out, double* dout) noexcept;
// Layout, direction-major columns: seed element (i, d) of array q (size n) is seed_q[d*n + i];
// derivative (j, d) of output j (m outputs) is dout[d*m + j]. Directions are a run-time loop
// that takes two at a time (a pair type in the source file, see emit_source_file).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "symbolic/equation_list.hpp"
#include "symbolic/grouped_tangent.hpp"

namespace dydp::symbolic {

struct EmitOptions {
  std::string function_name;
  std::string namespace_name;  // enclosing namespace; empty for none (required for extern_c)
  std::string origin;          // one line for the header comment: model and options it came from
  bool extern_c = false;       // C linkage (for dlopen in tests)
  // Refuse to write more than this many operations (an in-extenso form can be astronomical).
  std::uint64_t max_ops = 20'000'000;
  // When set, sines and cosines of the elements of the input array `trig_array` are read from
  // the table this function returns ({sin x0, cos x0, sin x1, ...}, emit_trig_table), which a
  // model's functions share, instead of each calling std::sin and std::cos.
  std::string trig_table;
  std::string trig_array = "q";
};

struct EmittedFunction {
  std::string name;
  std::string declaration;  // `void NAME(...) noexcept;`
  std::string definition;
  bool uses_lanes = false;  // a tangent: its source file needs the pair type (emit_source_file adds it)
};

// A plain function evaluating every assignment and writing every output to out.
EmittedFunction emit_function(const EquationList& list, const EmitOptions& options);

// A tangent function; `tangent` comes from tangent_list(list, seeded_arrays) with the same arrays.
EmittedFunction emit_tangent(const EquationList& tangent, std::span<const ArrayId> seeded_arrays,
                             const EmitOptions& options);

// A tangent in blocks (grouped_tangent): the primal once, then each block's derivative part over
// its own directions, as functions that may be compiled in translation units of their own (the
// sedan's blocks together are one function of 28 000 assignments otherwise). `entry` has
// emit_tangent's arguments with `const int* nd` (nd[b] directions for block b, the blocks'
// directions consecutive in the seed arrays and in dout) instead of `int nd`; it evaluates the
// primal, writes `out`, stores the primal values the blocks read in a workspace on its stack and
// calls blocks[b] for block b's directions:
//   void NAME_block_B(inputs..., const double* work, int nb, int d0, seeds..., double* dout) noexcept;
// `seeded_arrays`: every array some block seeds, in the order of the seed arguments.
struct GroupedTangentFunctions {
  EmittedFunction entry;
  std::vector<EmittedFunction> blocks;
};
GroupedTangentFunctions emit_grouped_tangent(const GroupedTangent& grouped, std::span<const ArrayId> seeded_arrays,
                                             const EmitOptions& options);

// The table function of EmitOptions::trig_table for an array of `size` elements: sin and cos of
// every element, computed again only when the array differs from the previous call's on the same
// thread (all functions of a model called at one state share one evaluation).
EmittedFunction emit_trig_table(std::size_t size, const EmitOptions& options);

// Whole files: a header declaring the functions and a source including it (by `header_name`).
std::string emit_header_file(std::span<const EmittedFunction> functions, const EmitOptions& options);
std::string emit_source_file(std::span<const EmittedFunction> functions, const std::string& header_name,
                             const EmitOptions& options);

// One expression in C++ syntax, for messages and documentation.
std::string to_cpp(const Context& context, NodeId expression);

}  // namespace dydp::symbolic
