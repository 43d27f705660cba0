// Sensitivity outputs of the Co-Simulation FMU (`sensitivities:` of an FMU description): the
// CDC damper's d(output)/d(valve_current) and d(output)/d(pipe_length) over a run against the
// native run's sensitivities (engine::run with the same directions), both measured against a
// converged native reference (from the blocks' initial states and from `initial: equilibrium`),
// and against central differences of the FMU's own outputs; the quarter car's objectives'
// sensitivities against objectives.json's; the refusal of Model Exchange; the sensitivities
// through an FMU state.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "engine/analysis/run.hpp"
#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"
#include "engine/studies/initial_equilibrium.hpp"
#include "tests/fmi/fmu_fixture.hpp"

namespace dydp::test {
namespace {

namespace fs = std::filesystem;

/// Instantiated, parameters set (value reference, value), initialised with rtol (0: the scene's).
fmi3Instance start_cs(Fmu& fmu, double stop, const std::vector<std::pair<fmi3ValueReference, double>>& set = {},
                      double rtol = 0.0) {
  const Fmi3Functions& f = fmu.f();
  fmi3Instance inst = fmu.instantiate_cs();
  EXPECT_NE(inst, nullptr) << fmu.last_error();
  for (const auto& [vr, value] : set) EXPECT_EQ(f.fmi3SetFloat64(inst, &vr, 1, &value, 1), fmi3OK) << fmu.last_error();
  EXPECT_EQ(f.fmi3EnterInitializationMode(inst, rtol > 0, rtol, 0.0, true, stop), fmi3OK) << fmu.last_error();
  EXPECT_EQ(f.fmi3ExitInitializationMode(inst), fmi3OK) << fmu.last_error();
  return inst;
}

/// Outputs at t0 and after each of `steps` communication steps of h; with_inputs, the damper's
/// stroke and rate set from the rig's sines at the start of each step.
std::vector<std::vector<double>> run_cs(Fmu& fmu, fmi3Instance inst, double h, int k0, int k1,
                                        const std::vector<fmi3ValueReference>& outputs, bool with_inputs) {
  const Fmi3Functions& f = fmu.f();
  const auto inputs = fmu.description().of("input");
  std::vector<std::vector<double>> out;
  std::vector<double> y(outputs.size());
  auto read = [&] {
    EXPECT_EQ(f.fmi3GetFloat64(inst, outputs.data(), outputs.size(), y.data(), y.size()), fmi3OK) << fmu.last_error();
    out.push_back(y);
  };
  if (k0 == 0) read();
  for (int k = k0; k < k1; ++k) {
    const double t = k * h;
    if (with_inputs) {
      const double u[2] = {rig_stroke(t), rig_stroke_rate(t)};
      EXPECT_EQ(f.fmi3SetFloat64(inst, inputs.data(), 2, u, 2), fmi3OK) << fmu.last_error();
    }
    fmi3Boolean event = false, terminate = false, early = false;
    fmi3Float64 last = 0.0;
    EXPECT_EQ(f.fmi3DoStep(inst, t, (k + 1) * h - t, true, &event, &terminate, &early, &last), fmi3OK) << fmu.last_error();
    read();
  }
  return out;
}

std::vector<double> column(const std::vector<std::vector<double>>& rows, size_t j) {
  std::vector<double> c;
  for (const auto& r : rows) c.push_back(r[j]);
  return c;
}

/// The damper's sensitivity outputs over 0.5 s of the FMU of `description` (the rig scene
/// `scene`, its sources inside, so that it integrates the native equations) against the native
/// run of `scene` with the same directions, both against a reference 10^4 times tighter.
void expect_damper_sensitivities_match_native(const std::string& scene, const std::string& description,
                                              const std::string& name) {
  engine::Diagram d = engine::load_scene(scene);
  d.time.stop = 0.5;
  const double h = 0.005;
  const int steps = 100;
  d.set_sensitivities({d.find_parameter("valve_current"), d.find_parameter("pipe_length")});
  engine::start_at_equilibrium(d);  // `initial: equilibrium`: its dx/dp too
  const engine::RunResult native = engine::run(d, {});
  d.solver.rtol *= 1e-4;
  d.solver.atol *= 1e-4;
  engine::start_at_equilibrium(d);
  const engine::RunResult reference = engine::run(d, {});
  ASSERT_EQ(reference.sensitivity_names, (std::vector<std::string>{"valve_current", "pipe_length"}));

  auto fmu = load_fmu(description, name, "native", true);
  const Description& desc = fmu->description();
  const std::string fmu_name = name;
  const auto outputs = desc.of("output");
  fmi3Instance inst = start_cs(*fmu, 0.5);
  const auto cs = run_cs(*fmu, inst, h, 0, steps, outputs, false);
  ASSERT_EQ(cs.size(), reference.t.size());

  double cs_error = 0.0, native_error = 0.0;
  int compared = 0;
  for (const char* signal : {"damper.force", "damper.p_rebound", "damper.p_compression", "damper.power"}) {
    const int i = reference.signal_index(signal);
    ASSERT_GE(i, 0) << signal;
    for (int dir = 0; dir < 2; ++dir) {
      const std::string name = std::string("d(") + signal + ")/d(" + reference.sensitivity_names[dir] + ")";
      const auto& v = desc.variable(name);
      EXPECT_EQ(v.attributes.at("causality"), "output") << name;
      EXPECT_EQ(v.attributes.at("variability"), "continuous") << name;
      const size_t j = std::find(outputs.begin(), outputs.end(), v.value_reference) - outputs.begin();
      ASSERT_LT(j, outputs.size()) << name;
      std::vector<double> b, r;
      for (size_t k = 0; k < reference.t.size(); ++k)
        b.push_back(native.tangent(static_cast<int>(k), dir, i)), r.push_back(reference.tangent(static_cast<int>(k), dir, i));
      const auto a = column(cs, j);
      const double e_cs = column_error(a, r), e_native = column_error(b, r);
      cs_error = std::max(cs_error, e_cs), native_error = std::max(native_error, e_native);
      ++compared;
      std::printf("[measure] %s %s: CS error %.3g, native error %.3g (relative to the column's largest value), "
                  "CS - native %.3g\n", fmu_name.c_str(), name.c_str(), e_cs, e_native, column_error(a, b));
    }
  }
  EXPECT_EQ(compared, 8);
  // As for the values (fmu_co_simulation_test.cpp): the FMU's sensitivities held to 10 times the
  // native run's own error against the converged reference, and to 1e-3 outright.
  EXPECT_LE(cs_error, std::max(10.0 * native_error, 1e-9));
  EXPECT_LE(cs_error, 1e-3);
  fmu->f().fmi3FreeInstance(inst);
}

TEST(CoSimulationSensitivities, DamperSensitivitiesMatchTheNativeRunWithinItsOwnError) {
  expect_damper_sensitivities_match_native(kDamperRig, damper_sensitivity_description(true), "cdc_damper_sens_rig");
}

TEST(CoSimulationSensitivities, FromTheEquilibriumTheyStartAtItsDerivatives) {
  // The rig starting at `initial: equilibrium`: the sensitivities start at the equilibrium's dx/dp.
  const std::string rig = scene_at_equilibrium(kDamperRig, "cdc_damper_rig_sens_at_rest.yaml");
  const std::string description = (FmuFolder::path() / "cdc_damper_sens_at_rest.yml").string();
  std::ofstream(description) << "fmu: cdc_damper_sens_at_rest\nscene: cdc_damper_rig_sens_at_rest.yaml\n"
                                "outputs: [damper.force, damper.p_rebound, damper.p_compression, damper.power]\n"
                                "sensitivities: [valve_current, pipe_length]\n";
  expect_damper_sensitivities_match_native(rig, description, "cdc_damper_sens_at_rest");
}

TEST(CoSimulationSensitivities, DamperSensitivitiesMatchCentralDifferencesOfTheFmu) {
  // The damper FMU with its stroke and rate driven from outside: d(force)/d(valve_current)
  // against (force(p + h) - force(p - h)) / 2h of two more runs, at two h; all three runs at a
  // tolerance tight enough (rtol 1e-9) that the integrator's noise over h stays small.
  auto fmu = load_fmu(damper_sensitivity_description(false), "cdc_damper_sens", "differences", true);
  const Description& desc = fmu->description();
  const fmi3ValueReference force = desc.vr("damper.force"), dforce = desc.vr("d(damper.force)/d(valve_current)"),
                           current = desc.vr("valve_current");
  const double p0 = std::stod(desc.variable("valve_current").attributes.at("start")), rtol = 1e-9;
  const double h = 0.005;
  const int steps = 100;
  fmi3Instance inst = start_cs(*fmu, 0.5, {}, rtol);
  const auto sens = column(run_cs(*fmu, inst, h, 0, steps, {dforce}, true), 0);
  fmu->f().fmi3FreeInstance(inst);
  std::vector<double> errors;
  std::vector<std::vector<double>> differences;
  for (double rel : {1e-3, 1e-4}) {
    const double dp = rel * p0;
    std::vector<std::vector<double>> y;
    for (double sign : {1.0, -1.0}) {
      fmi3Instance run = start_cs(*fmu, 0.5, {{current, p0 + sign * dp}}, rtol);
      y.push_back(column(run_cs(*fmu, run, h, 0, steps, {force}, true), 0));
      fmu->f().fmi3FreeInstance(run);
    }
    std::vector<double> cd;
    for (size_t k = 0; k < y[0].size(); ++k) cd.push_back((y[0][k] - y[1][k]) / (2 * dp));
    errors.push_back(column_error(sens, cd));
    differences.push_back(cd);
    std::printf("[measure] cdc_damper d(damper.force)/d(valve_current) against central differences, h = %.0e x p: %.3g "
                "(relative to the column's largest value)\n", rel, errors.back());
  }
  const double spread = column_error(differences[1], differences[0]);
  std::printf("[measure] cdc_damper central differences at the two h against each other: %.3g\n", spread);
  // The differences' own error is their spread between the two h (truncation at the larger,
  // the integrator's noise over the smaller): the sensitivity lies within it of both.
  for (double e : errors) EXPECT_LE(e, std::max(2.0 * spread, 1e-7));
  EXPECT_LE(*std::min_element(errors.begin(), errors.end()), 1e-4);
}

TEST(CoSimulationSensitivities, QuarterCarObjectiveSensitivitiesMatchObjectivesJson) {
  const double horizon = 2.5;
  engine::Diagram d = engine::load_scene(kQuarterCar);
  d.time.stop = horizon;
  const int steps = static_cast<int>(std::lround(horizon / d.time.output_step));
  d.set_sensitivities({d.find_parameter("valve_current")});
  const engine::RunResult native = engine::run(d, {});
  d.solver.rtol *= 1e-4;
  d.solver.atol *= 1e-4;
  const engine::RunResult reference = engine::run(d, {});

  const fs::path file = FmuFolder::path() / "quarter_car_sens.yml";
  std::ofstream(file) << "fmu: quarter_car_sens\nscene: " << kQuarterCar
                      << "\noutputs: [body_az.y, damper.force, stroke.y, tyre.force, comfort_rms, comfort_wk, "
                         "damper_power]\nsensitivities: [valve_current]\n";
  auto fmu = load_fmu(file.string(), "quarter_car_sens", "objectives", true);
  const Description& desc = fmu->description();
  const auto outputs = desc.of("output");
  fmi3Instance inst = start_cs(*fmu, horizon);
  const auto cs = run_cs(*fmu, inst, d.time.output_step, 0, steps, outputs, false);
  int compared = 0;
  for (size_t o = 0; o < reference.objectives.size(); ++o) {
    const engine::ObjectiveResult& ref = reference.objectives[o];
    const std::string name = "d(" + ref.name + ")/d(valve_current)";
    const size_t j = std::find(outputs.begin(), outputs.end(), desc.vr(name)) - outputs.begin();
    ASSERT_LT(j, outputs.size()) << name;
    const double fmu_value = cs.back()[j], nat = native.objectives[o].sensitivity[0], r = ref.sensitivity[0];
    std::printf("[measure] quarter_car_cdc %s: FMU %.10g, native %.10g, reference %.10g\n", name.c_str(), fmu_value, nat, r);
    // As for the objectives' values: within 10 times the native run's own error.
    EXPECT_LE(std::fabs(fmu_value - r), std::max(10.0 * std::fabs(nat - r), 1e-9 * std::fabs(r))) << name;
    EXPECT_LE(std::fabs(fmu_value - r), 1e-3 * std::fabs(r)) << name;
    ++compared;
  }
  EXPECT_EQ(compared, 3);
  fmu->f().fmi3FreeInstance(inst);
}

TEST(CoSimulationSensitivities, ModelExchangeWithSensitivitiesIsRefusedAtTheirLine) {
  const std::string description = damper_sensitivity_description(false);
  for (bool co_simulation : {false, true}) {
    fmi::ExportOptions o;
    o.source = description;
    o.out = (FmuFolder::path() / "refused_me.fmu").string();
    o.co_simulation = co_simulation;  // --kind me, then both
    try {
      fmi::export_fmu(o);
      ADD_FAILURE() << "exported Model Exchange with sensitivities";
    } catch (const engine::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("cdc_damper_sens.yml:7: sensitivities: "), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(o.out));
  }
  const std::string cli = std::string(DYDP_BINARY) + " fmu " + description + " --out " +
                          (FmuFolder::path() / "refused_cli.fmu").string() + " --kind me > /dev/null 2>&1";
  const int status = std::system(cli.c_str());
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2) << status;
  // An unknown direction is refused at its line.
  const fs::path bad = FmuFolder::path() / "bad_direction.yml";
  std::ofstream(bad) << "fmu: bad\nscene: " << kDamperRig << "\nsensitivities:\n  - valve_current\n  - spring_rate\n";
  fmi::ExportOptions o;
  o.source = bad.string();
  o.out = (FmuFolder::path() / "bad_direction.fmu").string();
  o.model_exchange = false;
  try {
    fmi::export_fmu(o);
    ADD_FAILURE() << "exported an unknown direction";
  } catch (const engine::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad_direction.yml:5: sensitivities: "), std::string::npos) << e.what();
  }
}

TEST(CoSimulationSensitivities, AnFmuStateRestoresTheSensitivitiesExactly) {
  auto fmu = load_fmu(damper_sensitivity_description(false), "cdc_damper_sens", "state", true);
  const Fmi3Functions& f = fmu->f();
  const auto outputs = fmu->description().of("output");
  fmi3Instance inst = start_cs(*fmu, 1.0);
  run_cs(*fmu, inst, 0.005, 0, 20, outputs, true);
  std::vector<double> at_20(outputs.size());
  ASSERT_EQ(f.fmi3GetFloat64(inst, outputs.data(), outputs.size(), at_20.data(), at_20.size()), fmi3OK);
  fmi3FMUState state = nullptr;
  ASSERT_EQ(f.fmi3GetFMUState(inst, &state), fmi3OK) << fmu->last_error();
  const auto first = run_cs(*fmu, inst, 0.005, 20, 40, outputs, true);
  ASSERT_EQ(f.fmi3SetFMUState(inst, state), fmi3OK) << fmu->last_error();
  std::vector<double> restored(outputs.size());
  ASSERT_EQ(f.fmi3GetFloat64(inst, outputs.data(), outputs.size(), restored.data(), restored.size()), fmi3OK);
  EXPECT_EQ(restored, at_20);  // the sensitivity outputs among them, to the last bit
  EXPECT_EQ(run_cs(*fmu, inst, 0.005, 20, 40, outputs, true), first);

  // Serialised and deserialised into a new instance: the same again.
  size_t size = 0;
  ASSERT_EQ(f.fmi3SerializedFMUStateSize(inst, state, &size), fmi3OK);
  std::vector<fmi3Byte> bytes(size);
  ASSERT_EQ(f.fmi3SerializeFMUState(inst, state, bytes.data(), size), fmi3OK);
  fmi3Instance other = start_cs(*fmu, 1.0);
  fmi3FMUState carried = nullptr;
  ASSERT_EQ(f.fmi3DeserializeFMUState(other, bytes.data(), size, &carried), fmi3OK) << fmu->last_error();
  ASSERT_EQ(f.fmi3SetFMUState(other, carried), fmi3OK);
  ASSERT_EQ(f.fmi3GetFloat64(other, outputs.data(), outputs.size(), restored.data(), restored.size()), fmi3OK);
  EXPECT_EQ(restored, at_20);
  EXPECT_EQ(run_cs(*fmu, other, 0.005, 20, 40, outputs, true), first);
  // A byte string cut short of its sensitivities is refused.
  fmi3FMUState bad = nullptr;
  EXPECT_EQ(f.fmi3DeserializeFMUState(inst, bytes.data(), size - 8, &bad), fmi3Error);
  f.fmi3FreeFMUState(inst, &state);
  f.fmi3FreeInstance(other);
  f.fmi3FreeInstance(inst);
}

}  // namespace
}  // namespace dydp::test
