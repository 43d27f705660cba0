// The `initial:` section of a scene: where its runs start (the blocks' initial states, or the
// static equilibrium at time.start) and the signals that equilibrium holds at other values.
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>
#include <utility>
#include <vector>

#include "engine/framework/diagram.hpp"

namespace dydp::engine {

/// What `initial:` says, read before the blocks: `equilibrium` or `declared`, or a mapping
/// `{state: ..., hold: {SIGNAL: VALUE, ...}}`. Throws InputError at the value's line.
struct InitialSection {
  bool equilibrium = false;
  int line = 0;
  struct Hold {
    std::string signal;
    double value = 0.0;
    int line = 0;
  };
  std::vector<Hold> holds;
};
InitialSection read_initial_section(const YAML::Node& n, const std::string& file);

/// Resolves the holds against the built diagram (`block.port` or `block.port[i]`, an output of a
/// kept block) into d.initial. Throws InputError naming `initial.hold.SIGNAL` at its line.
void bind_initial_section(const InitialSection& s, const std::string& file, Diagram& d);

}  // namespace dydp::engine
