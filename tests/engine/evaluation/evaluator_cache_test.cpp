// The value pass's cache: Evaluator::outputs returns at once for the point it last evaluated.
// A block that refuses a new point (OutOfDomain) leaves the signals of the blocks before it
// already written for that point; the cache must not then pass them off as the last point's.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "engine/evaluation/evaluator.hpp"
#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"

namespace dydp::engine {
namespace {

TEST(EvaluatorCache, ARefusedPointDoesNotLeaveItsSignalsForTheLastPoint) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() / "dydp_evaluator_cache.yaml";
  std::ofstream(path) << "scene: cache\n"
                         "time: {stop: 1.0, output_step: 0.1}\n"
                         "blocks:\n"
                         "  stroke: {type: source.constant, value: 0.01}\n"
                         "  rate: {type: source.constant, value: 0.2}\n"
                         "  first: {type: damper.cdc}\n"
                         "  second: {type: damper.cdc}\n"
                         "connections:\n"
                         "  - stroke.y -> first.stroke\n"
                         "  - rate.y -> first.stroke_rate\n"
                         "  - stroke.y -> second.stroke\n"
                         "  - rate.y -> second.stroke_rate\n"
                         "outputs: [first.force, second.force]\n";
  const Diagram d = load_scene(path.string());
  std::filesystem::remove(path);
  int first = -1, second = -1;
  for (size_t i = 0; i < d.nodes.size(); ++i) {
    if (d.nodes[i].name == "first") first = static_cast<int>(i);
    if (d.nodes[i].name == "second") second = static_cast<int>(i);
  }
  ASSERT_GE(first, 0);
  ASSERT_GE(second, 0);
  ASSERT_LT(first, second) << "the first damper's outputs are written before the second's";
  const int force = d.nodes[first].output_offset[0];

  Evaluator ev(d, false);
  std::vector<double> x(d.num_states);
  ev.initial_state(0.0, x.data());
  ev.outputs(0.0, x.data());
  const double at_x = ev.signals()[force];

  // The first damper's rebound pressure up (its force changes), the second's reservoir
  // pressure negative (it refuses the point).
  std::vector<double> refused = x;
  refused[d.nodes[first].state_offset] += 1e6;
  refused[d.nodes[second].state_offset + 2] = -1.0;
  EXPECT_THROW(ev.outputs(0.0, refused.data()), OutOfDomain);
  EXPECT_NE(ev.signals()[force], at_x) << "the refused pass wrote the first damper's force";

  ev.outputs(0.0, x.data());
  EXPECT_EQ(ev.signals()[force], at_x) << "the last good point's signals, evaluated again";
}

}  // namespace
}  // namespace dydp::engine
