// A scene that starts at its static equilibrium (`initial: equilibrium`, docs/scenes.md) on the
// linear quarter car (the generated model's spring and damper, a linear tyre): its run starts
// where every state derivative vanishes and stays there under constant inputs, the start is the
// closed form's (the tyre carries both masses), the initial sensitivities are dx*/dp (the
// closed form's d(tyre force)/d(ms) = g), and the sensitivities at later times of a run driven
// by a road sine are those of whole runs each started from its own equilibrium (central
// differences, a step study); the sedan on a still 4-poster stays still from its equilibrium.
// Bad `initial:` values are refused at their line.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "engine/analysis/run.hpp"
#include "engine/analysis/tolerances.hpp"
#include "engine/evaluation/evaluator.hpp"
#include "engine/framework/errors.hpp"
#include "engine/studies/initial_equilibrium.hpp"
#include "engine/studies/sweep.hpp"
#include "tests/engine/scene_error_test.hpp"

namespace dydp::engine {
namespace {

constexpr double kG = 9.81;
constexpr double kMs = 350.0, kMu = 40.0, kKs = 20000.0, kKt = 250000.0;

/// The quarter car of tests/engine/linear/quarter_car_modes_test.cpp started from its
/// equilibrium; `road` the blocks rz and rzd (the road's height and rate), `initial` the section.
std::string quarter_car(const std::string& name, const std::string& road, const std::string& initial,
                        double stop = 1.0) {
  const std::string path = (std::filesystem::temp_directory_path() / ("dydp_initial_" + name + ".yaml")).string();
  std::ofstream(path) << "scene: " << name << R"(
time: {start: 0.0, stop: )" << stop << R"(, output_step: 0.01}
solver: {method: bdf, rtol: 1.0e-10, atol: 1.0e-12}
)" << initial << R"(
parameters:
  ks: {value: 20000.0, unit: N/m}
  cs: {value: 1500.0, unit: N s/m}
  kt: {value: 250000.0, unit: N/m}
  ms: {value: 350.0, unit: kg}
sensitivities: [ks, kt, ms]
blocks:
)" << road << R"(
  car: {type: multibody.quarter_car, spring: $ks, damper: $cs, sprung_mass: $ms, q0.z_body: 0.59, q0.z_wheel: 0.01}
  wheel_z: {type: math.demux, width: 3, indices: [2]}
  wheel_zdot: {type: math.demux, width: 3, indices: [2]}
  tyre: {type: tyre.vertical, stiffness: $kt, damping: 150.0, contact_width: 1.0e-6, force_width: 1.0e-6}
  zero: {type: source.constant, value: 0.0}
  tyre_force: {type: math.mux, inputs: 3}
  no_strut: {type: math.mux, inputs: 3}
  body_az: {type: math.demux, width: 3, indices: [2]}
connections:
  - rz.y -> tyre.road_z
  - rzd.y -> tyre.road_zdot
  - car.wheel_position -> wheel_z.u
  - car.wheel_velocity -> wheel_zdot.u
  - wheel_z.y -> tyre.wheel_z
  - wheel_zdot.y -> tyre.wheel_zdot
  - zero.y -> tyre_force.in1
  - zero.y -> tyre_force.in2
  - tyre.force -> tyre_force.in3
  - tyre_force.y -> car.tyre
  - zero.y -> no_strut.in1
  - zero.y -> no_strut.in2
  - zero.y -> no_strut.in3
  - no_strut.y -> car.strut_top
  - no_strut.y -> car.strut_seat
  - car.body_acc -> body_az.u
outputs: [body_az.y, tyre.force, car.wheel_position, car.travel]
)";
  return path;
}

const std::string kStillRoad = R"(  rz: {type: source.constant, value: 0.0}
  rzd: {type: source.constant, value: 0.0})";
// 10 mm at 2 Hz from t = 0: the road's rate is 2 pi 2 0.01 m/s there, held at 0 for the equilibrium.
const std::string kSineRoad = R"(  rz: {type: source.sine, amplitude: 0.01, frequency: 2.0}
  rzd: {type: source.sine, amplitude: 0.12566370614359174, frequency: 2.0, phase: 1.5707963267948966})";

/// The largest |signal(t) - signal(t0)| over the run, per signal.
std::vector<double> largest_change(const RunResult& r) {
  std::vector<double> out(r.num_signals(), 0.0);
  for (size_t k = 0; k < r.t.size(); ++k)
    for (int i = 0; i < r.num_signals(); ++i)
      out[i] = std::max(out[i], std::fabs(r.value(static_cast<int>(k), i) - r.value(0, i)));
  return out;
}

