// The sedan (generated_models/sedan.mbs.yaml) beyond the oracle comparisons every model gets in
// generated_test.cpp: assembly from a disturbed configuration, free fall with g, the static
// equilibrium of the design position (spring preloads and wheel loads, checked against the
// total weight), motion ratios (generated tangent against central differences of the oracle),
// and ride and wheel-hop frequencies of the linearised car on linear springs and tyres against
// hand values per corner; the multibody.sedan
// block at rest in a scene with the spring, damper and tyre blocks.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include "engine/analysis/run.hpp"
#include "engine/framework/diagram.hpp"
#include "generated_models/registry.hpp"
#include "oracle_compare.hpp"
#include "symbolic/mbs/numeric_dynamics.hpp"
#include "symbolic/mbs/reduced_dynamics.hpp"

namespace dydp::mbs {
namespace {

using namespace dydp::mbs::testing;

// Spring rates the docs recommend (see docs/models.md, sedan): front chosen for ~1.2 Hz.
constexpr double kFrontSpring = 80000.0;   // [N/m]
constexpr double kRearSpring = 167000.0;   // [N/m] the reference's value
constexpr double kTyre = 250000.0;         // [N/m]
const char* const kCorners[] = {"fl", "fr", "rl", "rr"};

struct Sedan {
  const GeneratedModel& g = *generated::find_model("sedan");
  Model model = load_model(std::string(DYDP_MODELS_DIR) + "/sedan.mbs.yaml");
  ReducedDynamics reduced{g};
  Vector q0 = Eigen::Map<const Vector>(g.initial_q, g.n);

