// The Jacobian from the diagram's structure (engine/evaluation/jacobian_colouring.hpp): columns whose
// rows do not meet share a tangent pass, and the Jacobian scattered back from the colours is
// the one-column-per-direction Jacobian entry for entry; every nonzero of it lies in the
// structure.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "engine/evaluation/evaluator.hpp"
#include "engine/evaluation/jacobian_colouring.hpp"
#include "engine/framework/diagram.hpp"
#include "tests/temp_folder_test.hpp"

namespace dydp::engine {
namespace {

class Colouring : public test::TempFolderTest {
 protected:
  Colouring() : TempFolderTest("dydp_colouring_") {}
};

// Two masses on springs, each driven by its own force and measured by its own objective; with
// `coupled`, the first's position also drives the second.
std::string two_masses(bool coupled) {
  std::string s = R"(scene: two_masses
time: {start: 0.0, stop: 1.0, output_step: 0.01}
blocks:
  f1: {type: source.sine, amplitude: 2.0, frequency: 0.8}
  f2: {type: source.sine, amplitude: 1.0, frequency: 1.3}
  body1: {type: mass_spring_damper, m: 1.5, k: 40.0, c: 1.2, x0: 0.05, v0: 0.0}
  body2: {type: mass_spring_damper, m: 0.5, k: 90.0, c: 0.3, x0: -0.02, v0: 0.1}
  push: {type: math.gain, k: 30.0}
  total: {type: math.sum}
  o1: {type: objective.rms, window: [0.0, 1.0]}
  o2: {type: objective.rms, window: [0.0, 1.0]}
connections:
  - f1.y -> body1.f
  - body1.x -> o1.in
  - body2.x -> o2.in
)";
  s += coupled ? "  - body1.x -> push.u\n  - push.y -> total.in1\n  - f2.y -> total.in2\n  - total.y -> body2.f\n"
               : "  - f2.y -> push.u\n  - push.y -> total.in1\n  - f2.y -> total.in2\n  - total.y -> body2.f\n";
  return s + "outputs: [o1, o2]\n";
}

// The coloured Jacobian against the identity's at a few states; returns the colouring.
JacobianColouring check_against_identity(const Diagram& d) {
  Evaluator ev(d, false);
  JacobianColouring colouring(d);
  const int nx = d.num_states, nq = d.num_quadratures;
  std::vector<double> x(nx);
  ev.initial_state(d.time.start, x.data());
  std::vector<double> identity(static_cast<std::size_t>(nx) * nx, 0.0);
  for (int i = 0; i < nx; ++i) identity[static_cast<std::size_t>(i) * nx + i] = 1.0;
  for (int trial = 0; trial < 3; ++trial) {
    const double t = d.time.start + 0.1 * trial;
    std::vector<double> J(static_cast<std::size_t>(nx) * nx, -1.0), JQ(static_cast<std::size_t>(nq) * nx, -1.0);
    std::vector<double> Jref(J.size()), JQref(JQ.size());
    colouring.evaluate(ev, t, x.data(), {J.data(), nx}, {nq ? JQ.data() : nullptr, nq});
    ev.tangents(t, x.data(), nx, {identity.data(), nx}, false, {Jref.data(), nx}, {nq ? JQref.data() : nullptr, nq});
    for (int j = 0; j < nx; ++j) {
      for (int r = 0; r < nx; ++r) {
        EXPECT_EQ(J[j * nx + r], Jref[j * nx + r]) << "row " << r << ", column " << j;
        if (Jref[j * nx + r] != 0.0) EXPECT_TRUE(colouring.reaches(j, r)) << "row " << r << ", column " << j;
      }
      for (int r = 0; r < nq; ++r) {
        EXPECT_EQ(JQ[j * nq + r], JQref[j * nq + r]) << "quadrature row " << r << ", column " << j;
        if (JQref[j * nq + r] != 0.0) EXPECT_TRUE(colouring.reaches(j, nx + r)) << "quadrature " << r << ", column " << j;
      }
    }
    for (double& v : x) v *= 1.0 + 0.1 * (trial + 1);  // another state
  }
  return colouring;
}

TEST_F(Colouring, IndependentSubsystemsShareTangentPasses) {
  const Diagram d = load_scene(write("s.yaml", two_masses(false)));
  ASSERT_EQ(d.num_states, 4);
  const JacobianColouring c = check_against_identity(d);
  EXPECT_EQ(c.colours(), 2) << "each mass's two states: one pass for both masses";
  EXPECT_EQ(c.colour_of(0) == c.colour_of(1), false);
  EXPECT_FALSE(c.reaches(0, 2)) << "the first mass does not move the second";
  EXPECT_FALSE(c.reaches(2, 0)) << "nor the second the first";
}

TEST_F(Colouring, ACouplingSeparatesTheColours) {
  const Diagram d = load_scene(write("s.yaml", two_masses(true)));
  const JacobianColouring c = check_against_identity(d);
  EXPECT_EQ(c.colours(), 4) << "the first mass drives the second: no column can share";
  EXPECT_TRUE(c.reaches(0, 2)) << "through the gain and the sum";
  EXPECT_FALSE(c.reaches(2, 0)) << "one way only";
  for (const Node& n : d.nodes) {
    if (n.name != "o2") continue;
    EXPECT_TRUE(c.reaches(2, d.num_states + n.quad_offset)) << "the second mass's position into its objective";
    EXPECT_FALSE(c.reaches(0, d.num_states + n.quad_offset))
        << "a state-only output (the second mass's position) stops the first mass's reach";
  }
}

TEST(ColouringScenes, TheShippedScenesJacobiansAreTheIdentitysEntryForEntry) {
  for (const char* scene : {"quarter_car_cdc", "fourposter_comfort", "cornering_arb"}) {
    SCOPED_TRACE(scene);
    const Diagram d = load_scene(std::string(DYDP_SOURCE_DIR) + "/scenarios/" + scene + ".yaml");
    const JacobianColouring c = check_against_identity(d);
    RecordProperty(std::string(scene) + "_colours", c.colours());
    RecordProperty(std::string(scene) + "_states", d.num_states);
    EXPECT_LE(c.colours(), d.num_states);
  }
}

}  // namespace
}  // namespace dydp::engine
