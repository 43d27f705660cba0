// Math blocks: gain, sum, product (direct feedthrough) and integrator, first-order lag (states).
#include <cmath>
#include <string>

#include "engine/framework/registry.hpp"

namespace dydp::blocks {
namespace {

using engine::Block;
using engine::BlockSettings;
using engine::DirView;
using engine::Eval;
using engine::Seeds;

constexpr double kInf = std::numeric_limits<double>::infinity();

int width_of(const BlockSettings& s) {
  const int w = s.integer("width");
  if (w < 1) s.fail("width", "must be at least 1");
  return w;
}

/// y = k u, element-wise.
class Gain : public Block {
 public:
  explicit Gain(int width) : w_(width) {
    declare_input("u", w_);
    declare_output("y", w_);
  }
  void outputs(const Eval& e, double* const* y) const override {
    for (int i = 0; i < w_; ++i) y[0][i] = e.p[0] * e.u[0][i];
  }
  void outputs_tangent(const Eval& e, const Seeds& s, const DirView* dy) const override {
    for (int d = 0; d < s.directions; ++d)
      for (int i = 0; i < w_; ++i) dy[0](i, d) = e.p[0] * s.u[0](i, d) + e.u[0][i] * s.p(0, d);
  }

 private:
  int w_;
};

/// y = sum over inputs of sign_k u_k; signs from a string such as "+-+".
class Sum : public Block {
 public:
  Sum(const std::string& signs, int width) : w_(width) {
    for (size_t k = 0; k < signs.size(); ++k) {
      sign_.push_back(signs[k] == '-' ? -1.0 : 1.0);
      declare_input("in" + std::to_string(k + 1), w_);
    }
    declare_output("y", w_, engine::kUnitOfFirstInput);
  }
  void outputs(const Eval& e, double* const* y) const override {
    for (int i = 0; i < w_; ++i) {
      double acc = 0;
      for (size_t k = 0; k < sign_.size(); ++k) acc += sign_[k] * e.u[k][i];
      y[0][i] = acc;
    }
  }
  void outputs_tangent(const Eval&, const Seeds& s, const DirView* dy) const override {
    for (int d = 0; d < s.directions; ++d)
      for (int i = 0; i < w_; ++i) {
        double acc = 0;
        for (size_t k = 0; k < sign_.size(); ++k) acc += sign_[k] * s.u[k](i, d);
        dy[0](i, d) = acc;
      }
  }

 private:
  int w_;
  std::vector<double> sign_;
};

/// y = a * b, element-wise.
class Product : public Block {
 public:
  explicit Product(int width) : w_(width) {
    declare_input("a", w_);
    declare_input("b", w_);
    declare_output("y", w_);
  }
  void outputs(const Eval& e, double* const* y) const override {
    for (int i = 0; i < w_; ++i) y[0][i] = e.u[0][i] * e.u[1][i];
  }
  void outputs_tangent(const Eval& e, const Seeds& s, const DirView* dy) const override {
    for (int d = 0; d < s.directions; ++d)
      for (int i = 0; i < w_; ++i)
        dy[0](i, d) = s.u[0](i, d) * e.u[1][i] + e.u[0][i] * s.u[1](i, d);
  }

 private:
  int w_;
};

/// dx/dt = u, y = x, x(t0) = initial.
class Integrator : public Block {
 public:
  explicit Integrator(int width) : w_(width) {
    declare_input("u", w_, "", false);
    declare_output("y", w_, "", false);
    std::vector<std::string> names;
    for (int i = 0; i < w_; ++i) names.push_back(w_ == 1 ? "x" : "x" + std::to_string(i));
    declare_states(names);
  }
  void initial_state(const Eval& e, double* x0) const override {
    for (int i = 0; i < w_; ++i) x0[i] = e.p[0];
  }
  void initial_state_tangent(const Eval&, const Seeds& s, DirView dx0) const override {
    for (int d = 0; d < s.directions; ++d)
      for (int i = 0; i < w_; ++i) dx0(i, d) = s.p(0, d);
  }
  void outputs(const Eval& e, double* const* y) const override {
    for (int i = 0; i < w_; ++i) y[0][i] = e.x[i];
  }
  void outputs_tangent(const Eval&, const Seeds& s, const DirView* dy) const override {
    for (int d = 0; d < s.directions; ++d)
      for (int i = 0; i < w_; ++i) dy[0](i, d) = s.x(i, d);
  }
  void derivatives(const Eval& e, double* xdot) const override {
    for (int i = 0; i < w_; ++i) xdot[i] = e.u[0][i];
  }
  void derivatives_tangent(const Eval&, const Seeds& s, DirView dxdot) const override {
    for (int d = 0; d < s.directions; ++d)
      for (int i = 0; i < w_; ++i) dxdot(i, d) = s.u[0](i, d);
  }

 private:
  int w_;
};

/// tau dx/dt = u - x, y = x (first-order lag, unit static gain).
class Lag : public Integrator {
 public:
  enum { kInitial, kTau };
  explicit Lag(int width) : Integrator(width), w_(width) {}
  void derivatives(const Eval& e, double* xdot) const override {
    for (int i = 0; i < w_; ++i) xdot[i] = (e.u[0][i] - e.x[i]) / e.p[kTau];
  }
  void derivatives_tangent(const Eval& e, const Seeds& s, DirView dxdot) const override {
    const double tau = e.p[kTau];
    for (int d = 0; d < s.directions; ++d)
      for (int i = 0; i < w_; ++i)
        dxdot(i, d) = (s.u[0](i, d) - s.x(i, d)) / tau -
                      (e.u[0][i] - e.x[i]) / (tau * tau) * s.p(kTau, d);
  }

