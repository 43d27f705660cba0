// The generated models a parameterised multibody test applies to: the test models named by
// CMake (DYDP_TEST_MODELS) filtered by a property of the model (sensors, constraints, coordinate
// groups), so a case that does not apply is not instantiated rather than skipped at run time.
#pragma once

#include <initializer_list>
#include <string>
#include <vector>

#include "generated_models/registry.hpp"
#include "symbolic/mbs/generated_model.hpp"

namespace dydp::mbs::testing {

/// The names of `models` whose generated model satisfies `applies`, in their order; a name with
/// no generated model is kept, so the test's own ASSERT_NE(g, nullptr) reports it.
template <class Applies>
std::vector<std::string> models_where(std::initializer_list<const char*> models, Applies applies) {
  std::vector<std::string> out;
  for (const char* name : models) {
    const GeneratedModel* g = generated::find_model(name);
    if (!g || applies(*g)) out.emplace_back(name);
  }
  return out;
}

inline bool has_sensors(const GeneratedModel& g) { return g.sensor_outputs > 0; }
inline bool has_constraints(const GeneratedModel& g) { return g.m > 0; }
inline bool has_coordinate_groups(const GeneratedModel& g) { return g.residual_tangent_groups != nullptr; }

}  // namespace dydp::mbs::testing
