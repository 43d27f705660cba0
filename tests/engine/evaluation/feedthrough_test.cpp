// Direct feedthrough per output-input pair: a block whose outputs read different inputs is
// evaluated in one step per group of outputs, so wiring one output back into an input that
// only another output reads is no algebraic loop; values and tangents follow the chain.
// Wiring an output back into an input it reads is a loop, reported at the file's line.
#include <gtest/gtest.h>

#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "engine/evaluation/evaluator.hpp"
#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"
#include "engine/framework/registry.hpp"
#include "tests/temp_folder_test.hpp"

namespace dydp::engine {
namespace {

namespace fs = std::filesystem;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Inputs u1, u2; state x (x' = u2 - x); parameter c.
// y1 = c u1 + x reads u1 only, y2 = u2^2 + c reads u2 only.
class SplitFeedthrough : public Block {
 public:
  SplitFeedthrough() {
    declare_input("u1", 1);
    declare_input("u2", 1);
    declare_output("y1", 1);
    declare_output("y2", 1);
    set_output_reads(0, {0});
    set_output_reads(1, {1});
    declare_states({"x"});
  }
  void initial_state(const Eval&, double* x0) const override { x0[0] = 0.0; }
  void outputs(const Eval& e, double* const* y) const override {
    if (output_ready(e, 0)) y[0][0] = e.p[0] * e.u[0][0] + e.x[0];
    if (output_ready(e, 1)) y[1][0] = e.u[1][0] * e.u[1][0] + e.p[0];
  }
  void outputs_tangent(const Eval& e, const Seeds& s, const DirView* dy) const override {
    for (int d = 0; d < s.directions; ++d) {
      if (output_ready(e, 0)) dy[0](0, d) = s.p(0, d) * e.u[0][0] + e.p[0] * s.u[0](0, d) + s.x(0, d);
      if (output_ready(e, 1)) dy[1](0, d) = 2.0 * e.u[1][0] * s.u[1](0, d) + s.p(0, d);
    }
  }
  void derivatives(const Eval& e, double* xdot) const override { xdot[0] = e.u[1][0] - e.x[0]; }
  void derivatives_tangent(const Eval&, const Seeds& s, DirView dxdot) const override {
    for (int d = 0; d < s.directions; ++d) dxdot(0, d) = s.u[1](0, d) - s.x(0, d);
  }
};

const BlockRegistration registration({"test.split_feedthrough", "test",
                                      "y1 = c u1 + x, y2 = u2^2 + c, x' = u2 - x",
                                      {{"c", "", 1.0, false, -kInf, kInf, "gain of u1 and offset of y2"}},
                                      {},
                                      [](const BlockSettings&) -> std::unique_ptr<Block> {
                                        return std::make_unique<SplitFeedthrough>();
                                      }});

class Feedthrough : public test::TempFolderTest {
 protected:
  Feedthrough() : TempFolderTest("dydp_feedthrough_") {}

  std::string write(const std::string& text) const { return TempFolderTest::write("s.yaml", text); }
  static int index_of(const Diagram& d, const std::string& name) {
    for (size_t i = 0; i < d.nodes.size(); ++i)
      if (d.nodes[i].name == name) return static_cast<int>(i);
    return -1;
  }
};

// src.y = a -> b.u1; b.y1 -> gain (k) -> b.u2. With x the state of b:
//   y1 = c a + x, g = k y1, y2 = g^2 + c, x' = g - x.
TEST_F(Feedthrough, OutputIntoInputReadOnlyByAnotherOutputIsNoLoop) {
  const std::string path = write(R"(scene: t
time: {stop: 1.0, output_step: 0.1}
parameters:
  a: {value: 2.0}
  k: {value: 3.0}
  c: {value: 0.5}
sensitivities: [a, k, c]
blocks:
  b: {type: test.split_feedthrough, c: $c}
  gain: {type: math.gain, k: $k}
  src: {type: source.constant, value: $a}
connections:
  - src.y -> b.u1
  - b.y1 -> gain.u
  - gain.y -> b.u2
outputs: [b.y1, b.y2]
)");
  Diagram d;
  ASSERT_NO_THROW(d = load_scene(path));
  const int b = index_of(d, "b"), gain = index_of(d, "gain"), src = index_of(d, "src");
  ASSERT_GE(b, 0);
  ASSERT_GE(gain, 0);
  ASSERT_GE(src, 0);

  // Order: src, b for y1 (u1 ready), gain, b for y2 (u1 and u2 ready).
  ASSERT_EQ(d.output_steps.size(), 4u);
  EXPECT_EQ(d.output_steps[0].node, src);
  EXPECT_EQ(d.output_steps[1].node, b);
  EXPECT_EQ(d.output_steps[1].outputs, std::vector<int>{0});
  EXPECT_EQ(d.output_steps[1].ready, (std::vector<unsigned char>{1, 0}));
  EXPECT_FALSE(d.output_steps[1].inputs_ready);
  EXPECT_EQ(d.output_steps[2].node, gain);
  EXPECT_EQ(d.output_steps[3].node, b);
  EXPECT_EQ(d.output_steps[3].outputs, std::vector<int>{1});
  EXPECT_EQ(d.output_steps[3].ready, (std::vector<unsigned char>{1, 1}));
  EXPECT_TRUE(d.output_steps[3].inputs_ready);

  const double a = 2.0, k = 3.0, c = 0.5, x = 0.5;
  const double y1 = c * a + x, g = k * y1, y2 = g * g + c;
  const int at_y1 = d.nodes[b].output_offset[0], at_y2 = d.nodes[b].output_offset[1];
  const int ld = d.num_signals;

  Evaluator ev(d, true);
  ASSERT_EQ(ev.num_directions(), 3);
  const double state[1] = {x};
  double xdot[1] = {0.0};
  ev.derivatives(0.0, state, xdot);
  EXPECT_DOUBLE_EQ(ev.signals()[at_y1], y1);
  EXPECT_DOUBLE_EQ(ev.signals()[at_y2], y2);
  EXPECT_DOUBLE_EQ(xdot[0], g - x);

  // Parameter directions a, k, c.
  std::vector<double> dxdot(3, 0.0);
  ev.tangents(0.0, state, 3, {}, true, {dxdot.data(), 1}, {});
  const auto& ds = ev.signal_tangents();
  EXPECT_DOUBLE_EQ(ds[0 * ld + at_y1], c);
  EXPECT_DOUBLE_EQ(ds[1 * ld + at_y1], 0.0);
  EXPECT_DOUBLE_EQ(ds[2 * ld + at_y1], a);
  EXPECT_DOUBLE_EQ(ds[0 * ld + at_y2], 2.0 * g * k * c);   // 13.5
  EXPECT_DOUBLE_EQ(ds[1 * ld + at_y2], 2.0 * g * y1);      // 13.5
  EXPECT_DOUBLE_EQ(ds[2 * ld + at_y2], 2.0 * g * k * a + 1.0);  // 55
  EXPECT_DOUBLE_EQ(dxdot[0], k * c);
  EXPECT_DOUBLE_EQ(dxdot[1], y1);
  EXPECT_DOUBLE_EQ(dxdot[2], k * a);

  // Jacobian pass: the state seed alone (the source's tangent is zero, b's is not).
  const double seed[1] = {1.0};
  double jac[1] = {0.0};
  ev.tangents(0.0, state, 1, {seed, 1}, false, {jac, 1}, {});
  EXPECT_DOUBLE_EQ(ev.signal_tangents()[at_y1], 1.0);
  EXPECT_DOUBLE_EQ(ev.signal_tangents()[at_y2], 2.0 * g * k);  // 27
  EXPECT_DOUBLE_EQ(jac[0], k - 1.0);
}

TEST_F(Feedthrough, OutputIntoInputItReadsIsAnAlgebraicLoop) {
  const std::string path = write(R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.constant, value: 1.0}
  b: {type: test.split_feedthrough}
  gain: {type: math.gain, k: 0.5}
connections:
  - src.y -> b.u1
  - b.y2 -> gain.u
  - gain.y -> b.u2
outputs: [b.y1]
)");
  try {
    load_scene(path);
    ADD_FAILURE() << "no algebraic loop reported";
  } catch (const InputError& e) {
    // The loop's first connection in the file; the CLI prints this and exits with status 2.
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.line(), 9) << e.what();
    EXPECT_EQ(e.field(), "connections");
    const std::string what = e.what();
    EXPECT_EQ(what.rfind(path + ":9: ", 0), 0u) << what;
    EXPECT_NE(what.find("algebraic loop"), std::string::npos) << what;
    EXPECT_NE(what.find("b -> gain"), std::string::npos) << what;
    EXPECT_EQ(what.find("src"), std::string::npos) << "src is not on the loop: " << what;
  }
}

}  // namespace
}  // namespace dydp::engine
