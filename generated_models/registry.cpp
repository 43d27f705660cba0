// The table of generated models (model_list.inc is written by CMake from DYDP_MODELS).
#include "generated_models/registry.hpp"

#define DYDP_MODEL(name) extern const ::dydp::mbs::GeneratedModel name##_model;
namespace dydp::generated {
#include "model_list.inc"
}  // namespace dydp::generated
#undef DYDP_MODEL

namespace dydp::generated {

std::vector<const mbs::GeneratedModel*> all_models() {
#define DYDP_MODEL(name) &name##_model,
  return {
#include "model_list.inc"
  };
#undef DYDP_MODEL
}

const mbs::GeneratedModel* find_model(std::string_view name) {
  for (const mbs::GeneratedModel* m : all_models())
    if (name == m->name) return m;
  return nullptr;
}

}  // namespace dydp::generated
