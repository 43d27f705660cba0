// A scene's `subsystems:` section to and from YAML for the GUI: definitions included by path are
// read for their ports and blocks and written back as the same `{file: PATH}`; inline ones are
// written back as they were read.
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "gui/scene_document.hpp"

namespace dydp::gui {

/// `file`: the scene's path (includes are relative to its folder). Throws engine::InputError
/// when the section is not shaped like one; a definition whose file cannot be read is kept
/// with its error (the engine reports it when the scene is run).
std::vector<DocSubsystem> read_subsystems(const YAML::Node& section, const std::string& file);

/// Writes an inline definition's blocks, connections and positions (`layout:`) into its
/// inline_yaml, keeping its other keys (description, parameters, ports): after the GUI has
/// changed the inside of the definition.
void store_inside(DocSubsystem& def);

/// Emits `subsystems: ...` (nothing when there are none) into an open mapping.
void emit_subsystems(YAML::Emitter& e, const std::vector<DocSubsystem>& subsystems);

}  // namespace dydp::gui
