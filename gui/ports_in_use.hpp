// Which ports a block shows on the canvas: all of them, unless it has so many (a whole car)
// that only those wired or logged are drawn. The canvas and the automatic layout agree on it,
// so that the layout sizes blocks as they are drawn.
#pragma once

#include <string>
#include <vector>

#include "gui/block_catalog.hpp"
#include "gui/scene_document.hpp"

namespace dydp::gui {

/// A block with more ports than this shows only those in use (View > Show all ports: the rest).
inline constexpr size_t kPortsShownAll = 30;

/// The ports of `block` (all of them: `ports`) that are drawn: every one when there are at most
/// kPortsShownAll, else those wired in `connections` or logged in `outputs`.
BlockPorts ports_in_use(const BlockPorts& ports, const std::string& block,
                        const std::vector<DocConnection>& connections, const std::vector<std::string>& outputs);

}  // namespace dydp::gui
