// Recorded signals against time for source blocks (tables, steering records, shaker pads):
// read from a recording (CSV or RPC III, io/recording.hpp) named in the block's settings,
// interpolated linearly or by a cubic spline (value, slope and curvature continuous: a recorded
// displacement, its rate and its acceleration).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "engine/framework/block_settings.hpp"

namespace dydp::blocks {

class TimeSeries {
 public:
  TimeSeries() = default;
  TimeSeries(std::vector<double> t, std::vector<double> y);

  /// Linear interpolation, held constant outside the samples.
  double linear(double t) const;
  /// Cubic spline through the samples (twice continuously differentiable, not-a-knot ends:
  /// exact for a cubic), held constant outside; value and rate.
  void cubic(double t, double& y, double& ydot) const;
  const std::vector<double>& times() const { return t_; }
  const std::vector<double>& values() const { return y_; }

 private:
  size_t segment(double t) const;
  std::vector<double> t_, y_;
  std::vector<double> slope_;  // the spline's slope at each sample
};

/// Why a recording does not cover the run [t_start, t_stop] (it starts late or ends early, and
/// its end value is held), or nothing when it covers it: a warning rule of recorded inputs.
std::optional<std::string> uncovered_span(const TimeSeries& series, double t_start, double t_stop);

/// Reads the columns `columns` against `time_column` from the recording in setting `file_key`;
/// errors name the setting (missing column) or the file and row (bad data, times not
/// increasing, fewer than two rows).
std::vector<TimeSeries> read_time_series(const engine::BlockSettings& s, const std::string& file_key,
                                         const std::string& time_column,
                                         const std::vector<std::string>& columns,
                                         const std::string& columns_key);

}  // namespace dydp::blocks