TEST(InitialEquilibrium, StartsWhereTheStateDerivativesVanishAndStaysThere) {
  Diagram d = load_scene(quarter_car("still", kStillRoad, "initial: equilibrium"));
  ASSERT_TRUE(d.initial.equilibrium);
  // A run without its start computed is refused rather than started from the declared state.
  EXPECT_THROW(run(d), std::logic_error);
  const RunResult r = run_from_initial(d);
  ASSERT_TRUE(d.start_is_current());
  // |xdot| / nominal at the start: what Newton left.
  Evaluator e(d, false);
  std::vector<double> xdot(d.num_states);
  e.derivatives(d.time.start, d.start.x.data(), xdot.data());
  const std::vector<double> nominal = state_nominals(d);
  for (int i = 0; i < d.num_states; ++i) EXPECT_LT(std::fabs(xdot[i]) / nominal[i], 1e-9) << state_label(d, i);
  // The closed form's equilibrium: the tyre carries both masses; the wheel sits (ms + mu) g / kt
  // below its free radius 0.32 m.
  const int force = r.signal_index("tyre.force"), wheel = r.signal_index("car.wheel_position[2]");
  EXPECT_NEAR(r.value(0, force), (kMs + kMu) * kG, 1e-9 * (kMs + kMu) * kG);
  EXPECT_NEAR(r.value(0, wheel), 0.32 - (kMs + kMu) * kG / kKt, 1e-12);
  // Still over the whole second: body acceleration below 1e-7 m/s^2, heights within 1e-11 m,
  // the tyre force within 1e-6 N.
  const std::vector<double> moved = largest_change(r);
  EXPECT_LT(moved[r.signal_index("body_az.y")], 1e-7);
  EXPECT_LT(moved[wheel], 1e-11);
  EXPECT_LT(moved[force], 1e-6);
  EXPECT_LT(std::fabs(r.value(0, r.signal_index("body_az.y"))), 1e-7);

  // The same scene from its declared state does move (0.59 m and 0.01 m are not the equilibrium):
  // the stillness above is the start's doing.
  Diagram declared = load_scene(quarter_car("still_declared", kStillRoad, "initial: declared"));
  EXPECT_FALSE(declared.initial.equilibrium);
  const RunResult free_run = run_from_initial(declared);
  EXPECT_TRUE(declared.start.x.empty());
  EXPECT_GT(largest_change(free_run)[force], 10.0);
}

TEST(InitialEquilibrium, InitialSensitivitiesAreTheEquilibriumsDerivatives) {
  Diagram d = load_scene(quarter_car("still_sens", kStillRoad, "initial: equilibrium"));
  const RunResult r = run_from_initial(d);
  ASSERT_EQ(r.sensitivity_names, (std::vector<std::string>{"ks", "kt", "ms"}));
  const int force = r.signal_index("tyre.force"), wheel = r.signal_index("car.wheel_position[2]");
  const int last = static_cast<int>(r.t.size()) - 1;
  for (int k : {0, last}) {
    // The tyre force (ms + mu) g: d/d(ms) = g, d/d(ks) = d/d(kt) = 0.
    EXPECT_NEAR(r.tangent(k, 2, force), kG, 1e-9 * kG) << "t = " << r.t[k];
    EXPECT_NEAR(r.tangent(k, 0, force), 0.0, 1e-9 * kG / kKs * kMs) << "t = " << r.t[k];
    // The wheel's height 0.32 - (ms + mu) g / kt: d/d(kt) = (ms + mu) g / kt^2, d/d(ms) = -g / kt.
    const double dkt = (kMs + kMu) * kG / (kKt * kKt);
    EXPECT_NEAR(r.tangent(k, 1, wheel), dkt, 1e-9 * dkt) << "t = " << r.t[k];
    EXPECT_NEAR(r.tangent(k, 2, wheel), -kG / kKt, 1e-9 * kG / kKt) << "t = " << r.t[k];
  }
}

/// `text` with `from` replaced by `to` (once; a failure when `from` is not there).
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

