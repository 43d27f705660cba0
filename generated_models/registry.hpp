// The registry of generated multibody models: every model listed in generated_models/
// CMakeLists.txt, looked up by name (the multibody block, tests, benchmarks).
#pragma once

#include <string_view>
#include <vector>

#include "symbolic/mbs/generated_model.hpp"

namespace dydp::generated {

// The model named `name`, or null.
const mbs::GeneratedModel* find_model(std::string_view name);
std::vector<const mbs::GeneratedModel*> all_models();

}  // namespace dydp::generated
