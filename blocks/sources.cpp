// Signal sources: constant, step, ramp and sine. Each output is a closed-form function of time
// and the block's parameters, so each tangent is the parameter derivative of that formula.
#include <cmath>
#include <numbers>

#include "engine/framework/registry.hpp"

namespace dydp::blocks {
namespace {

using engine::Block;
using engine::DirView;
using engine::Eval;
using engine::ParamSpec;
using engine::Seeds;

constexpr double kInf = std::numeric_limits<double>::infinity();

/// y = value.
class Constant : public Block {
 public:
  Constant() { declare_output("y", 1); }
  void outputs(const Eval& e, double* const* y) const override { y[0][0] = e.p[0]; }
  void outputs_tangent(const Eval&, const Seeds& s, const DirView* dy) const override {
    for (int d = 0; d < s.directions; ++d) dy[0](0, d) = s.p(0, d);
  }
};

/// y = before for t < time, after from t = time on.
class Step : public Block {
 public:
  enum { kTime, kBefore, kAfter };
  Step() { declare_output("y", 1); }
  void outputs(const Eval& e, double* const* y) const override {
    y[0][0] = e.reached(e.p[kTime]) ? e.p[kAfter] : e.p[kBefore];
  }
  void outputs_tangent(const Eval& e, const Seeds& s, const DirView* dy) const override {
    const int j = e.reached(e.p[kTime]) ? kAfter : kBefore;
    for (int d = 0; d < s.directions; ++d) dy[0](0, d) = s.p(j, d);
  }
  std::vector<double> breakpoints(const double* p, double, double) const override { return {p[kTime]}; }
};

/// y = offset + slope * max(0, t - start).
class Ramp : public Block {
 public:
  enum { kStart, kSlope, kOffset };
  Ramp() { declare_output("y", 1); }
  static double elapsed(const Eval& e) { return e.reached(e.p[kStart]) ? e.t - e.p[kStart] : 0.0; }
  void outputs(const Eval& e, double* const* y) const override {
    y[0][0] = e.p[kOffset] + e.p[kSlope] * elapsed(e);
  }
  void outputs_tangent(const Eval& e, const Seeds& s, const DirView* dy) const override {
    const double dt = elapsed(e);
    for (int d = 0; d < s.directions; ++d) dy[0](0, d) = s.p(kOffset, d) + dt * s.p(kSlope, d);
  }
  std::vector<double> breakpoints(const double* p, double, double) const override { return {p[kStart]}; }
};

/// y = offset + amplitude * sin(2 pi frequency t + phase).
class Sine : public Block {
 public:
  enum { kAmplitude, kFrequency, kPhase, kOffset };
  Sine() { declare_output("y", 1); }
  void outputs(const Eval& e, double* const* y) const override {
    const double arg = 2 * std::numbers::pi * e.p[kFrequency] * e.t + e.p[kPhase];
    y[0][0] = e.p[kOffset] + e.p[kAmplitude] * std::sin(arg);
  }
  void outputs_tangent(const Eval& e, const Seeds& s, const DirView* dy) const override {
    const double w = 2 * std::numbers::pi * e.t;
    const double arg = w * e.p[kFrequency] + e.p[kPhase];
    const double sn = std::sin(arg), cs = std::cos(arg), a = e.p[kAmplitude];
    for (int d = 0; d < s.directions; ++d)
      dy[0](0, d) = s.p(kOffset, d) + sn * s.p(kAmplitude, d) +
                    a * cs * (w * s.p(kFrequency, d) + s.p(kPhase, d));
  }
};

template <class B>
std::unique_ptr<Block> make(const engine::BlockSettings&) { return std::make_unique<B>(); }

const engine::BlockRegistration constant({
    "source.constant", "sources", "A constant value y.",
    {{"value", "", 0.0, false, -kInf, kInf, "the output value"}}, {}, make<Constant>});

const engine::BlockRegistration step({
    "source.step", "sources", "Steps from `before` to `after` at `time`.",
    {{"time", "s", 0.0, false, -kInf, kInf, "switching time", false},
     {"before", "", 0.0, false, -kInf, kInf, "value before the step"},
     {"after", "", 1.0, false, -kInf, kInf, "value from the step on"}},
    {}, make<Step>});

const engine::BlockRegistration ramp({
    "source.ramp", "sources", "offset + slope * (t - start) from `start` on, offset before.",
    {{"start", "s", 0.0, false, -kInf, kInf, "time the ramp starts", false},
     {"slope", "1/s", 1.0, false, -kInf, kInf, "rate of rise"},
     {"offset", "", 0.0, false, -kInf, kInf, "value before the ramp"}},
    {}, make<Ramp>});

const engine::BlockRegistration sine({
    "source.sine", "sources", "offset + amplitude * sin(2 pi frequency t + phase).",
    {{"amplitude", "", 1.0, false, -kInf, kInf, "peak value"},
     {"frequency", "Hz", 1.0, false, 0.0, kInf, "frequency"},
     {"phase", "rad", 0.0, false, -kInf, kInf, "phase at t = 0"},
     {"offset", "", 0.0, false, -kInf, kInf, "mean value"}},
    {}, make<Sine>});

}  // namespace
}  // namespace dydp::blocks
