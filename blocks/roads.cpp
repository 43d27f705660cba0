// Road inputs under the four wheels (front left, front right, rear left, rear right): a 4-poster
// test rig (sines plus smooth noise), an ISO 8608 random road, and a profile of discrete
// obstacles. Outputs `z` [m] and `zdot` [m/s], width 4 each, closed-form in time.
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <string>

#include "blocks/time_series.hpp"
#include "engine/framework/registry.hpp"

namespace dydp::blocks {
namespace {

using engine::Block;
using engine::BlockSettings;
using engine::DirView;
using engine::Eval;
using engine::ParamSpec;
using engine::Seeds;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kTwoPi = 2 * std::numbers::pi;
const char* const kPads[4] = {"fl", "fr", "rl", "rr"};

/// Phases uniform in [0, 2 pi) from a seeded 64-bit Mersenne twister (whose output sequence the
/// C++ standard fixes, so a seed gives the same road on every platform).
std::vector<double> random_phases(unsigned long long seed, int count) {
  std::mt19937_64 generator(seed);
  std::vector<double> phases(count);
  for (double& phase : phases) phase = kTwoPi * static_cast<double>(generator() >> 11) * 0x1.0p-53;
  return phases;
}

int positive_integer(const BlockSettings& s, const char* name) {
  const int n = s.integer(name);
  if (n < 1) s.fail(name, "must be at least 1");
  return n;
}

// ---------------------------------------------------------------- road.fourposter

/// z_i = A_i sin(2 pi f_i t + phi_i) + a sum_k sin(2 pi f_k t + theta_ik), a = noise_rms sqrt(2 / N),
/// f_k = f_lo + (k + 1/2)(f_hi - f_lo) / N: a noise of the given rms spread evenly over the band.
/// With `input_file` set (dydp replay), the pads instead follow the recorded columns named in
/// `pad_columns`, by a not-a-knot cubic spline (displacement, rate and acceleration continuous,
/// so that the integrator's steps are not cut at every sample); recorded data has no
/// parameters, so the tangents are zero.
class FourPoster : public Block {
 public:
  enum { kNoiseRms = 12, kNoiseLow, kNoiseHigh };
  FourPoster(unsigned long long seed, int components, std::vector<TimeSeries> recorded)
      : components_(components), recorded_(std::move(recorded)) {
    for (int pad = 0; pad < 4; ++pad) {
      const std::vector<double> phases = random_phases(seed + 7919ull * pad, components);
      for (double phase : phases) phase_turn_[pad].emplace_back(std::cos(phase), std::sin(phase));
    }
    declare_output("z", 4, "m");
    declare_output("zdot", 4, "m/s");
  }
  const std::vector<TimeSeries>& recorded() const { return recorded_; }
  static int amplitude(int pad) { return 3 * pad; }
  static int frequency(int pad) { return 3 * pad + 1; }
  static int phase(int pad) { return 3 * pad + 2; }
  double noise_frequency(const double* p, int k) const {
    return p[kNoiseLow] + (k + 0.5) * (p[kNoiseHigh] - p[kNoiseLow]) / components_;
  }
  // Per pad, sum_k sin(w_k t + theta_k) and sum_k w_k cos(w_k t + theta_k). The frequencies are
  // evenly spaced and the same for every pad, so exp(i w_k t) = exp(i w_0 t) exp(i dw t)^k
  // comes by one complex product per component (two sincos per call, not one per component and
  // pad), then turned by each pad's exp(i theta_k).
  void noise_sums(const double* p, double t, double sin_sum[4], double cos_sum[4]) const {
    const double w0 = kTwoPi * noise_frequency(p, 0), dw = kTwoPi * (p[kNoiseHigh] - p[kNoiseLow]) / components_;
    // (complex products written out: std::complex's operator* checks for infinities per call)
    const double step_c = std::cos(dw * t), step_s = std::sin(dw * t);
    double turn_c = std::cos(w0 * t), turn_s = std::sin(w0 * t);
    for (int pad = 0; pad < 4; ++pad) sin_sum[pad] = cos_sum[pad] = 0.0;
    for (int k = 0; k < components_; ++k) {
      const double wk = w0 + k * dw;
      for (int pad = 0; pad < 4; ++pad) {
        const std::complex<double> phase = phase_turn_[pad][k];
        sin_sum[pad] += turn_s * phase.real() + turn_c * phase.imag();
        cos_sum[pad] += wk * (turn_c * phase.real() - turn_s * phase.imag());
      }
      const double c = turn_c * step_c - turn_s * step_s;
      turn_s = turn_s * step_c + turn_c * step_s;
      turn_c = c;
    }
  }

