// The adjoint gradients (engine/analysis/cvodes_adjoint.hpp) against two independent references:
// the forward sensitivities of the same scene (all its declared parameters and directions,
// every objective: rms, ISO 2631 Wk-weighted rms, mean power), at tight tolerances; and central
// differences of psi, whose error must fall as h^2 towards the adjoint value. Objectives without
// an adjoint and fixed-step solvers are refused by name.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <functional>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <string>
#include <vector>

#include "engine/analysis/cvodes_adjoint.hpp"
#include "engine/analysis/run.hpp"
#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"
#include "tests/engine/msd_closed_form.hpp"

namespace dydp::engine {
namespace {

Diagram tight_scene(const std::string& scene, double stop, double rtol, double atol) {
  Diagram d = load_scene(std::string(DYDP_SOURCE_DIR) + "/scenarios/" + scene);
  d.time.stop = stop;
  d.solver.rtol = rtol;
  d.solver.atol = atol;
  d.solver.sens_error_test = true;
  std::vector<int> all(d.parameters.size());
  std::iota(all.begin(), all.end(), 0);
  d.set_sensitivities(all);
  return d;
}

RunResult run_adjoint(const Diagram& d) {
  RunOptions options;
  options.adjoint = true;
  return run(d, options);
}

void expect_same_gradients(const Diagram& d, const RunResult& forward, const RunResult& adjoint, double tolerance) {
  ASSERT_EQ(forward.objectives.size(), adjoint.objectives.size());
  ASSERT_EQ(forward.sensitivity_names, adjoint.sensitivity_names);
  for (size_t o = 0; o < forward.objectives.size(); ++o) {
    const ObjectiveResult& f = forward.objectives[o];
    const ObjectiveResult& a = adjoint.objectives[o];
    EXPECT_NEAR(a.value, f.value, 1e-6 * std::fabs(f.value)) << f.name;
    for (size_t k = 0; k < f.sensitivity.size(); ++k) {
      const double p = std::fabs(d.parameters[d.sensitivities[k]].value);
      // relative to the gradient, with a floor where it is nearly zero: 1e-9 of psi per |p|
      const double floor = 1e-9 * std::fabs(f.value) / (p > 0 ? p : 1.0);
      EXPECT_NEAR(a.sensitivity[k], f.sensitivity[k], tolerance * std::fabs(f.sensitivity[k]) + floor)
          << f.name << " by " << forward.sensitivity_names[k];
    }
  }
}

// The mass-spring-damper's rms against its closed form: psi = sqrt(1/T integral of x^2) by
// Gauss-Legendre over the exact x(t), its derivatives by complex step.
TEST(AdjointGradient, EqualsTheClosedFormOnTheMassSpringDamper) {
  const Diagram d = tight_scene("msd_sensitivity.yaml", 10.0, 1e-12, 1e-13);
  const RunResult r = run_adjoint(d);
  ASSERT_EQ(r.objectives.size(), 1u);
  const double from = 2.0, to = 10.0;
  auto rms = [&](const test::MsdParams<std::complex<double>>& p) {
    const auto integral = test::gauss_legendre<std::complex<double>>(
        [&](double t) { const auto x = test::msd_position(p, t); return x * x; }, from, to, 4000);
    return std::sqrt(integral / (to - from));
  };
  const test::MsdParams<double> p{1.5, 40.0, 1.2, 2.0, 2 * M_PI * 0.8, 0.05, 0.0};
  ASSERT_EQ(r.sensitivity_names, (std::vector<std::string>{"mass", "stiffness", "damping"}));
  for (int j = 0; j < 3; ++j) {
    const double g_ref = test::complex_step(rms, p, j);
    EXPECT_NEAR(r.objectives[0].sensitivity[j], g_ref, 1e-8 * std::fabs(g_ref)) << r.sensitivity_names[j];
  }
}

TEST(AdjointGradient, EqualsTheForwardSensitivitiesOnTheQuarterCar) {
  const Diagram d = tight_scene("quarter_car_cdc.yaml", 3.0, 1e-9, 1e-9);
  ASSERT_EQ(d.objectives.size(), 3u);
  const RunResult forward = run(d, {});
  const RunResult adjoint = run_adjoint(d);
  EXPECT_TRUE(adjoint.stats.adjoint.used);
  EXPECT_GT(adjoint.stats.adjoint.backward_steps, 0);
  EXPECT_GT(adjoint.stats.adjoint.checkpoints, 0);
  EXPECT_EQ(adjoint.stats.adjoint.segments, 2);  // the objectives' window opens at 2 s
  EXPECT_FALSE(adjoint.signal_sensitivities);
  EXPECT_TRUE(adjoint.tangents.empty());
  expect_same_gradients(d, forward, adjoint, 1e-6);
}

TEST(AdjointGradient, EqualsTheForwardSensitivitiesOnTheSedanFourposter) {
  // every declared parameter and direction: 2 scene parameters, 16 directions
  const Diagram d = tight_scene("fourposter_comfort.yaml", 2.6, 1e-10, 1e-10);
  ASSERT_EQ(d.sensitivities.size(), 18u);
  ASSERT_EQ(d.objectives.size(), 2u);
  const RunResult forward = run(d, {});
  const RunResult adjoint = run_adjoint(d);
  expect_same_gradients(d, forward, adjoint, 1e-6);
}

// psi by central differences at h = 4 %, 2 % and 1 % of p: where the difference's h^2 term is
// above the runs' noise (psi to about 1e-9 of itself, so the quotient to about 1e-7 psi / p) its
// error to the adjoint gradient falls by about 4 per halving, and the Richardson extrapolation of
// the last two, (4 D(h/2) - D(h)) / 3, agrees with the adjoint to 1e-5 of the gradient, or to
// the noise's 1e-6 psi / p where the gradient is that small.
TEST(AdjointGradient, AgreesWithCentralDifferencesOnTheQuarterCar) {
  const Diagram base = tight_scene("quarter_car_cdc.yaml", 3.0, 1e-9, 1e-9);
  const RunResult adjoint = run_adjoint(base);
  for (size_t k = 0; k < base.sensitivities.size(); ++k) {
    const int index = base.sensitivities[k];
    const double p = base.parameters[index].value;
    std::vector<std::vector<double>> quotients(adjoint.objectives.size());
    for (double rel : {0.04, 0.02, 0.01}) {
      const double h = rel * p;
      double psi[2][3] = {};
      for (int side = 0; side < 2; ++side) {
        Diagram d = tight_scene("quarter_car_cdc.yaml", 3.0, 1e-9, 1e-9);
        d.set_parameter(index, side == 0 ? p + h : p - h, false);
        RunOptions plain;
        plain.sensitivities = false;
        const RunResult r = run(d, plain);
        for (size_t o = 0; o < r.objectives.size(); ++o) psi[side][o] = r.objectives[o].value;
      }
      for (size_t o = 0; o < adjoint.objectives.size(); ++o) quotients[o].push_back((psi[0][o] - psi[1][o]) / (2 * h));
    }
    for (size_t o = 0; o < adjoint.objectives.size(); ++o) {
      const std::string what = adjoint.objectives[o].name + " by " + adjoint.sensitivity_names[k];
      const double g = adjoint.objectives[o].sensitivity[k];
      const double noise = 1e-6 * std::fabs(adjoint.objectives[o].value) / std::fabs(p);
      const std::vector<double>& D = quotients[o];
      const double e0 = std::fabs(D[0] - g), e1 = std::fabs(D[1] - g);
      if (e0 > 50 * noise) {
        EXPECT_GT(e0 / e1, 3.0) << what;
        EXPECT_LT(e0 / e1, 5.0) << what;
      }
      const double richardson = (4 * D[2] - D[1]) / 3;
      EXPECT_NEAR(richardson, g, 1e-5 * std::fabs(g) + noise) << what << ": differences " << D[0] << ", " << D[1]
                                                                << ", " << D[2];
    }
  }
}

TEST(AdjointGradient, RefusesAnObjectiveWithoutAnAdjointByName) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() / "dydp_adjoint_max_abs.yaml";
  std::ofstream(path) << "scene: peak\n"
                         "time: {stop: 1.0, output_step: 0.1}\n"
                         "parameters:\n"
                         "  stiffness: {value: 40.0}\n"
                         "sensitivities: [stiffness]\n"
                         "blocks:\n"
                         "  force: {type: source.constant, value: 0.0}\n"
                         "  body: {type: mass_spring_damper, k: $stiffness, x0: 0.1}\n"
                         "  peak: {type: objective.max_abs}\n"
                         "connections:\n"
                         "  - force.y -> body.f\n"
                         "  - body.x -> peak.in\n"
                         "outputs: [peak]\n";
  Diagram d = load_scene(path.string());
  std::filesystem::remove(path);
  try {
    run_adjoint(d);
    FAIL() << "an objective reading output samples was run by the adjoint method";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("peak"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("objective.max_abs"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no adjoint"), std::string::npos) << e.what();
  }
  d.solver.method = "rk4";
  try {
    check_adjoint_possible(d);
    FAIL() << "a fixed-step method was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--solver bdf"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace dydp::engine