TEST(InitialEquilibrium, SedanOnAStillRigStaysStill) {
  // scenarios/fourposter_comfort.yaml with the pads still (no sine, no noise), 1 s, from its
  // equilibrium: the dampers' oil (conserved: a family of equilibria) kept where the settling
  // motion leaves it, every state derivative zero there.
  const std::string source = std::string(DYDP_SOURCE_DIR) + "/scenarios/fourposter_comfort.yaml";
  std::ifstream in(source);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text = replaced(text, "time: {start: 0.0, stop: 20.0, output_step: 0.01}",
                  "time: {start: 0.0, stop: 1.0, output_step: 0.01}\ninitial: equilibrium");
  text = replaced(text, "amplitude_fl: 0.01, amplitude_fr: 0.01, amplitude_rl: 0.01, amplitude_rr: 0.01",
                  "amplitude_fl: 0.0, amplitude_fr: 0.0, amplitude_rl: 0.0, amplitude_rr: 0.0");
  text = replaced(text, "noise_rms: 0.0005", "noise_rms: 0.0");
  text = replaced(text, "{file: subsystems/corner_rig.yaml}",
                  "{file: " + std::string(DYDP_SOURCE_DIR) + "/scenarios/subsystems/corner_rig.yaml}");
  for (int k = 0; k < 2; ++k) text = replaced(text, "window: [2.0, 20.0]", "window: [0.2, 1.0]");
  const std::string path = (std::filesystem::temp_directory_path() / "dydp_initial_sedan_still.yaml").string();
  std::ofstream(path) << text;
  Diagram d = load_scene(path);
  const auto eq = start_at_equilibrium(d);
  ASSERT_TRUE(eq.has_value());
  EXPECT_GT(eq->rank_deficiency, 0);  // the oil of the dampers, the free coordinates
  Evaluator e(d, false);
  std::vector<double> xdot(d.num_states);
  e.derivatives(d.time.start, d.start.x.data(), xdot.data());
  const std::vector<double> nominal = state_nominals(d);
  for (int i = 0; i < d.num_states; ++i) EXPECT_LT(std::fabs(xdot[i]) / nominal[i], 1e-9) << state_label(d, i);
  const RunResult r = run(d);
  const std::vector<double> moved = largest_change(r);
  std::printf("sedan, still rig, 1 s from its equilibrium: body acceleration moves %.3g m/s^2, roll %.3g rad, "
              "the front-left tyre force %.3g N, its rebound pressure %.3g Pa\n",
              moved[r.signal_index("car.body_acc_z")], moved[r.signal_index("car.roll")],
              moved[r.signal_index("corner_fl.tyre.force")], moved[r.signal_index("corner_fl.damper.p_rebound")]);
  EXPECT_LT(moved[r.signal_index("car.body_acc_z")], 1e-9);
  EXPECT_LT(std::fabs(r.value(0, r.signal_index("car.body_acc_z"))), 1e-9);
  EXPECT_LT(moved[r.signal_index("car.roll")], 1e-12);
  EXPECT_LT(moved[r.signal_index("corner_fl.tyre.force")], 1e-6);
  EXPECT_LT(moved[r.signal_index("corner_fl.damper.p_rebound")], 1e-3);
}

/// A signal's value at output k of a whole run with scene parameter `p` set to `value`, started
/// from its own equilibrium.
double run_value(const std::string& path, const std::string& p, double value, int k, const std::string& signal) {
  Diagram d = load_scene(path);
  d.set_parameter(d.find_parameter(p), value);
  RunOptions o;
  o.sensitivities = false;
  const RunResult r = run_from_initial(d, o);
  return r.value(k, r.signal_index(signal));
}

