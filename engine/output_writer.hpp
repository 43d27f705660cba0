// The output folder contract (DESIGN.md section 5): signals.csv, objectives.json, run.json.
// Each file is written to a temporary name in the folder and renamed when complete.
#pragma once

#include <string>

#include "engine/diagram.hpp"
#include "engine/run.hpp"

namespace dydp::engine {

/// Writes `text` to path atomically (temporary file in the same folder, then rename).
void write_file_atomically(const std::string& path, const std::string& text);

std::string signals_csv(const RunResult& r);
std::string objectives_json(const RunResult& r);
std::string run_json(const Diagram& d, const RunResult& r);

/// Creates dir if needed and writes the three files.
void write_outputs(const std::string& dir, const Diagram& d, const RunResult& r);

}  // namespace dydp::engine
