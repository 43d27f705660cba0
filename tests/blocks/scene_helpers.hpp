// Helpers for block tests that run small scenes through the engine: write a scene to a
// per-process temporary folder, load it, run it, read logged signals and objectives.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "engine/analysis/run.hpp"
#include "engine/framework/diagram.hpp"

namespace dydp::test {

/// Writes `text` to a temporary scene file named `name` and returns its path.
inline std::string write_scene(const std::string& name, const std::string& text) {
  const auto dir = std::filesystem::temp_directory_path() / ("dydp_blocks_test_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto path = dir / name;
  std::ofstream(path, std::ios::binary) << text;
  return path.string();
}

/// Loads and runs a scene with overrides (NAME=VALUE pairs).
inline engine::RunResult run_scene(const std::string& path,
                                   const std::vector<std::pair<std::string, std::string>>& overrides = {},
                                   bool sensitivities = true) {
  const engine::Diagram d = engine::load_scene(path, overrides);
  engine::RunOptions options;
  options.sensitivities = sensitivities;
  return engine::run(d, options);
}

/// A logged signal over the output grid.
inline std::vector<double> signal(const engine::RunResult& r, const std::string& name) {
  const int i = r.signal_index(name);
  if (i < 0) throw std::runtime_error("no logged signal " + name);
  std::vector<double> out;
  for (size_t k = 0; k < r.t.size(); ++k) out.push_back(r.value(static_cast<int>(k), i));
  return out;
}

inline const engine::ObjectiveResult& objective(const engine::RunResult& r, const std::string& name) {
  for (const auto& o : r.objectives)
    if (o.name == name) return o;
  throw std::runtime_error("no objective " + name);
}

}  // namespace dydp::test
