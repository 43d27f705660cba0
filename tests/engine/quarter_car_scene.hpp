// The quarter car with its CDC damper's hydraulics on an ISO 8608 class C road
// (scenarios/quarter_car_cdc.yaml), for the fixed-step solvers' tests: loaded with the method
// and step a test asks, and BDF at the given tolerances for the reference run.
#pragma once

#include <string>

#include "engine/framework/diagram.hpp"

namespace dydp::engine::test {

inline Diagram quarter_car_cdc(const std::string& method, double step, double bdf_rtol, double bdf_atol) {
  Diagram d = load_scene(std::string(DYDP_SOURCE_DIR) + "/scenarios/quarter_car_cdc.yaml");
  d.solver.method = method;
  d.solver.step = step;
  if (method == "bdf") d.solver.rtol = bdf_rtol, d.solver.atol = bdf_atol;
  return d;
}

}  // namespace dydp::engine::test