  void outputs(const Eval& e, double* const* y) const override {
    if (!recorded_.empty()) {
      for (int pad = 0; pad < 4; ++pad) recorded_[pad].cubic(e.t, y[0][pad], y[1][pad]);
      return;
    }
    const double* p = e.p;
    const double a = p[kNoiseRms] * std::sqrt(2.0 / components_);
    double sin_sum[4], cos_sum[4];
    noise_sums(p, e.t, sin_sum, cos_sum);
    for (int pad = 0; pad < 4; ++pad) {
      const double w = kTwoPi * p[frequency(pad)];
      const double arg = w * e.t + p[phase(pad)];
      y[0][pad] = p[amplitude(pad)] * std::sin(arg) + a * sin_sum[pad];
      y[1][pad] = p[amplitude(pad)] * w * std::cos(arg) + a * cos_sum[pad];
    }
  }
  void outputs_tangent(const Eval& e, const Seeds& s, const DirView* dy) const override {
    if (!recorded_.empty()) {
      for (int d = 0; d < s.directions; ++d)
        for (int pad = 0; pad < 4; ++pad) dy[0](pad, d) = dy[1](pad, d) = 0.0;
      return;
    }
    const double* p = e.p;
    const double noise_shape = std::sqrt(2.0 / components_);
    double sin_sum[4], cos_sum[4];
    noise_sums(p, e.t, sin_sum, cos_sum);
    for (int pad = 0; pad < 4; ++pad) {
      const double amp = p[amplitude(pad)], w = kTwoPi * p[frequency(pad)];
      const double arg = w * e.t + p[phase(pad)], sn = std::sin(arg), cs = std::cos(arg);
      // The noise's contribution is linear in noise_rms: its tangent is (noise / noise_rms) d rms.
      const double unit_z = noise_shape * sin_sum[pad], unit_zdot = noise_shape * cos_sum[pad];
      for (int d = 0; d < s.directions; ++d) {
        const double da = s.p(amplitude(pad), d), dw = kTwoPi * s.p(frequency(pad), d);
        const double darg = dw * e.t + s.p(phase(pad), d), drms = s.p(kNoiseRms, d);
        dy[0](pad, d) = da * sn + amp * cs * darg + unit_z * drms;
        dy[1](pad, d) = da * w * cs + amp * dw * cs - amp * w * sn * darg + unit_zdot * drms;
      }
    }
  }

