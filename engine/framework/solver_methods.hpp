// Facts about the integration methods a scene's `solver.method` names, shared by the scene's
// validation (scene/) and the integrators (analysis/).
#pragma once

#include <string>

namespace dydp::engine {

/// The highest order `method` can take (BDF 5, Adams 12); 0 for the fixed-step methods, which
/// have no order to set.
int highest_order(const std::string& method);

}  // namespace dydp::engine
