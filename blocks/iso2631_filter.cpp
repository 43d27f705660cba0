// filter.iso2631: the frequency weightings Wk (vertical) and Wd (horizontal) of ISO 2631-1:1997,
// Annex A, H(s) = Hh Hl Ht Hs, as a cascade of second-order sections in state space.
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "engine/framework/registry.hpp"

namespace dydp::blocks {
namespace {

using engine::Block;
using engine::DirView;
using engine::Eval;
using engine::Seeds;

/// One section N(s) / (s^2 + w0 s / Q + w0^2), N(s) = b2 s^2 + b1 s + b0, with states scaled
/// like the signal: xi1 = (w0^2 / D(s)) u, xi2 = xi1' / w0, so that
///   xi1' = w0 xi2,  xi2' = w0 (u - xi1 - xi2 / Q),
///   y = (b0 / w0^2 - b2) xi1 + (b1 / w0 - b2 / Q) xi2 + b2 u.
struct Section {
  double w0, q, c1, c2, d;
  static Section make(double w0, double q, double b2, double b1, double b0) {
    return {w0, q, b0 / (w0 * w0) - b2, b1 / w0 - b2 / q, b2};
  }
};

/// The sections of a weighting, the strictly proper low-pass Hl first: the output then reads
/// states only (no direct feedthrough), whatever follows.
std::vector<Section> weighting(const std::string& name) {
  const double tau = 2 * std::numbers::pi;
  const double w1 = tau * 0.4, w2 = tau * 100.0, q12 = 1 / std::sqrt(2.0);
  std::vector<Section> s;
  s.push_back(Section::make(w2, q12, 0.0, 0.0, w2 * w2));  // Hl = w2^2 / (s^2 + w2 s / Q2 + w2^2)
  s.push_back(Section::make(w1, q12, 1.0, 0.0, 0.0));      // Hh = s^2 / (s^2 + w1 s / Q1 + w1^2)
  const bool wk = name == "Wk";
  const double w3 = tau * (wk ? 12.5 : 2.0), w4 = tau * (wk ? 12.5 : 2.0), q4 = 0.63;
  // Ht = (1 + s / w3) / (1 + s / (Q4 w4) + s^2 / w4^2) = w4^2 (1 + s / w3) / (s^2 + w4 s / Q4 + w4^2)
  s.push_back(Section::make(w4, q4, 0.0, w4 * w4 / w3, w4 * w4));
  if (wk) {
    // Hs = (s^2 + w5 s / Q5 + w5^2) / (s^2 + w6 s / Q6 + w6^2): unit gain at high frequency,
    // (f5 / f6)^2 = 0.5 at low frequency, as the standard's tables have it (Wk(1 Hz) = 0.482).
    const double w5 = tau * 2.37, q5 = 0.91, w6 = tau * 3.35, q6 = 0.91;
    s.push_back(Section::make(w6, q6, 1.0, w5 / q5, w5 * w5));
  }
  return s;
}

class Iso2631Filter : public Block {
 public:
  explicit Iso2631Filter(const std::string& name) : sections_(weighting(name)) {
    declare_input("a", 1, "m/s^2", false);
    declare_output("a_weighted", 1, "m/s^2", false);
    std::vector<std::string> names;
    for (size_t k = 0; k < sections_.size(); ++k)
      for (const char* n : {"xi1_", "xi2_"}) names.push_back(n + std::to_string(k));
    // The states are scaled like the signal (Section): nominal 1 m/s^2, the default.
    declare_states(names);
  }

  /// Runs the cascade: section k's input u_k (u_0 = a), state derivatives into xdot (if given),
  /// returns the last section's output. Section 0 has b2 = 0, so the output never reads `a`.
  double cascade(const double* x, double a, double* xdot) const {
    double u = a;
    for (size_t k = 0; k < sections_.size(); ++k) {
      const Section& s = sections_[k];
      const double xi1 = x[2 * k], xi2 = x[2 * k + 1];
      if (xdot) {
        xdot[2 * k] = s.w0 * xi2;
        xdot[2 * k + 1] = s.w0 * (u - xi1 - xi2 / s.q);
      }
      u = s.c1 * xi1 + s.c2 * xi2 + (s.d != 0.0 ? s.d * u : 0.0);
    }
    return u;
  }

  void initial_state(const Eval&, double* x0) const override {
    for (int i = 0; i < num_states(); ++i) x0[i] = 0.0;
  }
  void initial_state_tangent(const Eval&, const Seeds& s, DirView dx0) const override {
    for (int d = 0; d < s.directions; ++d)
      for (int i = 0; i < num_states(); ++i) dx0(i, d) = 0.0;
  }
  void outputs(const Eval& e, double* const* y) const override { y[0][0] = cascade(e.x, 0.0, nullptr); }
  void outputs_tangent(const Eval&, const Seeds& s, const DirView* dy) const override {
    // The cascade is linear: its tangent is the cascade of the seeds.
    std::vector<double> dx(num_states());
    for (int d = 0; d < s.directions; ++d) {
      for (int i = 0; i < num_states(); ++i) dx[i] = s.x(i, d);
      dy[0](0, d) = cascade(dx.data(), 0.0, nullptr);
    }
  }
  void derivatives(const Eval& e, double* xdot) const override { cascade(e.x, e.u[0][0], xdot); }
  void derivatives_tangent(const Eval&, const Seeds& s, DirView dxdot) const override {
    std::vector<double> dx(num_states()), dxd(num_states());
    for (int d = 0; d < s.directions; ++d) {
      for (int i = 0; i < num_states(); ++i) dx[i] = s.x(i, d);
      cascade(dx.data(), s.u[0](0, d), dxd.data());
      for (int i = 0; i < num_states(); ++i) dxdot(i, d) = dxd[i];
    }
  }

 private:
  std::vector<Section> sections_;
};

const engine::BlockRegistration iso2631({
    "filter.iso2631", "comfort",
    "ISO 2631-1 frequency weighting (Wk vertical, Wd horizontal) of an acceleration; rms it with objective.rms.",
    {},
    {{"weighting", "Wk or Wd", "Wk", false}},
    [](const engine::BlockSettings& s) -> std::unique_ptr<Block> {
      const std::string w = s.text("weighting");
      if (w != "Wk" && w != "Wd") s.fail("weighting", "expected Wk or Wd, got '" + w + "'");
      return std::make_unique<Iso2631Filter>(w);
    }});

}  // namespace
}  // namespace dydp::blocks
