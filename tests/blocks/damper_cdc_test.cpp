// damper.cdc: exact tangents (against central differences), the quasi-steady force at constant
// stroke rate (against an independent solution of the flow balance), the 1-4 kN band at
// 0.5 m/s with monotone softening in current, the pressure build-up time constant V / (B dQ/dp),
// the stiff case (bulk modulus x100) under BDF, and the sensitivity of a quarter-car rms
// objective to the valve current against central differences of whole runs.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include "tests/blocks/scene_helpers.hpp"
#include "tests/blocks/tangent_check.hpp"

namespace dydp::test {
namespace {

// ---- The damper's laws as docs/blocks.md states them, written independently of the block ----

struct Damper {
  double current = 0.8;
  double section_hard = 0.5e-6, section_soft = 8e-6, port = 3.0e-6;
  double piston_diameter = 0.032, rod_diameter = 0.020, density = 870, cd = 0.7, pt = 1e5;
  double piston_rebound = 2.0e-6, piston_check = 20e-6, base_compression = 1.3e-6, base_intake = 20e-6;
  double atmosphere = 1.01325e5, friction = 30, friction_velocity = 0.01;

  double a_piston() const { return std::numbers::pi / 4 * piston_diameter * piston_diameter; }
  double a_rod() const { return std::numbers::pi / 4 * rod_diameter * rod_diameter; }
  double a_annulus() const { return a_piston() - a_rod(); }
  double coefficient(double section) const { return cd * section * std::sqrt(2 / density); }
  double valve_section() const {
    return section_hard * std::pow(section_soft / section_hard, (current - 0.3) / 1.3);
  }
  double g(double z) const { return z / std::pow(z * z + pt * pt, 0.25); }
  /// Directional orifice: coefficient kf for dp > 0, kr for dp < 0.
  double flow(double dp, double kf, double kr) const {
    const double w = pt / 10, root = std::hypot(dp, w);
    return kf * (g((dp + root) / 2) - g(w / 2)) - kr * (g((root - dp) / 2) - g(w / 2));
  }
  double loss(double q, double k) const { return q * std::sqrt(q * q + k * k * pt) / (k * k); }

