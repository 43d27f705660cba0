// Physical error control: the absolute tolerance of each state is atol times its nominal
// magnitude (declared by the block, overridden by a scene's `nominal:` map), and the run
// reports which states limited the step.
//
// The checks rest on what the tolerance vector must do, not on recorded step counts: a run
// with nominal s and atol a holds every state to a * s, exactly as a run with nominal 1 and
// atol a * s does (the two must take the same steps and give the same numbers); a smaller
// nominal is a tighter tolerance and must cost more steps; and of two uncoupled oscillators,
// the fast one sets the step until the slow one's tolerance is made far tighter.
#include <gtest/gtest.h>

#include <numeric>

#include <cmath>

#include <fstream>
#include <iterator>
#include <numeric>
#include <string>

#include "engine/analysis/run.hpp"
#include "engine/analysis/tolerances.hpp"
#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"
#include "io/output_writer.hpp"
#include "tests/temp_folder_test.hpp"

namespace dydp::engine {
namespace {

class ErrorControl : public test::TempFolderTest {
 protected:
  ErrorControl() : TempFolderTest("dydp_error_control_") {}

  /// A damped oscillator released from x0 = 1 mm, decaying over 10 s, so that the absolute
  /// tolerance (not rtol) decides the steps once it has decayed; sensitivity to k.
  std::string decaying(const std::string& atol, const std::string& nominal) {
    return write("decay.yaml",
                 "scene: decay\n"
                 "time: {stop: 10.0, output_step: 0.1}\n"
                 "solver: {method: bdf, rtol: 1.0e-4, atol: " + atol + "}\n"
                 "parameters:\n"
                 "  k: {value: 400.0}\n"
                 "sensitivities: [k]\n"
                 "blocks:\n"
                 "  zero: {type: source.constant, value: 0.0}\n"
                 "  m: {type: mass_spring_damper, m: 1.0, k: $k, c: 4.0, x0: 1.0e-3" +
                     (nominal.empty() ? "" : ", nominal: " + nominal) + "}\n"
                 "connections:\n"
                 "  - zero.y -> m.f\n"
                 "outputs: [m.x]\n");
  }

  /// Two uncoupled oscillators, 1 rad/s and 3 rad/s, of equal amplitude, with rtol so small that
  /// the absolute tolerances alone set the step: at equal tolerances the fast one's local error
  /// (of the order of omega^(q+1) at order q) is the larger, by 3^(q+1) <= 729 up to order 5.
  std::string two_oscillators(const std::string& slow_nominal) {
    return write("two.yaml",
                 "scene: two\n"
                 "time: {stop: 5.0, output_step: 0.05}\n"
                 "solver: {method: bdf, rtol: 1.0e-13, atol: 1.0e-6}\n"
                 "blocks:\n"
                 "  zero: {type: source.constant, value: 0.0}\n"
                 "  slow: {type: mass_spring_damper, m: 1.0, k: 1.0, x0: 1.0" +
                     (slow_nominal.empty() ? "" : ", nominal: " + slow_nominal) + "}\n"
                 "  fast: {type: mass_spring_damper, m: 1.0, k: 9.0, x0: 1.0}\n"
                 "connections:\n"
                 "  - zero.y -> slow.f\n"
                 "  - zero.y -> fast.f\n"
                 "outputs: [slow.x, fast.x]\n");
  }

  static std::string read(const std::string& path) {
    std::ifstream in(path);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }

