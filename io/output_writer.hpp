// The output folder contract (DESIGN.md section 5): signals.csv, objectives.json, run.json.
// Each file is written to a temporary name in the folder and renamed when complete.
#pragma once

#include <string>

#include "engine/analysis/run_result.hpp"
#include "engine/framework/diagram.hpp"

namespace dydp::io {


std::string signals_csv(const engine::RunResult& r);
std::string objectives_json(const engine::RunResult& r);
std::string run_json(const engine::Diagram& d, const engine::RunResult& r);

/// Creates dir if needed and writes the three files.
void write_outputs(const std::string& dir, const engine::Diagram& d, const engine::RunResult& r);

}  // namespace dydp::io