  /// Quasi-steady pressures at stroke rate v and reservoir pressure p_res: the chamber balances
  /// and the pipe's momentum balance with zero time derivatives, solved by Newton.
  std::array<double, 3> steady(double v, double p_res) const {
    const double kv = coefficient(valve_section()), kp = coefficient(port);
    const double kpr = coefficient(piston_rebound), kpc = coefficient(piston_check);
    const double kbc = coefficient(base_compression), kbi = coefficient(base_intake);
    const auto residual = [&](const std::array<double, 3>& z) {
      const double q_piston = flow(z[0] - z[1], kpr, kpc), q_base = flow(z[1] - p_res, kbc, kbi);
      return std::array<double, 3>{(a_annulus() * v - q_piston - z[2]) * 1e4,
                                   (q_piston - q_base - a_piston() * v) * 1e4,
                                   (z[0] - p_res - loss(z[2], kv) - loss(z[2], kp)) * 1e-6};
    };
    std::array<double, 3> z{p_res + (v > 0 ? 3e6 : 1e6), p_res + (v > 0 ? 0.0 : 1e6),
                            v > 0 ? a_annulus() * v / 2 : -a_rod() * v};
    for (int it = 0; it < 200; ++it) {
      const auto r = residual(z);
      double jac[3][4];
      for (int j = 0; j < 3; ++j) {
        auto zz = z;
        const double h = j < 2 ? 10.0 : 1e-9;
        zz[j] += h;
        const auto rp = residual(zz);
        zz[j] -= 2 * h;
        const auto rm = residual(zz);
        for (int i = 0; i < 3; ++i) jac[i][j] = (rp[i] - rm[i]) / (2 * h);
      }
      for (int i = 0; i < 3; ++i) jac[i][3] = -r[i];
      for (int c = 0; c < 3; ++c) {  // Gaussian elimination with partial pivoting
        int piv = c;
        for (int i = c + 1; i < 3; ++i) if (std::fabs(jac[i][c]) > std::fabs(jac[piv][c])) piv = i;
        for (int k = 0; k < 4; ++k) std::swap(jac[c][k], jac[piv][k]);
        for (int i = c + 1; i < 3; ++i) {
          const double f = jac[i][c] / jac[c][c];
          for (int k = c; k < 4; ++k) jac[i][k] -= f * jac[c][k];
        }
      }
      std::array<double, 3> dz{};
      for (int i = 2; i >= 0; --i) {
        double acc = jac[i][3];
        for (int k = i + 1; k < 3; ++k) acc -= jac[i][k] * dz[k];
        dz[i] = acc / jac[i][i];
      }
      // Damped step: at most halve the pressure guesses' distance to the reservoir each time.
      double lambda = 1;
      while (lambda > 1e-3 && z[0] + lambda * dz[0] < 0) lambda /= 2;
      for (int i = 0; i < 3; ++i) z[i] += lambda * dz[i];
    }
    return z;
  }
  double force(double v, double p_res) const {
    const auto z = steady(v, p_res);
    return z[0] * a_annulus() - z[1] * a_piston() + atmosphere * a_rod() +
           friction * std::tanh(v / friction_velocity);
  }
};

// ---- Tangents ----

BlockCase damper_case(double current) {
  BlockCase c;
  c.type = "damper.cdc";
  c.params = {{"current", current}};
  c.states = {{3e6, 2e6}, {1e6, 8e5}, {5e5, 1e5}, {5e-5, 1.5e-4}};
  c.inputs = {{{0.0, 0.03}}, {{0.0, 0.6}}};
  return c;
}

TEST(DamperCdc, TangentsMatchFiniteDifferences) {
  check_tangents(damper_case(0.3));
  check_tangents(damper_case(1.1));
}

TEST(DamperCdc, TangentsMatchNearZeroPressureDrop) {
  BlockCase c = damper_case(0.8);
  c.states = {{5e5, 3e4}, {5e5, 3e4}, {5e5, 3e4}, {0.0, 1e-6}};
  c.inputs = {{{0.0, 0.001}}, {{0.0, 0.005}}};
  check_tangents(c);
}

// ---- Quasi-steady force ----

std::string constant_rate_scene(double rate, double current, double stop, double bulk_factor = 1.0) {
  return R"(scene: damper_constant_rate
time: {start: 0.0, stop: )" + std::to_string(stop) + R"(, output_step: 0.001}
solver: {method: bdf, rtol: 1.0e-9, atol: 1.0e-9}
parameters:
  current: {value: )" + std::to_string(current) + R"(, unit: A}
blocks:
  rate: {type: source.constant, value: )" + std::to_string(rate) + R"(}
  stroke: {type: source.ramp, start: 0.0, slope: )" + std::to_string(rate) + R"(}
  damper: {type: damper.cdc, current: $current, bulk_modulus: )" + std::to_string(1.5e9 * bulk_factor) + R"(}
connections:
  - stroke.y -> damper.stroke
  - rate.y -> damper.stroke_rate
outputs: [damper.force, damper.p_reservoir, damper.p_rebound, damper.p_compression]
)";
}

TEST(DamperCdc, ForceAtConstantRateMatchesQuasiSteadyBalance) {
  // 50 ms: the slowest transient (hard valve, compression: both chambers against the small
  // outflow conductance, about 5 ms) has died out; the stroke stays within 25 mm.
  for (double rate : {0.5, -0.5, 0.1}) {
    for (double current : {0.3, 1.6}) {
      const auto r = run_scene(write_scene("constant_rate.yaml", constant_rate_scene(rate, current, 0.05)), {}, false);
      Damper model;
      model.current = current;
      const double p_res = signal(r, "damper.p_reservoir").back();
      const double expected = model.force(rate, p_res);
      const double simulated = signal(r, "damper.force").back();
      EXPECT_NEAR(simulated, expected, 1e-3 * std::fabs(expected))
          << "rate " << rate << " m/s, current " << current << " A";
    }
  }
}

TEST(DamperCdc, ReboundForceAtHalfMetrePerSecondIsInBandAndSoftensWithCurrent) {
  Damper model;
  double previous = 1e300;
  for (double current : {0.3, 0.5, 0.7, 0.9, 1.1, 1.3, 1.6}) {
    model.current = current;
    const double f = model.force(0.5, 5e5);
    const double fc = model.force(-0.5, 5e5);
    std::printf("current %.1f A: force at +0.5 m/s %.0f N, at -0.5 m/s %.0f N\n", current, f, fc);
    EXPECT_GT(f, 1000.0) << current;
    EXPECT_LT(f, 4000.0) << current;
    EXPECT_LT(f, previous) << "not softer at " << current << " A";
    EXPECT_LT(fc, 0.0);
    previous = f;
  }
  // The simulated block agrees at both ends of the band.
  for (double current : {0.3, 1.6}) {
    const auto r = run_scene(write_scene("band.yaml", constant_rate_scene(0.5, current, 0.01)), {}, false);
    const double f = signal(r, "damper.force").back();
    EXPECT_GT(f, 1000.0);
    EXPECT_LT(f, 4000.0);
  }
}

// ---- Pressure build-up time constant ----

TEST(DamperCdc, PressureBuildUpTimeConstantMatchesLinearisation) {
  // The rebound chamber alone sets the time scale: the base valve is made wide (the compression
  // chamber follows the reservoir), the external valve nearly closed, the piston valve symmetric,
  // and the stroke rate small enough to stay laminar. Then tau = V_reb / (B dQ/dp).
  const double rate = 1e-3, bulk = 1.5e9, volume = 40e-6, section = 2e-6;
  const std::string scene = R"(scene: damper_build_up
time: {start: 0.0, stop: 0.001, output_step: 2.0e-6}
solver: {method: bdf, rtol: 1.0e-10, atol: 1.0e-8}
blocks:
  rate: {type: source.constant, value: 0.001}
  stroke: {type: source.ramp, start: 0.0, slope: 0.001}
  damper: {type: damper.cdc, bulk_modulus: 1.5e9, rebound_volume: 40.0e-6, piston_rebound_section: 2.0e-6,
           piston_check_section: 2.0e-6, base_compression_section: 400.0e-6, base_intake_section: 400.0e-6,
           valve_section_hard: 1.0e-9, valve_section_soft: 1.0e-9, valve_port_section: 1.0e-9}
connections:
  - stroke.y -> damper.stroke
  - rate.y -> damper.stroke_rate
outputs: [damper.p_rebound, damper.p_compression]
)";
  const auto r = run_scene(write_scene("build_up.yaml", scene), {}, false);
  const auto p_reb = signal(r, "damper.p_rebound"), p_comp = signal(r, "damper.p_compression");
  std::vector<double> drop;
  for (size_t k = 0; k < p_reb.size(); ++k) drop.push_back(p_reb[k] - p_comp[k]);

