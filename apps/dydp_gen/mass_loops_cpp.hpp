// The loop form of a model's mass matrix (mbs::MassLoops) as C++: NAME_mass_start, a plain
// generated function for the lanes' starting values, and NAME_mass_matrix, which carries them
// up the tree one loop per joint, two lanes at a time, and writes M's entries.
#pragma once

#include <string>
#include <vector>

#include "generate.hpp"
#include "symbolic/emit_cpp.hpp"
#include "symbolic/mbs/newton_euler.hpp"

namespace dydp::gen {

// NAME_mass_start and NAME_mass_matrix, in this order (`joints`: the joints' names, for the
// comments). `stats` gets one entry per function: the start's operations as emitted, the
// matrix's as executed (the start's, and each loop body's times its lanes).
std::vector<symbolic::EmittedFunction> emit_mass_loops(const mbs::MassLoops& loops, const std::string& name,
                                                       const std::vector<std::string>& joints,
                                                       symbolic::EmitOptions emit, std::vector<FunctionStats>& stats);

// (row, col) of each output of NAME_mass_matrix: M(j, j) by lane, then each sweep's entries.
void mass_loops_entries(const mbs::MassLoops& loops, std::vector<int>& rows, std::vector<int>& cols);

}  // namespace dydp::gen