TEST(InitialEquilibrium, SensitivitiesAreCentralDifferencesOfRunsFromTheirOwnEquilibria) {
  // The road's rate is held at 0 for the equilibrium; the run then follows the sine.
  const std::string path =
      quarter_car("sine", kSineRoad, "initial: {state: equilibrium, hold: {rzd.y: 0.0}}", 0.6);
  Diagram d = load_scene(path);
  ASSERT_EQ(d.initial.held.size(), 1u);
  const RunResult r = run_from_initial(d);
  const double values[] = {kKs, kKt, kMs};
  const std::vector<std::string> signals = {"body_az.y", "tyre.force", "car.wheel_position[2]", "car.travel[0]"};
  for (int k : {30, 60}) {  // t = 0.3 s and 0.6 s
    for (int j = 0; j < 3; ++j) {
      for (const std::string& s : signals) {
        const double exact = r.tangent(k, j, r.signal_index(s));
        // Central differences at h, h/2, h/4 (relative 4e-2, 2e-2, 1e-2): the error of each
        // against the run's sensitivity falls by ~4 per halving (O(h^2)) down to the finest, so
        // the differences converge to the sensitivity (a wrong initial sensitivity would leave
        // a floor: ratios near 1).
        double error[3];
        for (int m = 0; m < 3; ++m) {
          const double h = 4e-2 * values[j] / (1 << m);
          const double fd = (run_value(path, r.sensitivity_names[j], values[j] + h, k, s) -
                             run_value(path, r.sensitivity_names[j], values[j] - h, k, s)) /
                            (2 * h);
          error[m] = std::fabs(fd - exact);
        }
        // The column's scale: its largest magnitude over the run (a derivative passing through
        // zero at t is held to the column's size, not to its value there).
        double scale = 0.0;
        for (size_t q = 0; q < r.t.size(); ++q)
          scale = std::max(scale, std::fabs(r.tangent(static_cast<int>(q), j, r.signal_index(s))));
        ASSERT_GT(scale, 0.0) << s << " d/d" << r.sensitivity_names[j];
        std::printf("t = %.2f  d(%s)/d(%s) = %.10g: |D - S| at h, h/2, h/4: %.3g %.3g %.3g (ratios %.2f %.2f)\n",
                    r.t[k], s.c_str(), r.sensitivity_names[j].c_str(), exact, error[0], error[1], error[2],
                    error[0] / error[1], error[1] / error[2]);
        EXPECT_LT(error[2], 1e-3 * scale) << s << " d/d" << r.sensitivity_names[j] << " t = " << r.t[k];
        for (int m = 0; m < 2; ++m) {
          EXPECT_GT(error[m] / error[m + 1], 3.0) << s << " d/d" << r.sensitivity_names[j] << " t = " << r.t[k];
          EXPECT_LT(error[m] / error[m + 1], 5.0) << s << " d/d" << r.sensitivity_names[j] << " t = " << r.t[k];
        }
      }
    }
  }
  // The same run with the start's derivative dropped (dx0/dp = 0, as from a declared state that
  // does not move with p) is far from the differences: the comparison above can fail.
  Diagram dropped = load_scene(path);
  start_at_equilibrium(dropped);
  std::fill(dropped.start.dx_dp.begin(), dropped.start.dx_dp.end(), 0.0);
  const RunResult wrong = run(dropped);
  const int force = wrong.signal_index("tyre.force");
  const double h = 1e-2 * kMs;
  const double fd = (run_value(path, "ms", kMs + h, 30, "tyre.force") - run_value(path, "ms", kMs - h, 30, "tyre.force")) / (2 * h);
  std::printf("t = 0.30  d(tyre.force)/d(ms): differences %.10g, the run %.10g, with dx0/dp dropped %.10g\n", fd,
              r.tangent(30, 2, force), wrong.tangent(30, 2, force));
  EXPECT_GT(std::fabs(wrong.tangent(30, 2, force) - fd), 0.1 * std::fabs(fd));
  EXPECT_LT(std::fabs(r.tangent(30, 2, force) - fd), 1e-4 * std::fabs(fd));
}

TEST(InitialEquilibrium, SweepPointsAndTheirDifferencesStartFromTheirOwnEquilibria) {
  // The sine-road quarter car with the rms of its body acceleration over [0.1, 0.6] s, swept
  // over ms: each point's d(psi)/d(ms) against the sweep's own central differences (each run
  // of them from its own equilibrium) at h = 4 and 2 kg.
  std::ifstream in(quarter_car("sweep", kSineRoad, "initial: {state: equilibrium, hold: {rzd.y: 0.0}}", 0.6));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text = replaced(text, "  body_az: {type: math.demux, width: 3, indices: [2]}",
                  "  body_az: {type: math.demux, width: 3, indices: [2]}\n  rms: {type: objective.rms, window: [0.1, 0.6]}");
  text = replaced(text, "  - car.body_acc -> body_az.u", "  - car.body_acc -> body_az.u\n  - body_az.y -> rms.in");
  text = replaced(text, "outputs: [body_az.y,", "outputs: [rms, body_az.y,");
  const std::string path = (std::filesystem::temp_directory_path() / "dydp_initial_sweep_rms.yaml").string();
  std::ofstream(path) << text;
  SweepSpec spec;
  spec.scene = path;
  spec.parameter = "ms";
  spec.low = 340.0;
  spec.high = 360.0;
  spec.points = 2;
  spec.fd_steps = {4.0, 2.0};
  spec.threads = 1;
  const SweepResult r = sweep(spec);
  ASSERT_EQ(r.points.size(), 2u);
  for (const SweepPoint& pt : r.points) {
    ASSERT_EQ(pt.dpsi.size(), 1u);
    const double e1 = std::fabs(pt.fd[0][0] - pt.dpsi[0]), e2 = std::fabs(pt.fd[1][0] - pt.dpsi[0]);
    std::printf("sweep ms = %g: psi %.10g, d(psi)/d(ms) %.10g, |D - S| at 4 and 2 kg: %.3g %.3g (ratio %.2f)\n", pt.p,
                pt.psi[0], pt.dpsi[0], e1, e2, e1 / e2);
    EXPECT_GT(e1 / e2, 3.0) << pt.p;
    EXPECT_LT(e1 / e2, 5.0) << pt.p;
    EXPECT_LT(e2, 1e-3 * std::fabs(pt.dpsi[0])) << pt.p;
  }
}