  Damper model;
  model.piston_rebound = model.piston_check = section;
  const double k = model.coefficient(section);
  const double h = 1.0;  // [Pa] central difference of the flow law at zero pressure drop
  const double conductance = (model.flow(h, k, k) - model.flow(-h, k, k)) / (2 * h);
  const double tau = volume / (bulk * conductance);
  const double final_drop = model.a_annulus() * rate / conductance;
  EXPECT_NEAR(drop.back(), final_drop, 0.01 * final_drop);
  EXPECT_LT(final_drop, 0.05 * model.pt) << "the test must stay laminar";

  // The time at which the drop reaches 1 - 1/e of its final value.
  const double target = (1 - std::exp(-1.0)) * drop.back();
  double t63 = -1;
  for (size_t i = 1; i < drop.size(); ++i)
    if (drop[i - 1] < target && drop[i] >= target) {
      t63 = r.t[i - 1] + (target - drop[i - 1]) / (drop[i] - drop[i - 1]) * (r.t[i] - r.t[i - 1]);
      break;
    }
  std::printf("build-up: tau from linearisation %.4g s, simulated %.4g s\n", tau, t63);
  EXPECT_NEAR(t63, tau, 0.02 * tau);
  EXPECT_LT(tau, 1e-3) << "oil compressibility gives sub-millisecond time constants";
}

// ---- Stiff case ----

