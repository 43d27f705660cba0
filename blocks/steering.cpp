// steering: the rack displacement a manoeuvre commands: step, ramp-and-hold, sine, or a CSV
// column. Outputs `rack` [m] (positive: rack to the left, +y; which way the wheels turn depends on the linkage) and `rack_rate` [m/s]; every corner of the
// law is a breakpoint, and branches are chosen with Eval::reached().
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "blocks/time_series.hpp"
#include "engine/framework/errors.hpp"
#include "engine/framework/registry.hpp"

namespace dydp::blocks {
namespace {

using engine::Block;
using engine::BlockSettings;
using engine::DirView;
using engine::Eval;
using engine::Seeds;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kTwoPi = 2 * std::numbers::pi;

class Steering : public Block {
 public:
  enum class Mode { step, ramp_hold, sine, csv };
  enum { kAmplitude, kStart, kRampTime, kFrequency };

  Steering(Mode mode, std::vector<double> t, std::vector<double> y) : mode_(mode), t_(std::move(t)), y_(std::move(y)) {
    declare_output("rack", 1, "m");
    declare_output("rack_rate", 1, "m/s");
  }

  /// rack and rack_rate per unit amplitude (csv: the table itself), and d/d(frequency) of both.
  struct Law {
    double rack = 0, rate = 0, rack_f = 0, rate_f = 0;
  };
  Law law(const Eval& e) const {
    const double* p = e.p;
    Law l;
    switch (mode_) {
      case Mode::step:
        if (e.reached(p[kStart])) l.rack = 1.0;
        break;
      case Mode::ramp_hold:
        if (e.reached(p[kStart] + p[kRampTime])) l.rack = 1.0;
        else if (e.reached(p[kStart])) l.rack = (e.t - p[kStart]) / p[kRampTime], l.rate = 1.0 / p[kRampTime];
        break;
      case Mode::sine:
        if (e.reached(p[kStart])) {
          const double tau = e.t - p[kStart], w = kTwoPi * p[kFrequency];
          l.rack = std::sin(w * tau);
          l.rate = w * std::cos(w * tau);
          l.rack_f = kTwoPi * tau * std::cos(w * tau);
          l.rate_f = kTwoPi * std::cos(w * tau) - w * kTwoPi * tau * std::sin(w * tau);
        }
        break;
      case Mode::csv: {
        if (!e.reached(t_.front())) { l.rack = y_.front(); break; }
        if (e.reached(t_.back())) { l.rack = y_.back(); break; }
        size_t k = 1;  // the segment [t_(k-1), t_k) that the current integration segment is in
        while (k < t_.size() - 1 && e.reached(t_[k])) ++k;
        l.rate = (y_[k] - y_[k - 1]) / (t_[k] - t_[k - 1]);
        l.rack = y_[k - 1] + l.rate * (e.t - t_[k - 1]);
        break;
      }
    }
    return l;
  }
  bool scaled() const { return mode_ != Mode::csv; }

  void outputs(const Eval& e, double* const* y) const override {
    const Law l = law(e);
    const double a = scaled() ? e.p[kAmplitude] : 1.0;
    y[0][0] = a * l.rack;
    y[1][0] = a * l.rate;
  }
  void outputs_tangent(const Eval& e, const Seeds& s, const DirView* dy) const override {
    const Law l = law(e);
    for (int d = 0; d < s.directions; ++d) {
      if (!scaled()) { dy[0](0, d) = dy[1](0, d) = 0.0; continue; }
      const double da = s.p(kAmplitude, d), df = s.p(kFrequency, d), a = e.p[kAmplitude];
      dy[0](0, d) = da * l.rack + a * l.rack_f * df;
      dy[1](0, d) = da * l.rate + a * l.rate_f * df;
    }
  }
  std::vector<double> breakpoints(const double* p, double t0, double t1) const override {
    std::vector<double> b;
    if (mode_ == Mode::csv) b = t_;
    else b.push_back(p[kStart]);
    if (mode_ == Mode::ramp_hold) b.push_back(p[kStart] + p[kRampTime]);
    std::vector<double> out;
    for (double t : b) if (t > t0 && t <= t1) out.push_back(t);
    return out;
  }

 private:
  Mode mode_;
  std::vector<double> t_, y_;
};

/// Reads (time, value) columns of a CSV file for mode csv.
void read_table(const BlockSettings& s, std::vector<double>& t, std::vector<double>& y) {
  const TimeSeries series = read_time_series(s, "file", s.text("time_column"), {s.text("column")}, "column").front();
  t = series.times();
  y = series.values();
}

const engine::BlockRegistration steering({
    "steering", "manoeuvres",
    "Rack displacement (positive: rack to the left, +y): step, ramp_hold, sine from `start`, or a CSV column [m] against time.",
    {{"amplitude", "m", 0.01, false, -kInf, kInf, "rack displacement of the step, hold or sine"},
     {"start", "s", 1.0, false, -kInf, kInf, "time the manoeuvre starts", false},
     {"ramp_time", "s", 0.5, false, 1e-9, kInf, "ramp_hold: duration of the ramp", false},
     {"frequency", "Hz", 0.5, false, 0.0, kInf, "sine: frequency"}},
    {{"mode", "step, ramp_hold, sine or csv", "ramp_hold", false},
     {"file", "csv: CSV file, relative to the scene", "", false},
     {"column", "csv: column holding the rack displacement [m]", "rack", false},
     {"time_column", "csv: column holding time [s]", "t", false}},
    [](const BlockSettings& s) -> std::unique_ptr<Block> {
      const std::string m = s.text("mode");
      std::vector<double> t, y;
      Steering::Mode mode = Steering::Mode::step;
      if (m == "step") mode = Steering::Mode::step;
      else if (m == "ramp_hold") mode = Steering::Mode::ramp_hold;
      else if (m == "sine") mode = Steering::Mode::sine;
      else if (m == "csv") mode = Steering::Mode::csv, read_table(s, t, y);
      else s.fail("mode", "expected step, ramp_hold, sine or csv, got '" + m + "'");
      return std::make_unique<Steering>(mode, t, y);
    }});

}  // namespace
}  // namespace dydp::blocks
