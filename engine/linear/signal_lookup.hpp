// Signals named as the scene names them: `block.port` (every element of the port) or
// `block.port[i]` (one element), as signals.csv names its columns.
#pragma once

#include <string>
#include <vector>

#include "engine/framework/diagram.hpp"

namespace dydp::engine {

/// The signal offsets of `name`, one per element (a port's all, an element's one). Throws
/// InputError naming `field` (e.g. "--input") when no kept block has that port or element; the
/// message lists the block's ports when the block exists.
std::vector<int> signal_offsets(const Diagram& d, const std::string& name, const std::string& field);

/// `block.port` or `block.port[i]` for the signal at offset.
std::string signal_name(const Diagram& d, int offset);

}  // namespace dydp::engine