  static double share_of(const RunStats& s, const std::string& block) {
    double share = 0.0;
    for (const LimitingState& l : s.limiting_states)
      if (l.state.rfind(block + ".", 0) == 0) share += l.share;
    return share;
  }
};

TEST_F(ErrorControl, BlocksDeclareNominalsAndScenesOverrideThem) {
  const Diagram d = load_scene(write("n.yaml",
                                     "scene: n\n"
                                     "time: {stop: 1.0, output_step: 0.1}\n"
                                     "blocks:\n"
                                     "  zero: {type: source.constant, value: 0.0}\n"
                                     "  damper: {type: damper.cdc, nominal: {q_valve: 2.0e-4}}\n"
                                     "  m: {type: mass_spring_damper, nominal: {v: 0.5}}\n"
                                     "connections:\n"
                                     "  - zero.y -> damper.stroke\n"
                                     "  - zero.y -> damper.stroke_rate\n"
                                     "  - damper.force -> m.f\n"
                                     "outputs: [m.x]\n"));
  const std::vector<double> nominal = state_nominals(d);
  ASSERT_EQ(nominal.size(), 6u);
  // damper: the three pressures as declared (1 MPa), the flow overridden; m: x by default (1).
  for (const Node& n : d.nodes) {
    if (n.name == "damper") {
      EXPECT_EQ(nominal[n.state_offset + 0], 1e6);
      EXPECT_EQ(nominal[n.state_offset + 2], 1e6);
      EXPECT_EQ(nominal[n.state_offset + 3], 2e-4);
      EXPECT_EQ(state_label(d, n.state_offset + 3), "damper.q_valve");
    }
    if (n.name == "m") {
      EXPECT_EQ(nominal[n.state_offset + 0], 1.0);
      EXPECT_EQ(nominal[n.state_offset + 1], 0.5);
    }
  }
  const AbsoluteTolerances t = absolute_tolerances(d, 1e-8, 0);
  for (int i = 0; i < d.num_states; ++i) EXPECT_DOUBLE_EQ(t.states[i], 1e-8 * nominal[i]);
}

TEST_F(ErrorControl, NominalTimesAtolIsTheToleranceCvodesGets) {
  // nominal 2^-10 with atol 1e-6 must be the run with nominal 1 and atol 1e-6 / 1024: same
  // steps, same values, same sensitivities (their tolerance, atol * nominal / |k|, the same too).
  // A power of two, so that atol * nominal is the double nearest to 9.765625e-10 as written.
  RunResult scaled = run(load_scene(decaying("1.0e-6", "{x: 0.0009765625, v: 0.0009765625}")));
  RunResult plain = run(load_scene(decaying("9.765625e-10", "")));
  EXPECT_GT(scaled.stats.steps, run(load_scene(decaying("1.0e-6", ""))).stats.steps);
  EXPECT_EQ(scaled.stats.steps, plain.stats.steps);
  ASSERT_EQ(scaled.values.size(), plain.values.size());
  for (size_t i = 0; i < plain.values.size(); ++i) EXPECT_EQ(scaled.values[i], plain.values[i]);
  for (size_t i = 0; i < plain.tangents.size(); ++i) EXPECT_EQ(scaled.tangents[i], plain.tangents[i]);
}

TEST_F(ErrorControl, WithoutNominalScalingAtolHoldsEveryStateAsItStands) {
  // nominal_scaling: false ignores the nominals: the run with nominal 2^-10 is then the run with
  // nominal 1, and it is not the scaled one.
  const std::string nominal = "{x: 0.0009765625, v: 0.0009765625}";
  std::string text = read(decaying("1.0e-6", nominal));
  text.replace(text.find("atol: 1.0e-6}"), 13, "atol: 1.0e-6, nominal_scaling: false}");
  const RunResult unscaled = run(load_scene(write("unscaled.yaml", text)));
  const RunResult plain = run(load_scene(decaying("1.0e-6", "")));
  const RunResult scaled = run(load_scene(decaying("1.0e-6", nominal)));
  EXPECT_EQ(unscaled.stats.steps, plain.stats.steps);
  EXPECT_EQ(unscaled.values, plain.values);
  EXPECT_EQ(unscaled.tangents, plain.tangents);
  EXPECT_NE(unscaled.stats.steps, scaled.stats.steps);
}

TEST_F(ErrorControl, SmallerNominalCostsMoreSteps) {
  const long loose = run(load_scene(decaying("1.0e-6", ""))).stats.steps;
  const long tight = run(load_scene(decaying("1.0e-6", "{x: 1.0e-3, v: 1.0e-2}"))).stats.steps;
  const long tighter = run(load_scene(decaying("1.0e-6", "{x: 1.0e-5, v: 1.0e-4}"))).stats.steps;
  EXPECT_LT(loose, tight);
  EXPECT_LT(tight, tighter);
}

TEST_F(ErrorControl, TheFastOscillatorLimitsTheStepUntilTheSlowOneIsHeldTighter) {
  const RunResult both = run(load_scene(two_oscillators("")));
  ASSERT_FALSE(both.stats.limiting_states.empty());
  EXPECT_EQ(both.stats.limiting_states[0].state.rfind("fast.", 0), 0u) << both.stats.limiting_states[0].state;
  EXPECT_GT(share_of(both.stats, "fast"), 0.9);
  double total = 0.0;
  long steps = 0;
  for (const LimitingState& l : both.stats.limiting_states) total += l.share, steps += l.steps;
  EXPECT_LE(total, 1.0 + 1e-12);
  EXPECT_LE(steps, both.stats.steps);

  // Held to a tolerance 1e5 times tighter (more than 729), the slow oscillator's error is the
  // one the step is chosen for, and the steps are more.
  const RunResult strict = run(load_scene(two_oscillators("{x: 1.0e-5, v: 1.0e-5}")));
  EXPECT_GT(strict.stats.steps, both.stats.steps);
  EXPECT_EQ(strict.stats.limiting_states[0].state.rfind("slow.", 0), 0u) << strict.stats.limiting_states[0].state;
  EXPECT_GT(share_of(strict.stats, "slow"), 0.9);

  // run.json names them, block.state and share.
  const std::string json = io::run_json(load_scene(two_oscillators("")), both);
  EXPECT_NE(json.find("\"limiting_states\""), std::string::npos);
  EXPECT_NE(json.find("\"state\": \"" + both.stats.limiting_states[0].state + "\""), std::string::npos);
}

TEST_F(ErrorControl, AnObjectiveIntegralThatLimitsTheStepIsNamed) {
  // The slow oscillator beside the rms of a 4 Hz sine: the integral of sin^2 varies at 8 Hz, so
  // at equal absolute tolerances its local error is the largest, and it is named as
  // `block.integral` among the limiting states.
  const std::string path = write("integral.yaml",
                                 "scene: integral\n"
                                 "time: {stop: 2.0, output_step: 0.05}\n"
                                 "solver: {method: bdf, rtol: 1.0e-13, atol: 1.0e-6}\n"
                                 "blocks:\n"
                                 "  zero: {type: source.constant, value: 0.0}\n"
                                 "  slow: {type: mass_spring_damper, m: 1.0, k: 1.0, x0: 1.0}\n"
                                 "  wave: {type: source.sine, amplitude: 1.0, frequency: 4.0}\n"
                                 "  wave_rms: {type: objective.rms, window: [0.0, 2.0]}\n"
                                 "connections:\n"
                                 "  - zero.y -> slow.f\n"
                                 "  - wave.y -> wave_rms.in\n"
                                 "outputs: [slow.x, wave_rms]\n");
  const Diagram d = load_scene(path);
  const RunResult r = run(d);
  ASSERT_FALSE(r.stats.limiting_states.empty());
  EXPECT_EQ(r.stats.limiting_states[0].state.rfind("wave_rms.integral", 0), 0u) << r.stats.limiting_states[0].state;
  EXPECT_GT(r.stats.limiting_states[0].share, 0.5);
  EXPECT_EQ(state_label(d, d.num_states), r.stats.limiting_states[0].state);
}

TEST_F(ErrorControl, ALargerNewtonCoefficientReachesCvodesAndStopsTheIterationSooner) {
  // The quarter car with its CDC damper: a looser Newton test (0.5 against CVODES' 0.1) takes
  // fewer corrector iterations per step and fails fewer times; run.json records the setting.
  const std::string scenes = std::string(DYDP_SOURCE_DIR) + "/scenarios/";
  Diagram strict = load_scene(scenes + "quarter_car_cdc.yaml");
  Diagram loose = load_scene(scenes + "quarter_car_cdc.yaml");
  strict.time.stop = loose.time.stop = 3.0;
  EXPECT_EQ(strict.solver.newton_coefficient, 0.1);
  loose.solver.newton_coefficient = 0.5;
  RunOptions options;
  options.sensitivities = false;
  const RunResult a = run(strict, options), b = run(loose, options);
  EXPECT_LT(static_cast<double>(b.stats.nonlinear_iterations) / b.stats.steps,
            static_cast<double>(a.stats.nonlinear_iterations) / a.stats.steps);
  EXPECT_LE(b.stats.nonlinear_failures, a.stats.nonlinear_failures);
  EXPECT_NE(io::run_json(loose, b).find("\"newton_coefficient\": 0.5"), std::string::npos);
}

TEST_F(ErrorControl, AMaximumOrderReachesCvodesAndStepsAreCountedByOrder) {
  // The quarter car with its CDC damper: unbounded, BDF climbs past order 2 for most steps;
  // with solver.max_order 2 no step is taken above it. The counts by order add up to the steps.
  const std::string scenes = std::string(DYDP_SOURCE_DIR) + "/scenarios/";
  Diagram free = load_scene(scenes + "quarter_car_cdc.yaml");
  Diagram capped = load_scene(scenes + "quarter_car_cdc.yaml");
  free.time.stop = capped.time.stop = 1.0;
  capped.solver.max_order = 2;
  RunOptions options;
  options.sensitivities = false;
  const RunResult a = run(free, options), b = run(capped, options);
  const auto total = [](const std::vector<long>& v) { return std::accumulate(v.begin(), v.end(), 0L); };
  EXPECT_EQ(a.stats.max_order, 5);
  EXPECT_EQ(total(a.stats.steps_per_order), a.stats.steps);
  ASSERT_GT(a.stats.steps_per_order.size(), 2u);
  EXPECT_GT(total(a.stats.steps_per_order) - a.stats.steps_per_order[0] - a.stats.steps_per_order[1],
            a.stats.steps / 2);
  EXPECT_EQ(b.stats.max_order, 2);
  EXPECT_LE(b.stats.steps_per_order.size(), 2u);
  EXPECT_EQ(total(b.stats.steps_per_order), b.stats.steps);
  EXPECT_GT(b.stats.steps, a.stats.steps);  // second order needs more steps at the same tolerances
  EXPECT_NE(io::run_json(capped, b).find("\"max_order\": 2"), std::string::npos);
}

TEST_F(ErrorControl, RefreshingTheDampersBlocksCutsNewtonFailuresAndKeepsTheSolution) {
  // The quarter car with its CDC damper, with the sensitivity: the damper's own Jacobian block
  // refreshed at each set-up of the Newton matrix (the default) against CVODES' kept Jacobian.
  // Far fewer failed Newton iterations, so far fewer whole Jacobians; the same solution to the
  // accuracy the tolerances ask for.
  const std::string scenes = std::string(DYDP_SOURCE_DIR) + "/scenarios/";
  Diagram refreshed = load_scene(scenes + "quarter_car_cdc.yaml");
  Diagram kept = load_scene(scenes + "quarter_car_cdc.yaml");
  refreshed.time.stop = kept.time.stop = 3.0;
  EXPECT_TRUE(refreshed.solver.refresh_local_jacobians);
  kept.solver.refresh_local_jacobians = false;
  const RunResult a = run(refreshed, RunOptions{}), b = run(kept, RunOptions{});
  EXPECT_GT(a.stats.local_jac_evals, 0);
  EXPECT_EQ(b.stats.local_jac_evals, 0);
  EXPECT_LT(2 * a.stats.nonlinear_failures, b.stats.nonlinear_failures);
  EXPECT_LT(a.stats.jac_evals, b.stats.jac_evals);
  ASSERT_EQ(a.objectives.size(), b.objectives.size());
  ASSERT_FALSE(a.objectives.empty());
  for (size_t k = 0; k < a.objectives.size(); ++k) {
    const ObjectiveResult &x = a.objectives[k], &y = b.objectives[k];
    EXPECT_NEAR(x.value, y.value, 1e-5 * std::fabs(y.value)) << x.name;
    ASSERT_EQ(x.sensitivity.size(), y.sensitivity.size());
    for (size_t d = 0; d < x.sensitivity.size(); ++d)
      EXPECT_NEAR(x.sensitivity[d], y.sensitivity[d], 1e-4 * std::fabs(y.sensitivity[d])) << x.name << " " << d;
  }
  EXPECT_NE(io::run_json(kept, b).find("\"refresh_local_jacobians\": false"), std::string::npos);
}

TEST_F(ErrorControl, BadNominalsAreRefusedWithFileLineAndField) {
  auto expect_refused = [&](const std::string& nominal, const std::string& field, const std::string& phrase) {
    const std::string path = write("bad.yaml",
                                   "scene: bad\n"
                                   "time: {stop: 1.0, output_step: 0.1}\n"
                                   "blocks:\n"
                                   "  zero: {type: source.constant, value: 0.0}\n"
                                   "  m:\n"
                                   "    type: mass_spring_damper\n"
                                   "    nominal: " + nominal + "\n"
                                   "connections:\n"
                                   "  - zero.y -> m.f\n"
                                   "outputs: [m.x]\n");
    try {
      load_scene(path);
      ADD_FAILURE() << nominal << " was accepted";
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), path);
      EXPECT_EQ(e.line(), 7) << e.what();
      EXPECT_EQ(e.field(), field) << e.what();
      EXPECT_NE(std::string(e.what()).find(phrase), std::string::npos) << e.what();
    }
  };
  expect_refused("{y: 1.0}", "m.nominal.y", "no state of that name (states: x v)");
  expect_refused("{x: 0.0}", "m.nominal.x", "must be positive");
  expect_refused("{x: -1.0}", "m.nominal.x", "must be positive");
  expect_refused("{x: .inf}", "m.nominal.x", "expected a number");
  expect_refused("{x: big}", "m.nominal.x", "expected a number");
  expect_refused("1.0", "m.nominal", "expected a mapping");
}

TEST_F(ErrorControl, ABlockWithoutStatesHasNoNominalsToSet) {
  const std::string path = write("stateless.yaml",
                                 "scene: s\n"
                                 "time: {stop: 1.0, output_step: 0.1}\n"
                                 "blocks:\n"
                                 "  zero: {type: source.constant, value: 0.0, nominal: {x: 1.0}}\n"
                                 "  m: {type: mass_spring_damper}\n"
                                 "connections:\n"
                                 "  - zero.y -> m.f\n"
                                 "outputs: [m.x]\n");
  try {
    load_scene(path);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 4);
    EXPECT_EQ(e.field(), "zero.nominal.x");
    EXPECT_NE(std::string(e.what()).find("has no states"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace dydp::engine
