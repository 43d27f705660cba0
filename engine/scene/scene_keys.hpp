// The keys a scene file may use, section by section: the one table the loader checks a scene
// against (scene_loader.cpp, block_directions.cpp refuse any other key), and the list of them
// for tools that must keep every key of the format (the GUI's round trip is tested against it).
#pragma once

#include <array>
#include <string>
#include <vector>

namespace dydp::engine {

/// The top level of a scene file (docs/scenes.md).
inline constexpr std::array<const char*, 13> kSceneKeys = {
    "scene",      "description", "time",   "solver",      "initial", "parameters", "sensitivities",
    "directions", "subsystems",  "blocks", "connections", "outputs", "layout"};
/// `time:`.
inline constexpr std::array<const char*, 3> kTimeKeys = {"start", "stop", "output_step"};
/// `solver:`.
inline constexpr std::array<const char*, 11> kSolverKeys = {
    "method",          "rtol",           "atol",      "step", "max_steps", "min_step", "sens_error_test",
    "nominal_scaling", "newton_coefficient", "refresh_local_jacobians", "max_order"};
/// The keys of `solver:` that take true or false (the loader reads them in this order).
inline constexpr std::array<const char*, 3> kSolverSwitches = {"sens_error_test", "nominal_scaling",
                                                               "refresh_local_jacobians"};
/// `initial:` written as a mapping (`initial: {state: equilibrium, hold: {rig.zdot: 0}}`).
inline constexpr std::array<const char*, 2> kInitialKeys = {"state", "hold"};
/// A scene parameter written as a mapping (`parameters: {NAME: {value, ...}}`).
inline constexpr std::array<const char*, 4> kSceneParameterKeys = {"value", "unit", "range", "description"};
/// A direction written as a mapping (`directions: [{name, of, ...}]`).
inline constexpr std::array<const char*, 4> kDirectionKeys = {"name", "of", "range", "unit"};

/// Every key of the tables above as a path: "scene", "time.stop", "solver.max_order", "initial.hold",
/// "parameters.*.unit", "directions.*.of" (`*` for a name the scene chooses or a list entry).
/// The keys of a block (its type's parameters and settings) and of a subsystem definition are
/// not listed: the block registry and subsystem_definition.cpp hold those.
std::vector<std::string> scene_format_keys();

}  // namespace dydp::engine