std::string sine_stroke_scene(double bulk) {
  return R"(scene: damper_stiff
time: {start: 0.0, stop: 0.5, output_step: 0.001}
solver: {method: bdf, rtol: 1.0e-6, atol: 1.0e-6}
blocks:
  stroke: {type: source.sine, amplitude: 0.02, frequency: 2.0}
  rate: {type: source.sine, amplitude: 0.25132741228718347, frequency: 2.0, phase: 1.5707963267948966}
  damper: {type: damper.cdc, bulk_modulus: )" + std::to_string(bulk) + R"(}
  force_rms: {type: objective.rms, window: [0.25, 0.5]}
connections:
  - stroke.y -> damper.stroke
  - rate.y -> damper.stroke_rate
  - damper.force -> force_rms.in
outputs: [damper.force, force_rms]
)";
}

TEST(DamperCdc, StiffOilRunsWithBdfAndGivesNearlyTheSameForce) {
  const auto nominal = run_scene(write_scene("stiff1.yaml", sine_stroke_scene(1.5e9)), {}, false);
  const auto stiff = run_scene(write_scene("stiff100.yaml", sine_stroke_scene(1.5e11)), {}, false);
  const double f1 = objective(nominal, "force_rms").value, f100 = objective(stiff, "force_rms").value;
  EXPECT_GT(f1, 100.0);
  EXPECT_NEAR(f100, f1, 0.05 * f1);
}

// ---- Quarter car: sensitivity to the valve current ----

std::string quarter_car_scene() {
  return R"(scene: damper_quarter_car
time: {start: 0.0, stop: 2.0, output_step: 0.005}
solver: {method: bdf, rtol: 1.0e-10, atol: 1.0e-10}
parameters:
  current: {value: 0.8, unit: A}
sensitivities: [current]
blocks:
  road: {type: source.sine, amplitude: 0.01, frequency: 1.5}
  road_rate: {type: source.sine, amplitude: 0.0942477796076938, frequency: 1.5, phase: 1.5707963267948966}
  body: {type: mass_spring_damper, m: 400.0, k: 20000.0, c: 0.0}
  stroke: {type: math.sum, signs: "+-"}
  stroke_rate: {type: math.sum, signs: "+-"}
  damper: {type: damper.cdc, current: $current}
  on_body: {type: math.gain, k: -1.0}
  comfort: {type: objective.rms, window: [1.0, 2.0]}
  power: {type: objective.mean, window: [1.0, 2.0]}
connections:
  - body.x -> stroke.in1
  - road.y -> stroke.in2
  - body.v -> stroke_rate.in1
  - road_rate.y -> stroke_rate.in2
  - stroke.y -> damper.stroke
  - stroke_rate.y -> damper.stroke_rate
  - damper.force -> on_body.u
  - on_body.y -> body.f
  - body.a -> comfort.in
  - damper.power -> power.in
outputs: [body.x, comfort, power]
)";
}

TEST(DamperCdc, QuarterCarSensitivityToCurrentMatchesWholeRunDifferences) {
  const std::string path = write_scene("quarter_car.yaml", quarter_car_scene());
  const auto r = run_scene(path);
  for (const char* name : {"comfort", "power"}) {
    const double exact = objective(r, name).sensitivity.at(0);
    double best = 1e300, best_fd = 0;
    for (double h : {1e-2, 3e-3, 1e-3, 3e-4}) {
      const double plus = objective(run_scene(path, {{"current", std::to_string(0.8 + h)}}, false), name).value;
      const double minus = objective(run_scene(path, {{"current", std::to_string(0.8 - h)}}, false), name).value;
      const double fd = (plus - minus) / (2 * h);
      if (std::fabs(fd - exact) < best) best = std::fabs(fd - exact), best_fd = fd;
    }
    std::printf("%s: value %.6g, d/d(current) %.6g, central difference %.6g\n", name,
                objective(r, name).value, exact, best_fd);
    EXPECT_LT(best, 1e-4 * std::fabs(exact)) << name;
    EXPECT_GT(objective(r, name).value, 0.0);
  }
}

}  // namespace
}  // namespace dydp::test
