// The GeneratedModel descriptor of a multibody model (NAME_model.cpp): the model's names, units,
// initial values and structure as arrays, and the generated functions the registry hands out.
#pragma once

#include <string>
#include <vector>

#include "symbolic/mbs/model.hpp"
#include "symbolic/mbs/newton_euler.hpp"

namespace dydp::gen {

// Whether a sensor's outputs depend on qdd: acceleration sensors, and joint sensors that report
// the joint's acceleration.
bool reads_acceleration(const mbs::Sensor& sensor);

// What the descriptor records of the generation besides the model and its lists.
struct DescriptorChoices {
  std::string origin;                  // the header comment's source line (EmitOptions::origin)
  std::string header;                  // NAME.hpp, which declares the functions
  std::vector<int> independent;        // the independent coordinates
  bool independent_automatic = false;  // chosen by a pivoted QR of J at q0
  std::vector<int> jacobian_nonzero;   // J's structural nonzeros, m x n row-major
  std::vector<int> tangent_group;      // each coordinate's group in NAME_residual_tangent_groups, or -1
  int tangent_groups = 0;              // 0: no NAME_residual_tangent_groups
};

// The text of NAME_model.cpp.
std::string model_descriptor(const mbs::Model& model, const mbs::ModelLists& lists, const DescriptorChoices& choices);

}  // namespace dydp::gen
