// A run's logged signals as an RPC III time-history file (dydp replay --format rpc), for the
// rig's own tools: one channel per signal, described by its name, with its unit.
#pragma once

#include <string>

#include "engine/analysis/run_result.hpp"
#include "engine/framework/diagram.hpp"
#include "io/rpc3.hpp"

namespace dydp::io {

/// The file's bytes: DELTA_T the output step; the samples from the run's first output time
/// (the file's t = 0). Throws std::runtime_error when the output grid is not uniform.
std::string run_rpc3(const engine::Diagram& d, const engine::RunResult& r, io::Rpc3DataType type);

}  // namespace dydp::io