class InitialSectionErrors : public test::SceneErrorTest {
 protected:
  InitialSectionErrors() : SceneErrorTest("dydp_initial_errors_") {}
  std::string scene(const std::string& initial, const std::string& blocks = "  m: {type: mass_spring_damper, k: 4.0}\n  f: {type: source.constant, value: 1.0}\n") {
    return put("s.yaml", "scene: t\ntime: {stop: 1.0, output_step: 0.1}\n" + initial +
                             "\nblocks:\n" + blocks + "connections: [f.y -> m.f]\noutputs: [m.x]\n");
  }
};

TEST_F(InitialSectionErrors, UnknownStateIsRefusedAtItsLine) {
  const std::string path = scene("initial: equilibrum");
  expect_error(load_error(path), path, 3, "initial", "unknown value 'equilibrum' (equilibrium, declared)");
  const std::string mapped = scene("initial:\n  state: settled");
  expect_error(load_error(mapped), mapped, 4, "initial.state", "unknown value 'settled'");
}

TEST_F(InitialSectionErrors, UnknownKeyAndBadShapesAreRefused) {
  const std::string key = scene("initial: {from: equilibrium}");
  expect_error(load_error(key), key, 3, "initial.from", "unknown key");
  const std::string list = scene("initial: [equilibrium]");
  expect_error(load_error(list), list, 3, "initial", "expected equilibrium, declared or {state, hold}");
  const std::string hold = scene("initial:\n  state: equilibrium\n  hold: [f.y]");
  expect_error(load_error(hold), hold, 5, "initial.hold", "expected a mapping SIGNAL: VALUE");
}

TEST_F(InitialSectionErrors, HeldSignalMustBeAKeptOutputAndItsValueANumber) {
  const std::string value = scene("initial:\n  state: equilibrium\n  hold: {f.y: fast}");
  expect_error(load_error(value), value, 5, "initial.hold.f.y", "fast");
  const std::string port = scene("initial:\n  state: equilibrium\n  hold:\n    f.z: 0.0");
  expect_error(load_error(port), port, 6, "initial.hold.f.z", "block f has no output z (its outputs: y)");
  const std::string block = scene("initial:\n  state: equilibrium\n  hold:\n    g.y: 0.0");
  expect_error(load_error(block), block, 6, "initial.hold.g.y", "no block g in the scene");
  const std::string element = scene("initial:\n  state: equilibrium\n  hold:\n    f.y[1]: 0.0");
  expect_error(load_error(element), element, 6, "initial.hold.f.y[1]", "port f.y has 1 element(s)");
}

TEST_F(InitialSectionErrors, SceneWithNoEquilibriumInReachIsRefusedAtInitial) {
  // A constant force on a mass with no spring: it accelerates for ever.
  const std::string path =
      scene("initial: equilibrium", "  m: {type: mass_spring_damper, k: 0.0, c: 0.0}\n  f: {type: source.constant, value: 1.0}\n");
  Diagram d = load_scene(path);
  try {
    start_at_equilibrium(d);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    expect_error(e, path, 3, "initial", "no equilibrium in reach");
  }
  EXPECT_TRUE(d.start.x.empty());
}

TEST_F(InitialSectionErrors, ChangedParametersMakeTheStartStale) {
  const std::string path = scene("initial: equilibrium", "  m: {type: mass_spring_damper, k: 4.0, c: 1.0}\n  f: {type: source.constant, value: 2.0}\n");
  Diagram d = load_scene(path);
  ASSERT_TRUE(start_at_equilibrium(d).has_value());
  EXPECT_NEAR(d.start.x[0], 0.5, 1e-12);  // x* = f / k
  EXPECT_FALSE(start_at_equilibrium(d).has_value());  // current: not computed again
  d.nodes[0].p[1] = 8.0;  // k through the back door: the start no longer fits
  EXPECT_FALSE(d.start_is_current());
  EXPECT_THROW(run(d), std::logic_error);
  ASSERT_TRUE(start_at_equilibrium(d).has_value());
  EXPECT_NEAR(d.start.x[0], 0.25, 1e-12);
}

}  // namespace
}  // namespace dydp::engine