 private:
  int w_;
};

const engine::SettingSpec kWidth{"width", "number of elements of the signal", "1", false};

const engine::BlockRegistration gain({
    "math.gain", "math", "y = k u, element-wise.",
    {{"k", "", 1.0, false, -kInf, kInf, "gain"}}, {kWidth},
    [](const BlockSettings& s) -> std::unique_ptr<Block> { return std::make_unique<Gain>(width_of(s)); }});

const engine::BlockRegistration sum({
    "math.sum", "math", "y = sum of the inputs in1, in2, ... with the signs given.",
    {}, {{"signs", "one + or - per input, e.g. +-", "++", false}, kWidth},
    [](const BlockSettings& s) -> std::unique_ptr<Block> {
      const std::string signs = s.text("signs");
      if (signs.empty() || signs.find_first_not_of("+-") != std::string::npos)
        s.fail("signs", "expected a string of + and -, got '" + signs + "'");
      return std::make_unique<Sum>(signs, width_of(s));
    }});

const engine::BlockRegistration product({
    "math.product", "math", "y = a * b, element-wise.", {}, {kWidth},
    [](const BlockSettings& s) -> std::unique_ptr<Block> { return std::make_unique<Product>(width_of(s)); }});

const engine::BlockRegistration integrator({
    "math.integrator", "math", "y = initial + integral of u.",
    {{"initial", "", 0.0, false, -kInf, kInf, "value at the start"}}, {kWidth},
    [](const BlockSettings& s) -> std::unique_ptr<Block> { return std::make_unique<Integrator>(width_of(s)); }});

const engine::BlockRegistration lag({
    "math.lag", "math", "First-order lag: tau dy/dt = u - y.",
    {{"initial", "", 0.0, false, -kInf, kInf, "value at the start"},
     {"tau", "s", 0.1, false, 1e-12, kInf, "time constant"}},
    {kWidth},
    [](const BlockSettings& s) -> std::unique_ptr<Block> { return std::make_unique<Lag>(width_of(s)); }});

}  // namespace
}  // namespace dydp::blocks

namespace dydp::blocks {
namespace {

/// y = (u[i0], u[i1], ...): picks elements of a wider signal.
class Demux : public Block {
 public:
  Demux(int width, std::vector<int> indices) : index_(std::move(indices)) {
    declare_input("u", width);
    declare_output("y", static_cast<int>(index_.size()), engine::kUnitOfFirstInput);
  }
  void outputs(const Eval& e, double* const* y) const override {
    for (size_t k = 0; k < index_.size(); ++k) y[0][k] = e.u[0][index_[k]];
  }
  void outputs_tangent(const Eval&, const Seeds& s, const DirView* dy) const override {
    for (int d = 0; d < s.directions; ++d)
      for (size_t k = 0; k < index_.size(); ++k) dy[0](static_cast<int>(k), d) = s.u[0](index_[k], d);
  }

 private:
  std::vector<int> index_;
};

/// y = (in1, in2, ...): scalar inputs stacked into one signal.
class Mux : public Block {
 public:
  explicit Mux(int n) : n_(n) {
    for (int k = 0; k < n; ++k) declare_input("in" + std::to_string(k + 1), 1);
    declare_output("y", n, engine::kUnitOfFirstInput);
  }
  void outputs(const Eval& e, double* const* y) const override {
    for (int k = 0; k < n_; ++k) y[0][k] = e.u[k][0];
  }
  void outputs_tangent(const Eval&, const Seeds& s, const DirView* dy) const override {
    for (int d = 0; d < s.directions; ++d)
      for (int k = 0; k < n_; ++k) dy[0](k, d) = s.u[k](0, d);
  }

 private:
  int n_;
};

const engine::BlockRegistration demux({
    "math.demux", "math", "y = the listed elements of u (0-based), e.g. indices: [2].", {},
    {{"indices", "elements of u to output, 0-based", "0", false}, {"width", "width of u", "1", false}},
    [](const BlockSettings& s) -> std::unique_ptr<Block> {
      const int width = width_of(s);
      std::vector<int> index;
      for (double v : s.numbers("indices")) {
        if (v != std::floor(v) || v < 0 || v >= width)
          s.fail("indices", "index " + std::to_string(v) + " outside 0.." + std::to_string(width - 1));
        index.push_back(static_cast<int>(v));
      }
      return std::make_unique<Demux>(width, index);
    }});

const engine::BlockRegistration mux({
    "math.mux", "math", "y = (in1, in2, ...): scalar inputs stacked into one signal.", {},
    {{"inputs", "number of scalar inputs", "2", false}},
    [](const BlockSettings& s) -> std::unique_ptr<Block> {
      const int n = s.integer("inputs");
      if (n < 1) s.fail("inputs", "must be at least 1");
      return std::make_unique<Mux>(n);
    }});

}  // namespace
}  // namespace dydp::blocks
