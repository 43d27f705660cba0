#include "blocks/time_series.hpp"

#include <algorithm>
#include <sstream>

#include "engine/recording.hpp"
#include "engine/errors.hpp"

namespace dydp::blocks {

size_t TimeSeries::segment(double t) const {
  const size_t k = std::upper_bound(t_.begin(), t_.end(), t) - t_.begin();
  return std::min(std::max<size_t>(k, 1), t_.size() - 1);  // segment [k - 1, k]
}

double TimeSeries::linear(double t) const {
  if (t <= t_.front()) return y_.front();
  if (t >= t_.back()) return y_.back();
  const size_t k = segment(t);
  const double w = (t - t_[k - 1]) / (t_[k] - t_[k - 1]);
  return (1 - w) * y_[k - 1] + w * y_[k];
}

double TimeSeries::slope(size_t k) const {
  if (k == 0) return (y_[1] - y_[0]) / (t_[1] - t_[0]);
  if (k == t_.size() - 1) return (y_[k] - y_[k - 1]) / (t_[k] - t_[k - 1]);
  return (y_[k + 1] - y_[k - 1]) / (t_[k + 1] - t_[k - 1]);
}

void TimeSeries::cubic(double t, double& y, double& ydot) const {
  if (t <= t_.front() || t >= t_.back()) {
    y = t <= t_.front() ? y_.front() : y_.back();
    ydot = 0.0;
    return;
  }
  const size_t k = segment(t);
  const double h = t_[k] - t_[k - 1], s = (t - t_[k - 1]) / h;
  const double m0 = slope(k - 1) * h, m1 = slope(k) * h;
  const double s2 = s * s, s3 = s2 * s;
  y = (2 * s3 - 3 * s2 + 1) * y_[k - 1] + (s3 - 2 * s2 + s) * m0 + (-2 * s3 + 3 * s2) * y_[k] + (s3 - s2) * m1;
  ydot = ((6 * s2 - 6 * s) * y_[k - 1] + (3 * s2 - 4 * s + 1) * m0 + (-6 * s2 + 6 * s) * y_[k] + (3 * s2 - 2 * s) * m1) / h;
}

std::optional<std::string> uncovered_span(const TimeSeries& series, double t_start, double t_stop) {
  if (series.times().empty()) return std::nullopt;
  const double first = series.times().front(), last = series.times().back();
  const auto number = [](double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  };
  if (last < t_stop)
    return "the recording ends at " + number(last) + " s, before time.stop = " + number(t_stop) +
           " s: its last value is held";
  if (first > t_start)
    return "the recording starts at " + number(first) + " s, after time.start = " + number(t_start) +
           " s: its first value is held";
  return std::nullopt;
}

std::vector<TimeSeries> read_time_series(const engine::BlockSettings& s, const std::string& file_key,
                                         const std::string& time_column,
                                         const std::vector<std::string>& columns,
                                         const std::string& columns_key) {
  const std::string file = s.path(file_key);
  engine::CsvFile csv;
  try {
    csv = engine::read_recording(file);
  } catch (const engine::InputError& e) {
    if (e.line() == 0 && e.field().empty()) s.fail(file_key, "cannot open '" + file + "'");
    throw;
  }
  const int ct = csv.find(time_column);
  if (ct < 0) s.fail(columns_key == file_key ? file_key : "time_column", "no column '" + time_column + "' in " + file);
  const std::vector<double>& t = csv.columns[ct];
  if (t.size() < 2) throw engine::InputError(file, 2, time_column, "the table needs at least two rows");
  for (size_t k = 1; k < t.size(); ++k)
    if (!(t[k] > t[k - 1])) throw engine::InputError(file, static_cast<int>(k) + 2, time_column, "times must increase");
  std::vector<TimeSeries> out;
  for (const std::string& name : columns) {
    const int c = csv.find(name);
    if (c < 0) s.fail(columns_key, "no column '" + name + "' in " + file);
    out.emplace_back(t, csv.columns[c]);
  }
  return out;
}

}  // namespace dydp::blocks