 private:
  int components_;
  std::vector<std::complex<double>> phase_turn_[4];  // exp(i theta_k) of each pad's components
  std::vector<TimeSeries> recorded_;
};

std::vector<ParamSpec> fourposter_params() {
  std::vector<ParamSpec> out;
  const double phase[4] = {0.0, 0.0, 0.0, 0.0};
  for (int pad = 0; pad < 4; ++pad) {
    const std::string n = kPads[pad];
    out.push_back({"amplitude_" + n, "m", 0.005, false, -kInf, kInf, "sine amplitude of pad " + n});
    out.push_back({"frequency_" + n, "Hz", 2.0, false, 0.0, kInf, "sine frequency of pad " + n});
    out.push_back({"phase_" + n, "rad", phase[pad], false, -kInf, kInf, "sine phase of pad " + n});
  }
  out.push_back({"noise_rms", "m", 0.001, false, 0.0, kInf, "rms of the noise added to each pad"});
  out.push_back({"noise_low", "Hz", 0.5, false, 0.0, kInf, "lowest noise frequency", false});
  out.push_back({"noise_high", "Hz", 20.0, false, 0.0, kInf, "highest noise frequency", false});
  return out;
}

const engine::BlockRegistration fourposter({
    "road.fourposter", "roads",
    "4-poster rig: per pad a sine plus a smooth seeded noise (sum of random-phase sines). Pads fl, fr, rl, rr.",
    fourposter_params(),
    {{"seed", "seed of the noise phases", "1", false},
     {"components", "number of sines in each pad's noise", "50", false},
     {"input_file", "recorded pad displacements (CSV: t and one column per pad); replaces the sines", "", false},
     {"pad_columns", "columns of input_file for the pads fl, fr, rl, rr", "", false}},
    [](const BlockSettings& s) -> std::unique_ptr<Block> {
      std::vector<TimeSeries> recorded;
      if (!s.text("input_file").empty()) {
        std::vector<std::string> columns = s.texts("pad_columns");
        if (columns.size() == 1 && columns[0].empty()) columns = {kPads[0], kPads[1], kPads[2], kPads[3]};
        if (columns.size() != 4) s.fail("pad_columns", "expected four column names (fl, fr, rl, rr)");
        recorded = read_time_series(s, "input_file", "t", columns, "pad_columns");
      }
      return std::make_unique<FourPoster>(static_cast<unsigned long long>(s.integer("seed")),
                                          positive_integer(s, "components"), std::move(recorded));
    },
    {{"noise_low <= noise_high", "noise_low", engine::BlockCheck::Severity::error,
      [](const engine::CheckInput& in) -> std::optional<std::string> {
        if (in.p[FourPoster::kNoiseLow] <= in.p[FourPoster::kNoiseHigh]) return std::nullopt;
        std::ostringstream why;
        why << "noise band [" << in.p[FourPoster::kNoiseLow] << ", " << in.p[FourPoster::kNoiseHigh]
            << "] Hz: its low end is above its high end (noise_high)";
        return why.str();
      }},
     {"input_file covers [time.start, time.stop]", "input_file", engine::BlockCheck::Severity::warning,
      [](const engine::CheckInput& in) -> std::optional<std::string> {
        const auto* rig = dynamic_cast<const FourPoster*>(in.block);
        if (!rig || rig->recorded().empty()) return std::nullopt;
        return uncovered_span(rig->recorded().front(), in.t_start, in.t_stop);
      }}}});

// ---------------------------------------------------------------- road.iso8608

/// ISO 8608 class values Gd(n0) [m^3], n0 = 0.1 cycles/m, waviness w = 2.
double class_roughness(const BlockSettings& s) {
  const std::string c = s.text("class");
  const std::string classes = "ABCDEFGH";
  if (c.size() != 1 || classes.find(c[0]) == std::string::npos) s.fail("class", "expected one of A to H, got '" + c + "'");
  return 16e-6 * std::pow(4.0, static_cast<double>(classes.find(c[0])));
}

/// z(x) = s sum_k A_k cos(2 pi n_k x + phi_k), A_k = sqrt(2 Gd(n_k) dn), Gd(n) = Gd(n0)(n / n0)^-2,
/// n_k = n_min + (k + 1/2) dn; left and right tracks with independent phases. Front wheels at
/// x = x0 + v t, rear wheels at x - L (the wheelbase delay L / v).
class Iso8608 : public Block {
 public:
  enum { kSpeed, kWheelbase, kScale, kStart };
  Iso8608(double roughness, double n_min, double n_max, int components, unsigned long long seed) {
    const double dn = (n_max - n_min) / components;
    for (int k = 0; k < components; ++k) {
      const double n = n_min + (k + 0.5) * dn;
      n_.push_back(n);
      amplitude_.push_back(std::sqrt(2 * roughness * std::pow(n / 0.1, -2.0) * dn));
    }
    phase_[0] = random_phases(seed, components);
    phase_[1] = random_phases(seed + 104729ull, components);
    declare_output("z", 4, "m");
    declare_output("zdot", 4, "m/s");
  }
  /// Track (0 left, 1 right) and distance behind the front axle of wheel i (fl, fr, rl, rr).
  static int track(int i) { return i % 2; }
  static bool rear(int i) { return i >= 2; }

  void outputs(const Eval& e, double* const* y) const override {
    const double* p = e.p;
    for (int i = 0; i < 4; ++i) {
      const double x = p[kStart] + p[kSpeed] * e.t - (rear(i) ? p[kWheelbase] : 0.0);
      double z = 0, zdot = 0;
      for (size_t k = 0; k < n_.size(); ++k) {
        const double arg = kTwoPi * n_[k] * x + phase_[track(i)][k];
        z += amplitude_[k] * std::cos(arg);
        zdot -= amplitude_[k] * kTwoPi * n_[k] * p[kSpeed] * std::sin(arg);
      }
      y[0][i] = p[kScale] * z;
      y[1][i] = p[kScale] * zdot;
    }
  }
  void outputs_tangent(const Eval& e, const Seeds& s, const DirView* dy) const override {
    const double* p = e.p;
    const double v = p[kSpeed];
    for (int i = 0; i < 4; ++i) {
      const double x = p[kStart] + v * e.t - (rear(i) ? p[kWheelbase] : 0.0);
      // z = s Z(x), zdot = s v Z'(x): need Z, Z', Z''.
      double z0 = 0, z1 = 0, z2 = 0;
      for (size_t k = 0; k < n_.size(); ++k) {
        const double wn = kTwoPi * n_[k], arg = wn * x + phase_[track(i)][k];
        const double cs = std::cos(arg), sn = std::sin(arg);
        z0 += amplitude_[k] * cs;
        z1 -= amplitude_[k] * wn * sn;
        z2 -= amplitude_[k] * wn * wn * cs;
      }
      for (int d = 0; d < s.directions; ++d) {
        const double dv = s.p(kSpeed, d), ds = s.p(kScale, d);
        const double dx = s.p(kStart, d) + dv * e.t - (rear(i) ? s.p(kWheelbase, d) : 0.0);
        dy[0](i, d) = ds * z0 + p[kScale] * z1 * dx;
        dy[1](i, d) = ds * v * z1 + p[kScale] * (dv * z1 + v * z2 * dx);
      }
    }
  }

