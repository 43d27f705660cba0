// Co-Simulation through the FMI 3.0 calling sequence: fmi3DoStep (CVODES BDF inside the FMU)
// over the output grid against the native run (engine::run, CVODES BDF with dydp's own
// settings) at the same tolerances, both measured against a converged native reference; and
// FMU states (get, set, serialise) rolling a run back exactly.
#include <gtest/gtest.h>

#include <ctime>

#include "engine/analysis/run.hpp"
#include "engine/framework/diagram.hpp"
#include "tests/fmi/fmu_fixture.hpp"

namespace dydp::test {
namespace {

struct CsRun {
  std::vector<std::vector<double>> outputs;  ///< per output time, the FMU's outputs
  double cpu_per_step = 0.0;
};

fmi3Instance start_cs(Fmu& fmu, double stop) {
  const Fmi3Functions& f = fmu.f();
  fmi3Instance inst = fmu.instantiate_cs();
  EXPECT_NE(inst, nullptr) << fmu.last_error();
  EXPECT_EQ(f.fmi3EnterInitializationMode(inst, false, 0.0, 0.0, true, stop), fmi3OK) << fmu.last_error();
  EXPECT_EQ(f.fmi3ExitInitializationMode(inst), fmi3OK) << fmu.last_error();
  return inst;
}

CsRun run_cs(Fmu& fmu, fmi3Instance inst, double h, int steps, const std::vector<fmi3ValueReference>& outputs) {
  const Fmi3Functions& f = fmu.f();
  CsRun r;
  std::vector<double> y(outputs.size());
  EXPECT_EQ(f.fmi3GetFloat64(inst, outputs.data(), outputs.size(), y.data(), y.size()), fmi3OK);
  r.outputs.push_back(y);
  const std::clock_t start = std::clock();
  for (int k = 0; k < steps; ++k) {
    fmi3Boolean event = false, terminate = false, early = false;
    fmi3Float64 last = 0.0;
    const double t = k * h;
    EXPECT_EQ(f.fmi3DoStep(inst, t, (k + 1) * h - t, true, &event, &terminate, &early, &last), fmi3OK) << fmu.last_error();
    EXPECT_EQ(f.fmi3GetFloat64(inst, outputs.data(), outputs.size(), y.data(), y.size()), fmi3OK);
    r.outputs.push_back(y);
  }
  r.cpu_per_step = static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC / steps;
  return r;
}

struct Case {
  std::string scene, name;
  double horizon;
};

class CoSimulation : public ::testing::TestWithParam<Case> {};

TEST_P(CoSimulation, OutputsOverARunMatchTheNativeRunWithinItsOwnError) {
  const Case c = GetParam();
  // The native run at the scene's tolerances, and a reference 10^4 times tighter.
  engine::Diagram d = engine::load_scene(c.scene);
  d.time.stop = c.horizon;
  const double h = d.time.output_step;
  const int steps = static_cast<int>(std::lround(c.horizon / h));
  engine::RunOptions no_sens;
  no_sens.sensitivities = false;
  const engine::RunResult native = engine::run(d, no_sens);
  d.solver.rtol *= 1e-4;
  d.solver.atol *= 1e-4;
  const engine::RunResult reference = engine::run(d, no_sens);

  auto fmu = load_fmu(c.scene, c.name, "cs");
  fmi3Instance inst = start_cs(*fmu, c.horizon);
  const Description& desc = fmu->description();
  const auto outputs = desc.of("output");
  const CsRun cs = run_cs(*fmu, inst, h, steps, outputs);
  ASSERT_EQ(cs.outputs.size(), reference.t.size());

  double cs_error = 0.0, native_error = 0.0;
  int compared = 0;
  for (size_t j = 0; j < outputs.size(); ++j) {
    const std::string& name = desc.variables[outputs[j]].name;
    const int i = reference.signal_index(name);
    if (i < 0) continue;  // an objective: below
    std::vector<double> a, b, r;
    for (size_t k = 0; k < reference.t.size(); ++k)
      a.push_back(cs.outputs[k][j]), b.push_back(native.value(k, i)), r.push_back(reference.value(k, i));
    const double e_cs = column_error(a, r), e_native = column_error(b, r);
    cs_error = std::max(cs_error, e_cs), native_error = std::max(native_error, e_native);
    ++compared;
    std::printf("[measure] %s %s: CS error %.3g, native error %.3g (relative to the column's largest value), "
                "CS - native %.3g\n", c.name.c_str(), name.c_str(), e_cs, e_native, column_error(a, b));
  }
  EXPECT_GT(compared, 0);
  // Both integrate the same equations with CVODES BDF at the same rtol and atol: the FMU's
  // integrator is held to the native run's own error against the converged reference, with a
  // factor of 10 for the different step sequences (restarts at communication points, another
  // Newton matrix refresh); and to 1e-3 outright (the scene's claims are at 1e-2).
  EXPECT_LE(cs_error, std::max(10.0 * native_error, 1e-9));
  EXPECT_LE(cs_error, 1e-3);
  for (size_t j = 0; j < outputs.size(); ++j) {
    const std::string& name = desc.variables[outputs[j]].name;
    for (const engine::ObjectiveResult& o : reference.objectives) {
      if (o.name != name) continue;
      const auto& nat = native.objectives[&o - reference.objectives.data()];
      const double e_cs = std::fabs(cs.outputs.back()[j] - o.value), e_native = std::fabs(nat.value - o.value);
      std::printf("[measure] %s objective %s: FMU %.10g, native %.10g, reference %.10g\n", c.name.c_str(), name.c_str(),
                  cs.outputs.back()[j], nat.value, o.value);
      EXPECT_LE(e_cs, std::max(10.0 * e_native, 1e-9 * std::fabs(o.value))) << name;
    }
  }
  std::printf("[measure] %s: CPU per fmi3DoStep of %.4g s: %.3g ms; native run %.3g ms per output step\n", c.name.c_str(), h,
              1e3 * cs.cpu_per_step, 1e3 * native.stats.cpu_seconds / steps);
  fmu->f().fmi3FreeInstance(inst);
}

INSTANTIATE_TEST_SUITE_P(Fmus, CoSimulation,
                         ::testing::Values(Case{kQuarterCar, "quarter_car_cdc", 2.5}, Case{kDamperRig, "cdc_damper_rig", 1.0}),
                         [](const ::testing::TestParamInfo<Case>& info) { return info.param.name; });

/// Steps the damper FMU (stroke and rate from the rig's sines) from step k0 to k1, returning
/// its outputs after each step.
std::vector<std::vector<double>> damper_steps(Fmu& fmu, fmi3Instance inst, int k0, int k1) {
  const Fmi3Functions& f = fmu.f();
  const auto inputs = fmu.description().of("input"), outputs = fmu.description().of("output");
  const double h = 0.005;
  std::vector<std::vector<double>> out;
  for (int k = k0; k < k1; ++k) {
    const double t = k * h;
    const double u[2] = {rig_stroke(t), rig_stroke_rate(t)};
    EXPECT_EQ(f.fmi3SetFloat64(inst, inputs.data(), 2, u, 2), fmi3OK) << fmu.last_error();
    fmi3Boolean event = false, terminate = false, early = false;
    fmi3Float64 last = 0.0;
    EXPECT_EQ(f.fmi3DoStep(inst, t, (k + 1) * h - t, false, &event, &terminate, &early, &last), fmi3OK) << fmu.last_error();
    std::vector<double> y(outputs.size());
    EXPECT_EQ(f.fmi3GetFloat64(inst, outputs.data(), outputs.size(), y.data(), y.size()), fmi3OK);
    out.push_back(y);
  }
  return out;
}

TEST(FmuState, GetSetAndSerialisedStatesRollARunBackExactly) {
  auto fmu = load_fmu(kDamper, "cdc_damper", "state");
  const Fmi3Functions& f = fmu->f();
  fmi3Instance inst = start_cs(*fmu, 1.0);
  damper_steps(*fmu, inst, 0, 20);
  fmi3FMUState state = nullptr;
  ASSERT_EQ(f.fmi3GetFMUState(inst, &state), fmi3OK);
  ASSERT_NE(state, nullptr);
  const auto first = damper_steps(*fmu, inst, 20, 40);
  ASSERT_EQ(f.fmi3SetFMUState(inst, state), fmi3OK) << fmu->last_error();
  EXPECT_EQ(damper_steps(*fmu, inst, 20, 40), first);

  // Serialised, freed, deserialised: the same again, in this instance and in a new one.
  size_t size = 0;
  ASSERT_EQ(f.fmi3SerializedFMUStateSize(inst, state, &size), fmi3OK);
  std::vector<fmi3Byte> bytes(size);
  ASSERT_EQ(f.fmi3SerializeFMUState(inst, state, bytes.data(), size), fmi3OK);
  ASSERT_EQ(f.fmi3FreeFMUState(inst, &state), fmi3OK);
  EXPECT_EQ(state, nullptr);
  fmi3FMUState restored = nullptr;
  ASSERT_EQ(f.fmi3DeserializeFMUState(inst, bytes.data(), size, &restored), fmi3OK) << fmu->last_error();
  ASSERT_EQ(f.fmi3SetFMUState(inst, restored), fmi3OK);
  EXPECT_EQ(damper_steps(*fmu, inst, 20, 40), first);

  fmi3Instance other = start_cs(*fmu, 1.0);
  fmi3FMUState carried = nullptr;
  ASSERT_EQ(f.fmi3DeserializeFMUState(other, bytes.data(), size, &carried), fmi3OK) << fmu->last_error();
  ASSERT_EQ(f.fmi3SetFMUState(other, carried), fmi3OK);
  EXPECT_EQ(damper_steps(*fmu, other, 20, 40), first);

  // A damaged or foreign byte string is refused.
  std::vector<fmi3Byte> damaged = bytes;
  damaged[0] ^= 0xff;
  fmi3FMUState bad = nullptr;
  EXPECT_EQ(f.fmi3DeserializeFMUState(inst, damaged.data(), damaged.size(), &bad), fmi3Error);
  EXPECT_EQ(f.fmi3DeserializeFMUState(inst, bytes.data(), size - 1, &bad), fmi3Error);
  EXPECT_EQ(bad, nullptr);
  f.fmi3FreeInstance(other);
  f.fmi3FreeInstance(inst);
}

}  // namespace
}  // namespace dydp::test
