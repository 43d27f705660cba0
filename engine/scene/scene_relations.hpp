// Relations between the fields of a scene's `time:` and `solver:` sections, checked after each
// value passed its own test: a run of sensible length on a grid that fits in memory, tolerances
// that control something, a fixed step that ends the run in a bounded number of steps.
// The limits are the rules docs/scenes.md states.
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>

#include "engine/framework/diagram.hpp"
#include "engine/framework/solver_methods.hpp"

namespace dydp::engine {

inline constexpr double kMaxAbsTime = 1e6;           ///< [s] |time.start|, |time.stop|
inline constexpr double kMaxOutputIntervals = 1e7;   ///< output grid intervals
inline constexpr double kMaxFixedSteps = 1e9;        ///< fixed-step methods: steps per run
inline constexpr double kMaxStepLimit = 1e9;         ///< solver.max_steps

/// `section`: the scene's `time:` node (may be undefined: defaults). Throws InputError at the
/// line of the offending value.
void check_time_relations(const std::string& file, const YAML::Node& section, const TimeSpec& time);

/// `section`: the scene's `solver:` node (may be undefined). Throws InputError.
void check_solver_relations(const std::string& file, const YAML::Node& section,
                            const SolverSpec& solver, const TimeSpec& time);

}  // namespace dydp::engine