 private:
  std::vector<double> n_, amplitude_, phase_[2];
};

const engine::BlockRegistration iso8608({
    "road.iso8608", "roads",
    "ISO 8608 random road (classes A-H) as a sum of sinusoids at speed v; left/right independent; rear delayed by the wheelbase.",
    {{"speed", "m/s", 20.0, false, 1e-6, kInf, "vehicle speed"},
     {"wheelbase", "m", 2.776, false, 0.0, kInf, "distance from front to rear wheels"},
     {"roughness_scale", "", 1.0, false, 0.0, kInf, "factor on the profile (1: the class's geometric mean)"},
     {"start_position", "m", 0.0, false, -kInf, kInf, "road position of the front wheels at t = 0"}},
    {{"class", "roughness class, A (smoothest) to H", "C", false},
     {"seed", "seed of the phases", "1", false},
     {"components", "number of sinusoids per track", "200", false},
     {"n_min", "lowest spatial frequency [cycles/m]", "0.011", false},
     {"n_max", "highest spatial frequency [cycles/m]", "2.83", false}},
    [](const BlockSettings& s) -> std::unique_ptr<Block> {
      const double n_min = s.number("n_min"), n_max = s.number("n_max");
      if (!(n_min > 0)) s.fail("n_min", "must be positive");
      if (!(n_max > n_min)) s.fail("n_max", "must exceed n_min");
      return std::make_unique<Iso8608>(class_roughness(s), n_min, n_max, positive_integer(s, "components"),
                                       static_cast<unsigned long long>(s.integer("seed")));
    }});

// ---------------------------------------------------------------- road.profile

/// A cosine ramp from 0 to 1 over [0, l]: r(s) = (1 - cos(pi s / l)) / 2, with r' and r''.
struct Shape {
  double value = 0, slope = 0, curvature = 0;
  Shape& add(double factor, const Shape& o) {
    value += factor * o.value, slope += factor * o.slope, curvature += factor * o.curvature;
    return *this;
  }
};
Shape cosine_ramp(double s, double l) {
  if (s <= 0) return {};
  if (s >= l) return {1.0, 0.0, 0.0};
  const double k = std::numbers::pi / l;
  return {0.5 * (1 - std::cos(k * s)), 0.5 * k * std::sin(k * s), 0.5 * k * k * std::cos(k * s)};
}
/// A bump of height h over [0, l]: h (1 - cos(2 pi s / l)) / 2.
Shape cosine_bump(double s, double l) {
  if (s <= 0 || s >= l) return {};
  const double k = kTwoPi / l;
  return {0.5 * (1 - std::cos(k * s)), 0.5 * k * std::sin(k * s), 0.5 * k * k * std::cos(k * s)};
}

struct Obstacle {
  enum Kind { bump, pothole, step } kind;
  double position, length, height;  // start [m], length [m], height (depth for potholes) [m]
};

/// Discrete obstacles along the road (bumps, potholes, transverse steps), C1 in position, so
/// z and zdot are continuous; their edges are breakpoints.
class Profile : public Block {
 public:
  enum { kSpeed, kWheelbase, kStart };
  Profile(std::vector<Obstacle> obstacles, double edge_length, bool left, bool right)
      : obstacles_(std::move(obstacles)), edge_(edge_length), left_(left), right_(right) {
    declare_output("z", 4, "m");
    declare_output("zdot", 4, "m/s");
  }
  Shape at(double x) const {
    Shape z;
    for (const Obstacle& o : obstacles_) {
      const double s = x - o.position;
      if (o.kind == Obstacle::bump) z.add(o.height, cosine_bump(s, o.length));
      if (o.kind == Obstacle::step) z.add(o.height, cosine_ramp(s, edge_));
      if (o.kind == Obstacle::pothole)
        z.add(-o.height, cosine_ramp(s, edge_)).add(o.height, cosine_ramp(s - o.length + edge_, edge_));
    }
    return z;
  }
  bool on(int i) const { return i % 2 == 0 ? left_ : right_; }
  double position(const double* p, double t, int i) const {
    return p[kStart] + p[kSpeed] * t - (i >= 2 ? p[kWheelbase] : 0.0);
  }

