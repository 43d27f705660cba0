// Recorded signals as a table of named columns, from a CSV file or an MTS RPC III
// time-history file (.rsp, .drv, .tim): the RPC III channels are named by their descriptions
// (DESC.CHAN_n), after a column `t` of the sample times k * DELTA_T.
#pragma once

#include <memory>
#include <string>

#include "io/csv.hpp"

namespace dydp::io {

/// Reads a recording by its extension (RPC III for .rsp, .drv, .tim; CSV otherwise). Throws
/// InputError as read_csv and read_rpc3 do.
CsvFile read_recording(const std::string& path);

/// The recording at path, parsed once per process while the file is unchanged (same size and
/// modification time): a replay's blocks, its shadow run and its validation share one table.
/// The last few files read are kept. Throws as read_recording.
std::shared_ptr<const CsvFile> load_recording(const std::string& path);

}  // namespace dydp::io
