// The linear analyses (engine/linear/) on a linear quarter car (the generated model's own
// spring and damper, a tyre of linear stiffness and damping) against its closed form, built
// here by hand in absolute coordinates: M z'' + C z' + K z = f(road),
//   M = diag(ms, mu), K = [ks, -ks; -ks, ks + kt], C = [cs, -cs; -cs, cs + ct].
// Independent of the generator: the model's relative coordinates, its sensors and the
// diagram's tangents give the same eigenvalues, derivatives and transfer function or fail.
#include <gtest/gtest.h>

#include <complex>
#include <filesystem>
#include <fstream>

#include "engine/framework/errors.hpp"
#include "engine/linear/equilibrium.hpp"
#include "engine/linear/frequency_response.hpp"
#include "engine/linear/modes.hpp"

namespace dydp::engine {
namespace {

using Complex = std::complex<double>;
constexpr double kG = 9.81, kTwoPi = 6.283185307179586;

struct Values {
  double ks = 20000.0, cs = 1500.0, kt = 250000.0, ct = 150.0, ms = 350.0, mu = 40.0;
};

std::string scene_file() {
  const std::string path = (std::filesystem::temp_directory_path() / "dydp_quarter_car_linear.yaml").string();
  std::ofstream(path) << R"(scene: quarter_car_linear
time: {start: 0.0, stop: 1.0, output_step: 0.01}
parameters:
  ks: {value: 20000.0, unit: N/m}
  cs: {value: 1500.0, unit: N s/m}
  kt: {value: 250000.0, unit: N/m}
  ct: {value: 150.0, unit: N s/m}
  ms: {value: 350.0, unit: kg}
sensitivities: [ks]
blocks:
  rz: {type: source.constant, value: 0.0}
  rzd: {type: source.constant, value: 0.0}
  car: {type: multibody.quarter_car, spring: $ks, damper: $cs, sprung_mass: $ms, q0.z_body: 0.59, q0.z_wheel: 0.01}
  wheel_z: {type: math.demux, width: 3, indices: [2]}
  wheel_zdot: {type: math.demux, width: 3, indices: [2]}
  tyre: {type: tyre.vertical, stiffness: $kt, damping: $ct, contact_width: 1.0e-6, force_width: 1.0e-6}
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
outputs: [body_az.y, tyre.force, car.wheel_position]
)";
  return path;
}

/// The closed form's first-order matrix [0 I; -M^-1 K, -M^-1 C] and its eigenvalues.
Eigen::Matrix4d closed_form_matrix(const Values& v) {
  Eigen::Matrix2d M, K, C;
  M << v.ms, 0, 0, v.mu;
  K << v.ks, -v.ks, -v.ks, v.ks + v.kt;
  C << v.cs, -v.cs, -v.cs, v.cs + v.ct;
  Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
  A.topRightCorner<2, 2>() = Eigen::Matrix2d::Identity();
  A.bottomLeftCorner<2, 2>() = -M.inverse() * K;
  A.bottomRightCorner<2, 2>() = -M.inverse() * C;
  return A;
}

/// The two eigenvalues with Im > 0, by frequency.
std::vector<Complex> closed_form_modes(const Values& v) {
  Eigen::EigenSolver<Eigen::Matrix4d> eig(closed_form_matrix(v));
  std::vector<Complex> out;
  for (int i = 0; i < 4; ++i)
    if (eig.eigenvalues()[i].imag() > 0) out.push_back(eig.eigenvalues()[i]);
  std::sort(out.begin(), out.end(), [](Complex a, Complex b) { return std::abs(a) < std::abs(b); });
  return out;
}

/// Body acceleration over road height: s^2 Zs / Zr with (M s^2 + C s + K) Z = [0; kt + ct s] Zr.
Complex closed_form_acceleration(const Values& v, double f) {
  const Complex s(0, kTwoPi * f);
  Eigen::Matrix2cd Z;
  Z << v.ms * s * s + v.cs * s + v.ks, -(v.cs * s + v.ks), -(v.cs * s + v.ks), v.mu * s * s + (v.cs + v.ct) * s + v.ks + v.kt;
  Eigen::Vector2cd rhs(0.0, v.kt + v.ct * s);
  return s * s * Eigen::Vector2cd(Z.partialPivLu().solve(rhs))[0];
}

class QuarterCarLinear : public ::testing::Test {
 protected:
  void SetUp() override {
    d_ = load_scene(scene_file());
    eq_ = find_equilibrium(d_);
  }
  int parameter(const std::string& name) const { return d_.find_parameter(name); }
  Diagram d_;
  Equilibrium eq_;
};

TEST_F(QuarterCarLinear, EquilibriumCarriesTheWeightOnSpringAndTyre) {
  const Values v;
  EXPECT_LT(eq_.residual, 1e-9);
  ASSERT_EQ(eq_.x.size(), 4u);
  // The tyre carries both masses, the spring the sprung one.
  const std::vector<double> f = signal_values(d_, 0.0, eq_.x, {"tyre.force"});
  EXPECT_NEAR(f[0], (v.ms + v.mu) * kG, 1e-9 * (v.ms + v.mu) * kG);
  // Its sensitivity: the tyre deflects by (ms + mu) g / kt, so d(wheel centre)/d(kt) =
  // (ms + mu) g / kt^2 (the wheel rises as the tyre stiffens), and the spring's by ms g / ks.
  const std::vector<double> zw = signal_values(d_, 0.0, eq_.x, {"car.wheel_position[2]"});
  const double R0 = 0.32;
  EXPECT_NEAR(zw[0], R0 - (v.ms + v.mu) * kG / v.kt, 1e-12);
  const auto col = [&](const std::string& p) {
    const auto it = std::find(eq_.parameters.begin(), eq_.parameters.end(), parameter(p));
    EXPECT_NE(it, eq_.parameters.end()) << p;
    return static_cast<Eigen::Index>(it - eq_.parameters.begin());
  };
  // The wheel's absolute height is z_body - 0.3 + z_wheel (states 0 and 1: q.z_body, q.z_wheel).
  ASSERT_EQ(eq_.states[0], "car.q.z_body");
  ASSERT_EQ(eq_.states[1], "car.q.z_wheel");
  const double dzw_dkt = eq_.dx_dp(0, col("kt")) + eq_.dx_dp(1, col("kt"));
  EXPECT_NEAR(dzw_dkt, (v.ms + v.mu) * kG / (v.kt * v.kt), 1e-9 * (v.ms + v.mu) * kG / (v.kt * v.kt));
  // The spring shortens by ms g / ks: d(z_body - wheel)/d(ks) = ms g / ks^2, so d(q.z_wheel)/d(ks)
  // = -ms g / ks^2 (the wheel's coordinate is its travel up relative to the body).
  EXPECT_NEAR(eq_.dx_dp(1, col("ks")), -v.ms * kG / (v.ks * v.ks), 1e-9 * v.ms * kG / (v.ks * v.ks));
  // Damping moves no equilibrium.
  EXPECT_NEAR(eq_.dx_dp(0, col("cs")), 0.0, 1e-15);
}

TEST_F(QuarterCarLinear, ModesAreTheClosedFormsTwo) {
  const LinearModel m = linearize(d_, eq_.t, eq_.x, {}, {});
  const std::vector<Mode> found = modes(m);
  const std::vector<Complex> expected = closed_form_modes(Values{});
  ASSERT_EQ(found.size(), 2u);
  for (int k = 0; k < 2; ++k) {
    EXPECT_LT(std::abs(found[k].eigenvalue - expected[k]), 1e-10 * std::abs(expected[k])) << k;
    EXPECT_NEAR(found[k].frequency_hz, std::abs(expected[k]) / kTwoPi, 1e-10 * found[k].frequency_hz);
    EXPECT_NEAR(found[k].damping_ratio, -expected[k].real() / std::abs(expected[k]), 1e-10);
  }
  // Body bounce near 1.1 Hz, wheel hop near 13 Hz, named by the states that carry them.
  EXPECT_GT(found[0].frequency_hz, 0.9);
  EXPECT_LT(found[0].frequency_hz, 1.5);
  EXPECT_GT(found[1].frequency_hz, 10.0);
  EXPECT_EQ(found[0].dominant[0].first.substr(0, 10), "car.q.z_bo");
}

TEST_F(QuarterCarLinear, EigenvalueDerivativesAreTheClosedFormsDerivatives) {
  const LinearModel m = linearize(d_, eq_.t, eq_.x, {}, {});
  std::vector<Eigen::MatrixXd> dA;
  const std::vector<std::string> names = {"ks", "cs", "kt", "ct", "ms"};
  for (const std::string& p : names) {
    const auto it = std::find(eq_.parameters.begin(), eq_.parameters.end(), parameter(p));
    ASSERT_NE(it, eq_.parameters.end()) << p;
    dA.push_back(linear_model_derivative(d_, m, parameter(p), eq_.dx_dp.col(it - eq_.parameters.begin())).A);
  }
  const std::vector<Mode> found = modes(m, dA);
  ASSERT_EQ(found.size(), 2u);
  for (size_t j = 0; j < names.size(); ++j) {
    // The closed form's eigenvalues differenced at +-1e-4 relative (their error ~1e-9 relative).
    Values up, down;
    auto field = [&](Values& v) -> double& {
      return j == 0 ? v.ks : j == 1 ? v.cs : j == 2 ? v.kt : j == 3 ? v.ct : v.ms;
    };
    const double h = 1e-4 * field(up);
    field(up) += h;
    field(down) -= h;
    const std::vector<Complex> lu = closed_form_modes(up), ld = closed_form_modes(down);
    for (int k = 0; k < 2; ++k) {
      const Complex expected = (lu[k] - ld[k]) / (2 * h);
      const Complex got = found[k].sensitivity[j].eigenvalue;
      EXPECT_LT(std::abs(got - expected), 1e-8 * std::abs(found[k].eigenvalue) / field(up)) << names[j] << " mode " << k;
      EXPECT_GT(std::abs(expected), 0.0) << names[j];
    }
  }
}

TEST_F(QuarterCarLinear, FrequencyResponseIsTheClosedFormTransferFunction) {
  const LinearModel m = linearize(d_, eq_.t, eq_.x, {"rz.y", "rzd.y"}, {"body_az.y"});
  ASSERT_EQ(m.B.cols(), 2);
  const std::vector<double> f = log_frequencies(0.5, 30.0, 25);
  const FrequencyResponse h = frequency_response(m, {0, 1}, f);
  for (size_t k = 0; k < f.size(); ++k) {
    const Complex expected = closed_form_acceleration(Values{}, f[k]);
    EXPECT_LT(std::abs(h.H[k][0] - expected), 1e-9 * std::abs(expected)) << f[k] << " Hz";
  }
}

TEST_F(QuarterCarLinear, MagnitudeDerivativeIsTheClosedFormsDerivative) {
  const LinearModel m = linearize(d_, eq_.t, eq_.x, {"rz.y", "rzd.y"}, {"body_az.y"});
  const int p = parameter("cs");
  const auto it = std::find(eq_.parameters.begin(), eq_.parameters.end(), p);
  ASSERT_NE(it, eq_.parameters.end());
  const LinearModelDerivative dm = linear_model_derivative(d_, m, p, eq_.dx_dp.col(it - eq_.parameters.begin()));
  const std::vector<double> f = {0.8, 1.2, 3.0, 12.0};
  const FrequencyResponse h = frequency_response(m, {0, 1}, f, {dm});
  for (size_t k = 0; k < f.size(); ++k) {
    Values up, down;
    const double step = 1e-4 * up.cs;
    up.cs += step;
    down.cs -= step;
    const double expected = (std::abs(closed_form_acceleration(up, f[k])) - std::abs(closed_form_acceleration(down, f[k]))) / (2 * step);
    EXPECT_NEAR(h.dmagnitude[0][k][0], expected, 1e-7 * std::abs(expected)) << f[k] << " Hz";
  }
}

// The band rms of |H| (a transmissibility objective) and its derivative against the closed
// form's, integrated by the same trapezoid rule on the same grid and differenced in cs.
TEST_F(QuarterCarLinear, BandRmsTransmissibilityAndItsDerivativeAreTheClosedForms) {
  const LinearModel m = linearize(d_, eq_.t, eq_.x, {"rz.y", "rzd.y"}, {"body_az.y"});
  const int p = parameter("cs");
  const auto it = std::find(eq_.parameters.begin(), eq_.parameters.end(), p);
  ASSERT_NE(it, eq_.parameters.end());
  const LinearModelDerivative dm = linear_model_derivative(d_, m, p, eq_.dx_dp.col(it - eq_.parameters.begin()));
  const std::vector<double> f = log_frequencies(0.5, 30.0, 40);
  const BandRms t = band_rms(frequency_response(m, {0, 1}, f, {dm}));
  auto closed = [&](const Values& v) {
    double sum = 0.0;
    for (size_t k = 0; k + 1 < f.size(); ++k)
      sum += 0.5 * (f[k + 1] - f[k]) *
             (std::norm(closed_form_acceleration(v, f[k])) + std::norm(closed_form_acceleration(v, f[k + 1])));
    return std::sqrt(sum / (f.back() - f.front()));
  };
  ASSERT_EQ(t.value.size(), 1u);
  EXPECT_NEAR(t.value[0], closed(Values{}), 1e-9 * t.value[0]);
  Values up, down;
  const double step = 1e-4 * up.cs;
  up.cs += step;
  down.cs -= step;
  const double expected = (closed(up) - closed(down)) / (2 * step);
  EXPECT_NEAR(t.sensitivity[0][0], expected, 1e-7 * std::abs(expected));
  // Most of a band in linear frequency lies above sqrt(2) times the body's frequency, where
  // damping transmits more: the band rms rises with cs.
  EXPECT_GT(expected, 0.0);
}

TEST_F(QuarterCarLinear, UnknownSignalsAreRefusedByName) {
  try {
    linearize(d_, 0.0, eq_.x, {"rz.nope"}, {});
    FAIL() << "an unknown port was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("block rz has no output nope (its outputs: y)"), std::string::npos) << e.what();
  }
  EXPECT_THROW(linearize(d_, 0.0, eq_.x, {}, {"nowhere.y"}), InputError);
  EXPECT_THROW(linearize(d_, 0.0, eq_.x, {}, {"car.body_acc[3]"}), InputError);
  EXPECT_THROW(linearize(d_, 0.0, eq_.x, {}, {"car.body_acc[x]"}), InputError);
}

}  // namespace
}  // namespace dydp::engine
