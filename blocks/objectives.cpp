// Objective blocks: integral, mean, rms, max-abs and final value of their input over a time
// window. Integrals are quadratures (integrated by the solver with their sensitivities);
// max-abs and final value read the input sampled on the output grid.
#include <cmath>
#include <limits>

#include "blocks/objective_window.hpp"
#include "engine/framework/objective.hpp"
#include "engine/framework/registry.hpp"

namespace dydp::blocks {
namespace {

using engine::Block;
using engine::BlockSettings;
using engine::ConstDirView;
using engine::DirView;
using engine::Eval;
using engine::ObjectiveSamples;
using engine::Seeds;

constexpr double kInf = std::numeric_limits<double>::infinity();

/// The window [from, to] an objective looks at; open ends extend to the run's span.
struct Window {
  double from = -kInf, to = kInf;
  bool contains(const Eval& e) const { return e.reached(from) && !e.reached(to); }
  double length(const ObjectiveSamples& s) const {
    return std::min(to, s.t_stop) - std::max(from, s.t_start);
  }
};

Window read_window(const BlockSettings& s) {
  Window w;
  if (s.texts("window").size() == 1 && s.texts("window")[0].empty()) return w;
  const std::vector<double> v = s.numbers("window");
  if (v.size() != 2 || !(v[0] < v[1])) s.fail("window", "expected [from, to] with from < to");
  w.from = v[0];
  w.to = v[1];
  return w;
}

/// Base: one scalar input `in`; no outputs; the window's edges are breakpoints.
class ObjectiveBlock : public Block, public engine::Objective {
 public:
  explicit ObjectiveBlock(Window w, int quadratures) : window_(w) {
    declare_input("in", 1, "", false);
    declare_quadratures(quadratures);
  }
  void outputs(const Eval&, double* const*) const override {}
  void outputs_tangent(const Eval&, const Seeds&, const DirView*) const override {}
  std::vector<double> breakpoints(const double*, double, double) const override {
    std::vector<double> b;
    if (std::isfinite(window_.from)) b.push_back(window_.from);
    if (std::isfinite(window_.to)) b.push_back(window_.to);
    return b;
  }

 protected:
  Window window_;
};

/// Q = integral over the window of u (power 1) or u^2 (power 2).
class Integral : public ObjectiveBlock {
 public:
  enum class Kind { integral, mean, rms };
  Integral(Window w, Kind kind) : ObjectiveBlock(w, 1), kind_(kind) {}
  std::string unit(const std::string& input) const override {
    if (kind_ != Kind::integral) return input;
    return input.empty() ? "s" : input + " s";
  }

  void quadratures(const Eval& e, double* qdot) const override {
    const double u = e.u[0][0];
    qdot[0] = !window_.contains(e) ? 0.0 : kind_ == Kind::rms ? u * u : u;
  }
  void quadratures_tangent(const Eval& e, const Seeds& s, DirView dq) const override {
    const bool in = window_.contains(e);
    const double slope = kind_ == Kind::rms ? 2 * e.u[0][0] : 1.0;
    for (int d = 0; d < s.directions; ++d) dq(0, d) = in ? slope * s.u[0](0, d) : 0.0;
  }

  /// integral: Q; mean: Q / T; rms: sqrt(Q / T), d rms = dQ / (2 T rms).
  double objective(const double*, const double* q, ConstDirView dq, const ObjectiveSamples& s,
                   double* dpsi) const override {
    const double T = window_.length(s);
    double psi = q[0], scale = 1.0;
    if (kind_ == Kind::mean) psi = q[0] / T, scale = 1.0 / T;
    if (kind_ == Kind::rms) {
      psi = std::sqrt(std::max(q[0], 0.0) / T);
      scale = psi > 0 ? 1.0 / (2 * T * psi) : 0.0;
    }
    for (int d = 0; d < s.directions; ++d) dpsi[d] = scale * dq(0, d);
    return psi;
  }

 private:
  Kind kind_;
};

/// max |u| over the output samples in the window, and the derivative at the maximising sample.
class MaxAbs : public ObjectiveBlock {
 public:
  explicit MaxAbs(Window w) : ObjectiveBlock(w, 0) {}
  bool needs_samples() const override { return true; }
  double objective(const double*, const double*, ConstDirView, const ObjectiveSamples& s,
                   double* dpsi) const override {
    const auto& t = *s.t;
    const auto& u = *s.u;
    long best = -1;
    for (size_t k = 0; k < t.size(); ++k)
      if (t[k] >= window_.from && t[k] <= window_.to && (best < 0 || std::fabs(u[k]) > std::fabs(u[best])))
        best = static_cast<long>(k);
    for (int d = 0; d < s.directions; ++d)
      dpsi[d] = best < 0 ? 0.0 : (u[best] < 0 ? -1.0 : 1.0) * (*s.du)[best * s.directions + d];
    return best < 0 ? std::numeric_limits<double>::quiet_NaN() : std::fabs(u[best]);
  }
};

/// u at the last output sample in the window.
class FinalValue : public ObjectiveBlock {
 public:
  explicit FinalValue(Window w) : ObjectiveBlock(w, 0) {}
  bool needs_samples() const override { return true; }
  double objective(const double*, const double*, ConstDirView, const ObjectiveSamples& s,
                   double* dpsi) const override {
    const auto& t = *s.t;
    long last = -1;
    for (size_t k = 0; k < t.size(); ++k)
      if (t[k] >= window_.from && t[k] <= window_.to) last = static_cast<long>(k);
    for (int d = 0; d < s.directions; ++d) dpsi[d] = last < 0 ? 0.0 : (*s.du)[last * s.directions + d];
    return last < 0 ? std::numeric_limits<double>::quiet_NaN() : (*s.u)[last];
  }
};

const engine::SettingSpec kWindowSpec{"window", "[from, to] in s; the whole run when absent", "", false};

template <Integral::Kind kind>
std::unique_ptr<Block> make_integral(const BlockSettings& s) {
  return std::make_unique<Integral>(read_window(s), kind);
}

const engine::BlockRegistration integral({"objective.integral", "objectives",
    "psi = integral of the input over the window.", {}, {kWindowSpec},
    make_integral<Integral::Kind::integral>, window_checks()});
const engine::BlockRegistration mean({"objective.mean", "objectives",
    "psi = mean of the input over the window.", {}, {kWindowSpec},
    make_integral<Integral::Kind::mean>, window_checks()});
const engine::BlockRegistration rms({"objective.rms", "objectives",
    "psi = root mean square of the input over the window.", {}, {kWindowSpec},
    make_integral<Integral::Kind::rms>, window_checks()});
const engine::BlockRegistration max_abs({"objective.max_abs", "objectives",
    "psi = largest |input| at the output samples in the window.", {}, {kWindowSpec},
    [](const BlockSettings& s) -> std::unique_ptr<Block> { return std::make_unique<MaxAbs>(read_window(s)); },
    window_checks()});
const engine::BlockRegistration final_value({"objective.final", "objectives",
    "psi = the input at the last output sample in the window.", {}, {kWindowSpec},
    [](const BlockSettings& s) -> std::unique_ptr<Block> { return std::make_unique<FinalValue>(read_window(s)); },
    window_checks()});

}  // namespace
}  // namespace dydp::blocks
