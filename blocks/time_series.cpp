#include "blocks/time_series.hpp"

#include <algorithm>
#include <memory>
#include <sstream>

#include "engine/framework/errors.hpp"
#include "engine/framework/interpolation.hpp"
#include "io/recording.hpp"

namespace dydp::blocks {

size_t TimeSeries::segment(double t) const {
  const size_t k = std::upper_bound(t_.begin(), t_.end(), t) - t_.begin();
  return std::min(std::max<size_t>(k, 1), t_.size() - 1);  // segment [k - 1, k]
}

double TimeSeries::linear(double t) const { return engine::interpolate_linear(t_, y_, t); }

TimeSeries::TimeSeries(std::vector<double> t, std::vector<double> y)
    : t_(std::move(t)), y_(std::move(y)), slope_(t_.size(), 0.0) {
  // The slopes m_k of the cubic spline, from continuity of the second derivative at each
  // interior sample, h_k m_{k-1} + 2 (h_{k-1} + h_k) m_k + h_{k-1} m_{k+1} = 3 (h_k d_{k-1} +
  // h_{k-1} d_k) (h_k the intervals, d_k the chords' slopes), and at the ends the not-a-knot
  // condition (the third derivative continuous at the second and the last but one sample; with
  // fewer than four samples, zero curvature at the ends). A tridiagonal system, solved by
  // elimination.
  const size_t n = t_.size();
  if (n < 2) return;
  std::vector<double> h(n - 1), d(n - 1), lower(n, 0.0), diag(n), upper(n, 0.0), rhs(n);
  for (size_t k = 0; k + 1 < n; ++k) {
    h[k] = t_[k + 1] - t_[k];
    d[k] = (y_[k + 1] - y_[k]) / h[k];
  }
  for (size_t k = 1; k + 1 < n; ++k) {
    lower[k] = h[k];
    diag[k] = 2.0 * (h[k - 1] + h[k]);
    upper[k] = h[k - 1];
    rhs[k] = 3.0 * (h[k] * d[k - 1] + h[k - 1] * d[k]);
  }
  if (n >= 4) {
    const double left = h[0] + h[1], right = h[n - 3] + h[n - 2];
    diag[0] = h[1], upper[0] = left;
    rhs[0] = ((h[0] + 2.0 * left) * h[1] * d[0] + h[0] * h[0] * d[1]) / left;
    lower[n - 1] = right, diag[n - 1] = h[n - 3];
    rhs[n - 1] = (h[n - 2] * h[n - 2] * d[n - 3] + (2.0 * right + h[n - 2]) * h[n - 3] * d[n - 2]) / right;
  } else {
    diag[0] = 2.0, upper[0] = 1.0, rhs[0] = 3.0 * d[0];
    lower[n - 1] = 1.0, diag[n - 1] = 2.0, rhs[n - 1] = 3.0 * d[n - 2];
  }
  for (size_t k = 1; k < n; ++k) {
    const double f = lower[k] / diag[k - 1];
    diag[k] -= f * upper[k - 1];
    rhs[k] -= f * rhs[k - 1];
  }
  slope_[n - 1] = rhs[n - 1] / diag[n - 1];
  for (size_t k = n - 1; k-- > 0;) slope_[k] = (rhs[k] - upper[k] * slope_[k + 1]) / diag[k];
}

void TimeSeries::cubic(double t, double& y, double& ydot) const {
  if (t <= t_.front() || t >= t_.back()) {
    y = t <= t_.front() ? y_.front() : y_.back();
    ydot = 0.0;
    return;
  }
  const size_t k = segment(t);
  const double h = t_[k] - t_[k - 1], s = (t - t_[k - 1]) / h;
  const double m0 = slope_[k - 1] * h, m1 = slope_[k] * h;
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
  std::shared_ptr<const io::CsvFile> recording;
  try {
    recording = io::load_recording(file);
  } catch (const engine::InputError& e) {
    if (e.line() == 0 && e.field().empty()) s.fail(file_key, "cannot open '" + file + "'");
    throw;
  }
  const io::CsvFile& csv = *recording;
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
