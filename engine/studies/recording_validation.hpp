// How well a run follows a recording: for every recorded column named after a logged signal
// (a measured response replayed with its inputs), the rms difference and the correlation over
// the run's output grid, the recording interpolated linearly to it. replay.json's `validation`.
#pragma once

#include <string>
#include <vector>

#include "engine/analysis/run_result.hpp"
#include "io/csv.hpp"

namespace dydp::engine {

struct SignalAgreement {
  std::string signal;
  double rms_error = 0.0;    // sqrt(mean((simulated - measured)^2)), in the signal's unit
  double correlation = 0.0;  // Pearson's, 0 when either side is constant
  size_t samples = 0;        // output times compared
};

/// One entry per column of `recording` after its first (the time t) that names a logged signal
/// of `run`, in the recording's column order.
std::vector<SignalAgreement> compare_with_recording(const RunResult& run, const io::CsvFile& recording);

}  // namespace dydp::engine
