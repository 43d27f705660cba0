// The ports of a subsystem instance as the GUI draws it: each port of the definition with the
// width and unit of the internal port it stands for, the internal block made with the instance's
// parameter values in place of `$name` (as the engine's flattening does).
#pragma once

#include "gui/block_catalog.hpp"
#include "gui/scene_document.hpp"

namespace dydp::gui {

/// `instance`: a block of type `subsystem.NAME` of `doc` (or of a definition inside it).
BlockPorts instance_ports(const SceneDocument& doc, const DocBlock& instance);

/// The ports of any block of `doc` (a block type's, or an instance's through its definition);
/// also of a block inside a definition once bound (bound_block).
BlockPorts block_ports(const SceneDocument& doc, const DocBlock& block);

/// The internal block `block` of definition `def` with `$name` values replaced by the instance's
/// values (or the definition's defaults): what the engine makes of it.
DocBlock bound_block(const DocSubsystem& def, const DocBlock& instance, const DocBlock& block);

}  // namespace dydp::gui
