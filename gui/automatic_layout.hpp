// The layered layout (layered_layout.hpp) applied to a scene's blocks or to the blocks inside
// one of its subsystem definitions: each block sized as the canvas draws it.
#pragma once

#include "gui/scene_document.hpp"

namespace dydp::gui {

/// Which blocks get new positions: all of them, or only those without one (placed below the
/// others, so that nothing overlaps what was placed by hand).
enum class LayoutScope { all_blocks, unplaced_blocks };

/// Lays out the scene's blocks.
void lay_out_scene(SceneDocument& doc, LayoutScope scope);
/// Lays out the blocks inside `def`, a definition of doc.subsystems.
void lay_out_definition(const SceneDocument& doc, DocSubsystem& def, LayoutScope scope);

}  // namespace dydp::gui
