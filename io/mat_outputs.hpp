// The output folder's content as MAT v5 files (--format mat): run.mat and replay.mat hold the
// signals.csv table (its column names, their units, the values at full precision) and the JSON
// files as structs; sweep.mat the sweep.csv table and sweep.json.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "engine/analysis/run_result.hpp"
#include "engine/framework/diagram.hpp"

namespace dydp::io {

/// JSON documents to add as structs: (variable name, JSON text).
using JsonDocuments = std::vector<std::pair<std::string, std::string>>;

/// Variables `names` and `units` (1 x columns cells: t, the signals, d(S)/d(P) as in
/// signals.csv), `signals` (samples x columns), `objectives` (objectives.json's "objectives")
/// and `run` (run.json), then the extra documents.
void write_run_mat(const std::string& path, const engine::Diagram& d, const engine::RunResult& r,
                   const JsonDocuments& extra = {});

/// Variables `names` (the CSV header) and `table` (rows x columns) from a CSV text with a
/// header line and numeric rows, then the documents.
void write_table_mat(const std::string& path, const std::string& csv_text, const JsonDocuments& documents);

}  // namespace dydp::io
