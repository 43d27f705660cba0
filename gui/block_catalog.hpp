// What the GUI knows about block types, read from the engine's registry: palette sections and
// the ports of a block with given settings (an instance is made, as the engine would, to ask it).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "engine/framework/block.hpp"
#include "engine/framework/registry.hpp"
#include "gui/scene_document.hpp"

namespace dydp::gui {

struct BlockPorts {
  std::vector<engine::PortDecl> inputs, outputs;
  bool is_objective = false;
  std::string error;  ///< non-empty: the settings do not make a block (ports unknown)
};

/// The ports of a block of `type` with the settings written in `block` (defaults elsewhere).
BlockPorts ports_of(const engine::BlockType& type, const DocBlock& block);

/// A palette section: title and the types in it, sorted by name.
struct PaletteSection {
  std::string title;
  std::vector<const engine::BlockType*> types;
};

/// The registry's types grouped for the palette: sources, vehicle, tyres and roads, hydraulics,
/// objectives, math, then any group the registry has that these do not cover, under its name.
std::vector<PaletteSection> palette_sections();

/// The palette section title a registry group goes to.
std::string section_of_group(const std::string& group);

/// The stem of names given to new blocks of a type: "source.sine" -> "sine".
std::string name_stem(const std::string& type);

/// Index of parameter or setting `key` in the type's specs, or -1.
int parameter_index(const engine::BlockType& type, const std::string& key);
int setting_index(const engine::BlockType& type, const std::string& key);

}  // namespace dydp::gui
