#include "engine/framework/solver_methods.hpp"

namespace dydp::engine {

int highest_order(const std::string& method) {
  if (method == "bdf") return 5;
  if (method == "adams") return 12;
  return 0;
}

}  // namespace dydp::engine