  int input(const std::string& name) const {
    for (int i = 0; i < g.inputs; ++i)
      if (name == g.input_names[i]) return i;
    ADD_FAILURE() << "no input " << name;
    return 0;
  }
  int sensor(const std::string& name) const {
    for (int i = 0; i < g.sensor_outputs; ++i)
      if (name == g.sensor_names[i]) return i;
    ADD_FAILURE() << "no sensor output " << name;
    return 0;
  }
  int coordinate(const std::string& name) const {
    for (int i = 0; i < g.n; ++i)
      if (name == g.coordinate_names[i]) return i;
    ADD_FAILURE() << "no coordinate " << name;
    return 0;
  }
  Vector u_of(const Vector& q) const {
    Vector u(reduced.nu());
    for (int i = 0; i < reduced.nu(); ++i) u[i] = q[reduced.independent()[i]];
    return u;
  }
  Vector sensors(const ReducedDynamics::Result& r, const Vector& inputs) const {
    Vector out(g.sensor_outputs), lam = Vector::Zero(std::max(1, g.m)), in = inputs;
    g.sensors(r.q.data(), r.qd.data(), r.qdd.data(), lam.data(), in.data(), g.parameter_values, out.data());
    return out;
  }
  double total_mass() const {
    double m = 0.0;
    for (const Body& b : model.bodies) m += model.value(b.mass);
    return m;
  }
};

TEST(Sedan, Structure) {
  Sedan s;
  EXPECT_EQ(s.g.n, 33);
  EXPECT_EQ(s.g.m, 18);
  EXPECT_EQ(s.reduced.nu(), 14);
  EXPECT_EQ(s.g.driven_count, 1);
  // the design position closes every loop exactly
  NumericDynamics oracle(s.model);
  EXPECT_LT(oracle.constraints(s.q0).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(Sedan, AssemblesFromADisturbedConfiguration) {
  Sedan s;
  NumericDynamics oracle(s.model);
  const Vector inputs = Vector::Zero(s.g.inputs);
  for (double rack : {0.0, 0.05, -0.07}) {
    Vector in = inputs;
    in[s.input("rack.q")] = rack;
    // wheel travel (arms), body attitude, and a guess of the dependent coordinates 0.05 rad off
    Vector u = s.u_of(s.q0);
    u[6] = 0.04;
    u[7] = -0.03;
    u[8] = 0.05;
    u[9] = -0.02;
    u[4] = 0.02;
    u[5] = -0.03;
    Vector guess = s.q0;
    for (int v : s.reduced.dependent()) guess[v] += 0.05;
    const Vector ud = Vector::Zero(s.reduced.nu());
    ReducedDynamics::Result r;
    s.reduced.solve(u.data(), ud.data(), in.data(), nullptr, guess, r);
    EXPECT_LE(r.newton_iterations, 8) << "rack " << rack;
    EXPECT_LT(oracle.constraints(r.q).cwiseAbs().maxCoeff(), 1e-12) << "rack " << rack;
    EXPECT_NEAR(r.q[s.coordinate("rack")], rack, 1e-15);
  }
}

// The start the multibody block gives Newton-Raphson at a new state: the last solution moved
// along its B. Its error in the dependent coordinates is second order in the step of u (a quarter
// when the step halves), far below the last solution's own (first order), and the iteration from
// it takes fewer evaluations.
TEST(Sedan, PredictedStartIsSecondOrderInTheStep) {
  Sedan s;
  const Vector inputs = Vector::Zero(s.g.inputs);
  const int nu = s.reduced.nu();
  Vector u0 = s.u_of(s.q0);
  u0[6] = 0.02;
  u0[4] = 0.01;
  const Vector ud = Vector::Zero(nu);
  ReducedDynamics::Result last;
  s.reduced.solve(u0.data(), ud.data(), inputs.data(), nullptr, s.q0, last);
  ASSERT_TRUE(last.dynamics_current);
  Vector direction(nu);
  for (int i = 0; i < nu; ++i) direction[i] = std::cos(1.0 + 0.7 * i);  // every corner and the body
  double previous = 0.0;
  for (double step : {4e-3, 2e-3, 1e-3}) {
    const Vector u = u0 + step * direction;
    Vector guess;
    s.reduced.predict(last, u.data(), guess);
    ReducedDynamics::Result from_prediction, from_last;
    s.reduced.solve(u.data(), ud.data(), inputs.data(), nullptr, guess, from_prediction);
    s.reduced.solve(u.data(), ud.data(), inputs.data(), nullptr, last.q, from_last);
    double error = 0.0, error_last = 0.0;
    for (int v : s.reduced.dependent()) {
      error = std::max(error, std::abs(guess[v] - from_prediction.q[v]));
      error_last = std::max(error_last, std::abs(last.q[v] - from_prediction.q[v]));
    }
    EXPECT_LT(error, 0.05 * error_last) << "step " << step;
    EXPECT_LT(from_prediction.newton_iterations, from_last.newton_iterations) << "step " << step;
    if (previous > 0.0) {
      EXPECT_GT(previous / error, 3.0) << "step " << step;
      EXPECT_LT(previous / error, 5.0) << "step " << step;
    }
    previous = error;
  }
  // without the dynamics at its q (a kinematic solve only), the last q as it is
  s.reduced.solve_kinematics(u0.data(), ud.data(), inputs.data(), nullptr, s.q0, last);
  Vector guess;
  s.reduced.predict(last, (u0 + 1e-3 * direction).eval().data(), guess);
  EXPECT_EQ(guess, last.q);
}

TEST(Sedan, FallsFreelyWithG) {
  Sedan s;
  NumericDynamics oracle(s.model);
  const Vector in = Vector::Zero(s.g.inputs);
  const Vector u = s.u_of(s.q0), ud = Vector::Zero(s.reduced.nu());
  ReducedDynamics::Result r;
  s.reduced.solve(u.data(), ud.data(), in.data(), nullptr, s.q0, r);
  // every coordinate but the chassis height keeps still; no cut transmits a force
  for (int j = 0; j < s.g.n; ++j)
    EXPECT_NEAR(r.qdd[j], j == s.coordinate("z") ? -9.81 : 0.0, 1e-10) << s.g.coordinate_names[j];
  EXPECT_LT(r.lam.cwiseAbs().maxCoeff(), 1e-9);
  // every body's centre of mass (the oracle's kinematics) accelerates with g
  const NumericDynamics::Kinematics k = oracle.kinematics(r.q, r.qd, r.qdd);
  for (std::size_t b = 1; b < s.model.bodies.size(); ++b) {
    const int f = s.model.bodies[b].frame;
    const Eigen::Vector3d com(s.model.value(s.model.bodies[b].com[0]), s.model.value(s.model.bodies[b].com[1]),
                              s.model.value(s.model.bodies[b].com[2]));
    const Eigen::Vector3d a = k.acceleration[f] + k.alpha[f].cross(k.rotation[f] * com);
    EXPECT_LT((a - Eigen::Vector3d(0, 0, -9.81)).norm(), 1e-10) << s.model.bodies[b].name;
  }
}

// Static equilibrium of the design position under gravity, symmetric: spring forces (front,
// rear) and vertical tyre loads (front, rear) with B^T c(inputs) = 0 for the independent
// coordinates (linear in the inputs).
struct Equilibrium {
  double spring_front, spring_rear, tyre_front, tyre_rear, residual;
};

Equilibrium static_equilibrium(const Sedan& s) {
  const Vector u = s.u_of(s.q0), ud = Vector::Zero(s.reduced.nu());
  auto reduced_force = [&](const Vector& in) {
    ReducedDynamics::Result r;
    s.reduced.solve(u.data(), ud.data(), in.data(), nullptr, s.q0, r);
    return Vector(r.B.transpose() * (r.MBf * r.udd));  // B^T M B udd
  };
  const Vector zero = Vector::Zero(s.g.inputs);
  const Vector f0 = reduced_force(zero);
  const std::vector<std::vector<std::string>> unknowns{{"spring_fl", "spring_fr"}, {"spring_rl", "spring_rr"},
                                                       {"tyre_fz_fl.z", "tyre_fz_fr.z"}, {"tyre_fz_rl.z", "tyre_fz_rr.z"}};
  Matrix G(f0.size(), 4);
  for (int k = 0; k < 4; ++k) {
    Vector in = zero;
    for (const auto& name : unknowns[k]) in[s.input(name)] = 1.0;
    G.col(k) = reduced_force(in) - f0;
  }
  const Vector x = G.colPivHouseholderQr().solve(-f0);
  return {x[0], x[1], x[2], x[3], (G * x + f0).cwiseAbs().maxCoeff() / f0.cwiseAbs().maxCoeff()};
}

TEST(Sedan, StaticEquilibriumCarriesTheWeight) {
  Sedan s;
  const Equilibrium e = static_equilibrium(s);
  std::printf("static: spring preload front %.1f N, rear %.1f N; wheel load front %.1f N, rear %.1f N\n",
              e.spring_front, e.spring_rear, e.tyre_front, e.tyre_rear);
  RecordProperty("spring_preload_front", std::to_string(e.spring_front));
  RecordProperty("spring_preload_rear", std::to_string(e.spring_rear));
  RecordProperty("wheel_load_front", std::to_string(e.tyre_front));
  RecordProperty("wheel_load_rear", std::to_string(e.tyre_rear));
  EXPECT_LT(e.residual, 1e-10) << "4 forces balance all 14 independent coordinates";
  EXPECT_NEAR(2 * (e.tyre_front + e.tyre_rear), 9.81 * s.total_mass(), 1e-8 * s.total_mass());
  EXPECT_GT(e.spring_front, 0.0);
  EXPECT_GT(e.spring_rear, 0.0);
}

/// Motion ratio d(spring compression)/d(wheel-centre height) of corner c (fl, fr, rl, rr) at the
/// design position, by the generated tangents along the corner's arm coordinate.
double motion_ratio(Sedan& s, int c) {
  const int arm_u[4] = {6, 7, 8, 9};
  const Vector u0 = s.u_of(s.q0), ud = Vector::Zero(s.reduced.nu()), in = Vector::Zero(s.g.inputs);
  ReducedDynamics::Result r;
  s.reduced.solve(u0.data(), ud.data(), in.data(), nullptr, s.q0, r);
  Matrix du = Matrix::Zero(s.reduced.nu(), 1), dq, dqd, dqdd;
  du(arm_u[c], 0) = 1.0;
  s.reduced.tangent(r, in.data(), nullptr, 1, du.data(), nullptr, nullptr, nullptr, dq, dqd, dqdd);
  std::vector<double> out(s.g.sensor_outputs), dout(s.g.sensor_outputs);
  const Vector lam = Vector::Zero(s.g.m), zq = Vector::Zero(s.g.n), zin = Vector::Zero(s.g.inputs),
               zp = Vector::Zero(s.g.parameters);
  s.g.sensors_tangent(r.q.data(), r.qd.data(), r.qdd.data(), lam.data(), in.data(), s.g.parameter_values, 1,
                      dq.data(), zq.data(), zq.data(), zin.data(), zp.data(), out.data(), dout.data());
  const std::string corner = kCorners[c];
  return dout[s.sensor("spring_defl_" + corner + ".length")] / dout[s.sensor("wheel_z_" + corner + ".z")];
}

// Motion ratio d(spring compression)/d(wheel-centre height) per corner by the generated
// tangents (through the partitioning), against central differences of the oracle.
TEST(Sedan, MotionRatiosMatchTheOracle) {
  Sedan s;
  NumericDynamics oracle(s.model);
  const Vector u0 = s.u_of(s.q0), ud = Vector::Zero(s.reduced.nu()), in = Vector::Zero(s.g.inputs);
  ReducedDynamics::Result r;
  s.reduced.solve(u0.data(), ud.data(), in.data(), nullptr, s.q0, r);
  const int arm_u[4] = {6, 7, 8, 9};
  for (int c = 0; c < 4; ++c) {
    const std::string corner = kCorners[c];
    Matrix du = Matrix::Zero(s.reduced.nu(), 1), dq, dqd, dqdd;
    du(arm_u[c], 0) = 1.0;
    s.reduced.tangent(r, in.data(), nullptr, 1, du.data(), nullptr, nullptr, nullptr, dq, dqd, dqdd);
    std::vector<double> out(s.g.sensor_outputs), dout(s.g.sensor_outputs);
    const Vector lam = Vector::Zero(s.g.m), zq = Vector::Zero(s.g.n), zin = Vector::Zero(s.g.inputs),
                 zp = Vector::Zero(s.g.parameters);
    s.g.sensors_tangent(r.q.data(), r.qd.data(), r.qdd.data(), lam.data(), in.data(), s.g.parameter_values, 1,
                        dq.data(), zq.data(), zq.data(), zin.data(), zp.data(), out.data(), dout.data());
    const double ratio = dout[s.sensor("spring_defl_" + corner + ".length")] / dout[s.sensor("wheel_z_" + corner + ".z")];
    // the oracle: central differences of spring length and wheel height along the arm coordinate
    auto at = [&](double h) {
      Vector q = r.q, qd = Vector::Zero(s.g.n);
      q[s.reduced.independent()[arm_u[c]]] += h;
      std::vector<int> u(s.reduced.independent());
      const NumericDynamics::State st = oracle.direct_dynamics(q, qd, in, u);
      return oracle.sensors(st.q, st.qd, Vector::Zero(s.g.n));
    };
    const double h = 1e-5;
    const Vector d = (at(h) - at(-h)) / (2 * h);
    const double oracle_ratio = d[s.sensor("spring_defl_" + corner + ".length")] / d[s.sensor("wheel_z_" + corner + ".z")];
    std::printf("motion ratio %s: %.6f (oracle %.6f)\n", corner.c_str(), ratio, oracle_ratio);
    RecordProperty("motion_ratio_" + corner, std::to_string(ratio));
    EXPECT_NEAR(ratio, oracle_ratio, 1e-7);
    EXPECT_GT(ratio, 0.3);
    EXPECT_LT(ratio, 1.0);
  }
}

// The car on linear springs (preloaded for the design position) and linear tyres on a flat
// road: udd(u) linearised at the design position by central differences, K = -d(udd)/du;
// the eigenvalues of K are the squared circular frequencies of the undamped modes.
TEST(Sedan, RideFrequencies) {
  Sedan s;
  const Equilibrium e = static_equilibrium(s);
  const int nu = s.reduced.nu();
  const Vector u0 = s.u_of(s.q0), ud = Vector::Zero(nu);
  ReducedDynamics::Result r0;
  const Vector no_inputs = Vector::Zero(s.g.inputs);
  s.reduced.solve(u0.data(), ud.data(), no_inputs.data(), nullptr, s.q0, r0);
  const Vector sensors0 = s.sensors(r0, no_inputs);
  auto udd = [&](const Vector& u) {
    ReducedDynamics::Result r;
    Vector in = Vector::Zero(s.g.inputs);
    s.reduced.solve(u.data(), ud.data(), in.data(), nullptr, s.q0, r);
    const Vector y = s.sensors(r, in);
    for (const char* c : kCorners) {
      const std::string corner = c;
      const bool front = corner[0] == 'f';
      const double deflection = y[s.sensor("spring_defl_" + corner + ".length")];
      in[s.input("spring_" + corner)] = (front ? e.spring_front : e.spring_rear) +
                                        (front ? kFrontSpring : kRearSpring) * deflection;
      const double sink = sensors0[s.sensor("wheel_z_" + corner + ".z")] - y[s.sensor("wheel_z_" + corner + ".z")];
      in[s.input("tyre_fz_" + corner + ".z")] = (front ? e.tyre_front : e.tyre_rear) + kTyre * sink;
    }
    s.reduced.solve(u.data(), ud.data(), in.data(), nullptr, s.q0, r);
    return Vector(r.udd);
  };
  EXPECT_LT(udd(u0).cwiseAbs().maxCoeff(), 1e-8) << "the design position is an equilibrium";
  Matrix K(nu, nu);
  const double h = 1e-6;
  for (int i = 0; i < nu; ++i) {
    Vector up = u0, um = u0;
    up[i] += h;
    um[i] -= h;
    K.col(i) = -(udd(up) - udd(um)) / (2 * h);
  }
  Eigen::EigenSolver<Matrix> eig(K);
  std::vector<double> hz, hop_front, hop_rear;
  for (int i = 0; i < nu; ++i) {
    const double lambda = eig.eigenvalues()[i].real();
    if (lambda <= 1.0) continue;
    const double f = std::sqrt(lambda) / (2 * std::numbers::pi);
    hz.push_back(f);
    // A wheel-hop mode (above 8 Hz) belongs to the axle whose arms (u 6, 7 front; 8, 9 rear) move.
    const Eigen::VectorXd v = eig.eigenvectors().col(i).cwiseAbs();  // eigenvectors() is a temporary
    if (f > 8.0) (v[6] + v[7] > v[8] + v[9] ? hop_front : hop_rear).push_back(f);
  }
  std::sort(hz.begin(), hz.end());
  std::string list;
  for (double f : hz) list += std::to_string(f) + " ";
  std::printf("undamped frequencies [Hz]: %s\n", list.c_str());
  RecordProperty("frequencies_hz", list);
  ASSERT_EQ(hz.size(), 7u) << "bounce, pitch, roll and four wheel-hop modes (x, y, yaw and spins are free)";
  // By hand, one corner at a time (docs/models.md, springs and ride frequencies): the wheel rate
  // k_s MR^2 (MR the motion ratio, from the generated tangents) in series with the tyre, on the
  // sprung mass of the corner (static wheel load / g less the corner's bodies), gives the ride
  // frequency; the wheel hop is sqrt((k_w + k_t) / m_u) / 2 pi with m_u the wheel (with
  // spindle) and upright and half of the arms that pivot on the body. Masses from
  // generated_models/sedan.mbs.yaml: front wheel 21.103, upright 1.397, arms 1.611 and 1.032 kg;
  // rear wheel 21.103, upright 3.201, arms 4.744 and 15.204 kg.
  const double corner_front = 21.103 + 1.397 + 1.611 + 1.032, corner_rear = 21.103 + 3.201 + 4.744 + 15.204;
  const double unsprung_front = 21.103 + 1.397 + (1.611 + 1.032) / 2;
  const double unsprung_rear = 21.103 + 3.201 + (4.744 + 15.204) / 2;
  const double wheel_rate_front = kFrontSpring * std::pow(motion_ratio(s, 0), 2);
  const double wheel_rate_rear = kRearSpring * std::pow(motion_ratio(s, 2), 2);
  const auto series = [](double a, double b) { return a * b / (a + b); };
  const auto hertz = [](double stiffness, double mass) { return std::sqrt(stiffness / mass) / (2 * std::numbers::pi); };
  const double ride_front = hertz(series(wheel_rate_front, kTyre), e.tyre_front / 9.81 - corner_front);
  const double ride_rear = hertz(series(wheel_rate_rear, kTyre), e.tyre_rear / 9.81 - corner_rear);
  const double hop_front_hand = hertz(wheel_rate_front + kTyre, unsprung_front);
  const double hop_rear_hand = hertz(wheel_rate_rear + kTyre, unsprung_rear);
  std::printf("by hand: ride %.3f front, %.3f rear; wheel hop %.2f front, %.2f rear [Hz]\n", ride_front, ride_rear,
              hop_front_hand, hop_rear_hand);
  for (double f : hop_front) std::printf("front wheel-hop mode %.2f Hz\n", f);
  for (double f : hop_rear) std::printf("rear wheel-hop mode %.2f Hz\n", f);
  // The lowest mode is the front-dominated bounce; the rear ride lies with pitch and roll.
  EXPECT_NEAR(hz[0], ride_front, 0.1 * ride_front);
  EXPECT_NEAR(hz[1], ride_rear, 0.1 * ride_rear);
  ASSERT_EQ(hop_front.size(), 2u);
  ASSERT_EQ(hop_rear.size(), 2u);
  for (double f : hop_front) EXPECT_NEAR(f, hop_front_hand, 0.1 * hop_front_hand) << "front wheel hop";
  for (double f : hop_rear) EXPECT_NEAR(f, hop_rear_hand, 0.1 * hop_rear_hand) << "rear wheel hop";
}


// The multibody.sedan block in a scene: linear springs preloaded for the design position,
// linear dampers (math.gain on the stroke rate, tension positive), tyre.vertical on a flat road
// at z = 0, rack held at 0 by its inputs. Dropped from 1 cm above the design position, the car
// settles back into it (its static equilibrium); every feedback path (springs, dampers, tyres)
// runs through states, so the scene has no algebraic loop.
TEST(SedanScene, RestsInItsDesignPosition) {
  Sedan s;
  const Equilibrium e = static_equilibrium(s);
  std::ostringstream y;
  y << "scene: sedan_rest\ntime: {start: 0.0, stop: 3.0, output_step: 0.1}\n"
    << "solver: {method: bdf, rtol: 1.0e-8, atol: 1.0e-10}\nblocks:\n"
    << "  car: {type: multibody.sedan, q0.z: " << s.q0[2] + 0.01 << "}\n  zero: {type: source.constant, value: 0.0}\n";
  for (const char* c : kCorners) {
    const bool front = c[0] == 'f';
    y << "  spring_" << c << ": {type: spring.linear, stiffness: " << (front ? kFrontSpring : kRearSpring)
      << ", preload: " << (front ? e.spring_front : e.spring_rear) << "}\n"
      << "  damper_" << c << ": {type: math.gain, k: 8000.0}\n"
      << "  tyre_" << c << ": {type: tyre.vertical}\n";
  }
  y << "connections:\n";
  for (const char* c : kCorners) {
    const std::string k = c;
    for (const std::string& line :
         {"car.spring_defl_" + k + " -> spring_" + k + ".deflection", "spring_" + k + ".force -> car.spring_" + k,
          "car.damper_rate_" + k + " -> damper_" + k + ".u", "damper_" + k + ".y -> car.damper_" + k,
          "zero.y -> tyre_" + k + ".road_z", "zero.y -> tyre_" + k + ".road_zdot",
          "car.wheel_z_" + k + " -> tyre_" + k + ".wheel_z", "car.wheel_zdot_" + k + " -> tyre_" + k + ".wheel_zdot",
          "tyre_" + k + ".force -> car.tyre_fz_" + k, "zero.y -> car.arb_" + k, "zero.y -> car.tyre_fx_" + k,
          "zero.y -> car.tyre_fy_" + k, "zero.y -> car.wheel_torque_" + k})
      y << "  - " << line << "\n";
  }
  y << "  - zero.y -> car.rack\n  - zero.y -> car.rack_rate\n  - zero.y -> car.rack_acc\n"
    << "outputs: [car.body_pos, car.roll, car.pitch, car.wheel_z_fl, car.body_acc_z]\n";
  const std::string path = ::testing::TempDir() + "sedan_rest_" + std::to_string(::getpid()) + ".yaml";
  std::ofstream(path) << y.str();
  engine::RunOptions options;
  options.sensitivities = false;
  const engine::RunResult r = engine::run(engine::load_scene(path), options);
  std::remove(path.c_str());
  const int last = static_cast<int>(r.t.size()) - 1;
  ASSERT_NEAR(r.t.back(), 3.0, 1e-12);
  EXPECT_GT(r.value(0, r.signal_index("car.body_pos[2]")), s.q0[2] + 0.2 + 0.009);
  // tyre deflection at the design wheel loads: the design wheel-centre height
  EXPECT_NEAR(r.value(last, r.signal_index("car.wheel_z_fl")), 0.32 - e.tyre_front / kTyre, 2e-5);
  EXPECT_NEAR(r.value(last, r.signal_index("car.body_pos[2]")), s.q0[2] + 0.2, 5e-5);
  EXPECT_NEAR(r.value(last, r.signal_index("car.roll")), 0.0, 1e-9);
  EXPECT_NEAR(r.value(last, r.signal_index("car.pitch")), s.q0[4], 2e-4);
  EXPECT_LT(std::abs(r.value(last, r.signal_index("car.body_acc_z"))), 1e-3);
}

}  // namespace
}  // namespace dydp::mbs
