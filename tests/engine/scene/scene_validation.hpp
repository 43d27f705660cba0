// The fixture of the scene validation tests (scene_*_errors_test.cpp, scene_graph_test.cpp): a
// folder to write scenes into (SceneErrorTest), and where a block sits in a loaded diagram and
// in its evaluation order.
//
// Each scene is a raw string literal whose first line is line 1 of the file, so the expected
// line numbers can be counted in the literal.
#pragma once

#include <string>

#include "engine/framework/diagram.hpp"
#include "tests/engine/scene_error_test.hpp"

namespace dydp::engine {

class SceneValidation : public test::SceneErrorTest {
 protected:
  SceneValidation() : SceneErrorTest("dydp_scene_validation_") {}

  static int index_of(const Diagram& d, const std::string& name) {
    for (size_t i = 0; i < d.nodes.size(); ++i)
      if (d.nodes[i].name == name) return static_cast<int>(i);
    return -1;
  }

  /// Position in the evaluation order of node i's step for its outputs that read states only
  /// (reads_inputs false) or its first step for outputs that read inputs, or -1.
  static int position(const Diagram& d, int i, bool reads_inputs) {
    for (size_t k = 0; k < d.output_steps.size(); ++k)
      if (d.output_steps[k].node == i && d.output_steps[k].reads.empty() != reads_inputs)
        return static_cast<int>(k);
    return -1;
  }
};

}  // namespace dydp::engine