  void outputs(const Eval& e, double* const* y) const override {
    for (int i = 0; i < 4; ++i) {
      const Shape z = on(i) ? at(position(e.p, e.t, i)) : Shape{};
      y[0][i] = z.value;
      y[1][i] = z.slope * e.p[kSpeed];
    }
  }
  void outputs_tangent(const Eval& e, const Seeds& s, const DirView* dy) const override {
    const double v = e.p[kSpeed];
    for (int i = 0; i < 4; ++i) {
      const Shape z = on(i) ? at(position(e.p, e.t, i)) : Shape{};
      for (int d = 0; d < s.directions; ++d) {
        const double dv = s.p(kSpeed, d);
        const double dx = s.p(kStart, d) + dv * e.t - (i >= 2 ? s.p(kWheelbase, d) : 0.0);
        dy[0](i, d) = z.slope * dx;
        dy[1](i, d) = z.curvature * dx * v + z.slope * dv;
      }
    }
  }
  std::vector<double> breakpoints(const double* p, double t0, double t1) const override {
    std::vector<double> edges;
    for (const Obstacle& o : obstacles_) {
      edges.push_back(o.position);
      if (o.kind == Obstacle::bump) edges.push_back(o.position + o.length);
      if (o.kind == Obstacle::step) edges.push_back(o.position + edge_);
      if (o.kind == Obstacle::pothole)
        for (double s : {edge_, o.length - edge_, o.length}) edges.push_back(o.position + s);
    }
    std::vector<double> times;
    for (double x : edges)
      for (double behind : {0.0, p[kWheelbase]}) {
        const double t = (x + behind - p[kStart]) / p[kSpeed];
        if (t > t0 && t <= t1) times.push_back(t);
      }
    return times;
  }

 private:
  std::vector<Obstacle> obstacles_;
  double edge_;
  bool left_, right_;
};

std::vector<Obstacle> read_obstacles(const BlockSettings& s, const char* name, Obstacle::Kind kind, int per) {
  std::vector<Obstacle> out;
  if (s.texts(name).size() == 1 && s.texts(name)[0].empty()) return out;
  const std::vector<double> v = s.numbers(name);
  if (v.size() % per != 0) s.fail(name, "expected a flat list of " + std::to_string(per) + "-tuples");
  for (size_t i = 0; i < v.size(); i += per) {
    Obstacle o{kind, v[i], per == 3 ? v[i + 1] : 0.0, v[i + per - 1]};
    if (per == 3 && !(o.length > 0)) s.fail(name, "lengths must be positive");
    out.push_back(o);
  }
  return out;
}

const engine::BlockRegistration profile({
    "road.profile", "roads",
    "Discrete obstacles (bumps, potholes, transverse steps) passed at speed v; rear wheels follow by the wheelbase.",
    {{"speed", "m/s", 10.0, false, 1e-6, kInf, "vehicle speed"},
     {"wheelbase", "m", 2.776, false, 0.0, kInf, "distance from front to rear wheels"},
     {"start_position", "m", 0.0, false, -kInf, kInf, "road position of the front wheels at t = 0"}},
    {{"bumps", "flat list: position [m], length [m], height [m], ... (cosine bumps)", "", false},
     {"potholes", "flat list: position [m], length [m], depth [m], ... (cosine-edged)", "", false},
     {"steps", "flat list: position [m], height [m], ... (cosine ramp over edge_length)", "", false},
     {"edge_length", "length of a step's or pothole edge's ramp [m]", "0.05", false},
     {"tracks", "left, right or both", "both", false}},
    [](const BlockSettings& s) -> std::unique_ptr<Block> {
      std::vector<Obstacle> all = read_obstacles(s, "bumps", Obstacle::bump, 3);
      for (const auto& o : read_obstacles(s, "potholes", Obstacle::pothole, 3)) all.push_back(o);
      for (const auto& o : read_obstacles(s, "steps", Obstacle::step, 2)) all.push_back(o);
      const double edge = s.number("edge_length");
      if (!(edge > 0)) s.fail("edge_length", "must be positive");
      for (const auto& o : all)
        if (o.kind == Obstacle::pothole && o.length < 2 * edge) s.fail("potholes", "a pothole must be at least two edge lengths long");
      const std::string tracks = s.text("tracks");
      if (tracks != "left" && tracks != "right" && tracks != "both") s.fail("tracks", "expected left, right or both");
      return std::make_unique<Profile>(all, edge, tracks != "right", tracks != "left");
    }});

}  // namespace
}  // namespace dydp::blocks
