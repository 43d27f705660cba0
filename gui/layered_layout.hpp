// The automatic layout of a diagram without positions: layers by signal flow (a Sugiyama-style
// layered drawing). Cycles (the car and its corners drive each other) are broken by depth-first
// search from the sources; each block's layer is its longest path from a source, objectives go
// to a last layer of their own; blocks are ordered within layers by barycentre sweeps, keeping
// the order with the fewest crossings; then stacked without overlap, each pulled towards the
// ports it is wired to.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "gui/scene_document.hpp"

namespace dydp::gui {

/// What the layout needs of a block: its drawn size and where its ports sit [px].
struct LayoutBlock {
  std::string name;
  double width = 150, height = 60;
  bool objective = false;
  std::map<std::string, double> input_y, output_y;  ///< port -> offset below the block's top
};

struct LayoutPosition {
  double x = 0, y = 0;  ///< top-left corner [px]
  int layer = 0;
};

/// Positions for every block of `blocks` (top-left corners, the diagram's top-left at
/// (origin, origin)); connections naming other blocks are ignored.
std::map<std::string, LayoutPosition> layered_layout(const std::vector<LayoutBlock>& blocks,
                                                     const std::vector<DocConnection>& connections,
                                                     double origin = 40);

}  // namespace dydp::gui
