// Grouping blocks of a scene into a subsystem: the selected blocks move into a new inline
// definition (docs/scenes.md, "Subsystems") and one instance of it takes their place. Wires
// crossing the selection's boundary become the definition's ports, wires inside stay inside, a
// scene parameter used inside becomes a parameter of the definition that the instance passes
// through (`p: $p`), so values and sensitivities stay those of the scene before grouping.
#pragma once

#include <string>
#include <vector>

#include "gui/scene_document.hpp"

namespace dydp::gui {

struct Grouping {
  SceneDocument after;     ///< the scene with the instance in place of the blocks
  std::string instance;    ///< the new block's name (also the definition's)
  std::string error;       ///< not empty: refused, `after` is not meaningful
};

/// Replaces `blocks` of `doc` (blocks of the scene's own level) by an instance of a new inline
/// definition. Outputs logged from those blocks are logged through the instance
/// (`group.damper.force`), block-parameter directions likewise (`group.damper.friction`).
/// Refused: no block, an unknown one, or a `directions:` entry that may name one of them.
Grouping group_into_subsystem(const SceneDocument& doc, const std::vector<std::string>& blocks);

}  // namespace dydp::gui
