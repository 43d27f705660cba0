// The multibody front end of dydp-gen: a `*.mbs.yaml` model becomes its generated functions
// (mass matrix columns, residual and tangent, constraints, sensors and tangent, point
// Jacobians), split over translation units, and a GeneratedModel descriptor for the registry.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "generate.hpp"

namespace dydp::gen {

struct MbsGeneration {
  std::vector<FunctionStats> functions;
  // Parts of emitted functions measured alone (not emitted): the residual's inverse dynamics
  // (its first n outputs) and its constraint accelerations (the last m).
  std::vector<FunctionStats> parts;
  std::size_t scheme_assignments = 0;  // the recursive scheme before elimination
  std::vector<std::string> independent;  // names of the independent coordinates
  bool independent_automatic = false;
};

// Writes NAME.hpp, NAME_dynamics.cpp, NAME_residual_tangent.cpp, NAME_velocity_tangent.cpp,
// NAME_tangent_groups.cpp, NAME_tangent_blocks_0.cpp ... NAME_tangent_blocks_3.cpp (kTangentBlockFiles,
// empty for a model without coordinate groups), NAME_kinematics.cpp, NAME_sensors.cpp and
// NAME_model.cpp into out_dir.
// With `expand`, writes only the point Jacobians in extenso (NAME_expanded.hpp/.cpp): the other
// functions' in-extenso forms are far too large to write.
inline constexpr std::size_t kTangentBlockFiles = 4;  // generated_models/CMakeLists.txt lists as many
MbsGeneration generate_mbs(const std::string& model_path, const GenerationOptions& options);

}  // namespace dydp::gen
