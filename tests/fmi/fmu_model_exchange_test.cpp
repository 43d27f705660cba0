// Model Exchange through the FMI 3.0 calling sequence (dlopen, instantiate, initialise, event
// and continuous-time modes): the FMU's outputs over a run against the native diagram under the
// same integrator, and fmi3GetDirectionalDerivative / fmi3GetAdjointDerivative against the
// native linearisation (the blocks' tangents), central differences and each other.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <random>

#include "engine/evaluation/evaluator.hpp"
#include "engine/framework/diagram.hpp"
#include "engine/linear/linearization.hpp"
#include "engine/linear/signal_lookup.hpp"
#include "engine/studies/initial_equilibrium.hpp"
#include "tests/fmi/fmu_fixture.hpp"

namespace dydp::test {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

/// A diagram's right-hand side with its Jacobian and outputs, at (t, x).
struct Rhs {
  virtual ~Rhs() = default;
  virtual void evaluate(double t, const VectorXd& x, VectorXd& f, MatrixXd& jac) = 0;
  virtual std::vector<double> outputs(double t, const VectorXd& x) = 0;
};

/// The linearly implicit Euler scheme x+ = x + h (I - h J)^-1 f(t, x): L-stable, one linear
/// solve per step and no iteration, so that two right-hand sides that agree give the same
/// solution to rounding. Returns the outputs at every step (row per step) and leaves x.
std::vector<std::vector<double>> integrate(Rhs& rhs, VectorXd& x, double t0, double h, int steps) {
  std::vector<std::vector<double>> out;
  const int n = static_cast<int>(x.size());
  VectorXd f(n);
  MatrixXd jac(n, n);
  for (int k = 0; k < steps; ++k) {
    const double t = t0 + k * h;
    rhs.evaluate(t, x, f, jac);
    x += h * (MatrixXd::Identity(n, n) - h * jac).partialPivLu().solve(f);
    out.push_back(rhs.outputs(t + h, x));
  }
  return out;
}

/// The FMU through its Model Exchange functions; inputs(t) gives the inputs' values.
class FmuRhs : public Rhs {
 public:
  FmuRhs(Fmu& fmu, fmi3Instance inst, std::function<std::vector<double>(double)> inputs)
      : fmu_(fmu), f_(fmu.f()), inst_(inst), inputs_(std::move(inputs)) {
    const Description& d = fmu.description();
    states_ = d.of("state");
    derivatives_ = d.of("derivative");
    outputs_ = d.of("output");
    input_vrs_ = d.of("input");
  }
  void set(double t, const VectorXd& x) {
    ASSERT_EQ(f_.fmi3SetTime(inst_, t), fmi3OK) << fmu_.last_error();
    ASSERT_EQ(f_.fmi3SetContinuousStates(inst_, x.data(), x.size()), fmi3OK) << fmu_.last_error();
    if (!input_vrs_.empty()) {
      const std::vector<double> u = inputs_(t);
      ASSERT_EQ(f_.fmi3SetFloat64(inst_, input_vrs_.data(), input_vrs_.size(), u.data(), u.size()), fmi3OK);
    }
  }
  void evaluate(double t, const VectorXd& x, VectorXd& f, MatrixXd& jac) override {
    set(t, x);
    ASSERT_EQ(f_.fmi3GetContinuousStateDerivatives(inst_, f.data(), f.size()), fmi3OK) << fmu_.last_error();
    for (size_t j = 0; j < states_.size(); ++j) {
      const double one = 1.0;
      ASSERT_EQ(f_.fmi3GetDirectionalDerivative(inst_, derivatives_.data(), derivatives_.size(), &states_[j], 1, &one, 1,
                                                jac.col(j).data(), jac.rows()),
                fmi3OK)
          << fmu_.last_error();
    }
  }
  std::vector<double> outputs(double t, const VectorXd& x) override {
    set(t, x);
    std::vector<double> y(outputs_.size());
    EXPECT_EQ(f_.fmi3GetFloat64(inst_, outputs_.data(), outputs_.size(), y.data(), y.size()), fmi3OK) << fmu_.last_error();
    return y;
  }

 private:
  Fmu& fmu_;
  const Fmi3Functions& f_;
  fmi3Instance inst_;
  std::function<std::vector<double>(double)> inputs_;
  std::vector<fmi3ValueReference> states_, derivatives_, outputs_, input_vrs_;
};

/// The native diagram of the FMU's scene through the engine's evaluator: the blocks' states,
/// then the quadratures, as the FMU orders them; outputs by their signal names.
class NativeRhs : public Rhs {
 public:
  NativeRhs(const std::string& scene, const std::vector<std::string>& output_names)
      : d_(engine::load_scene(scene)), ev_(d_, false) {
    for (const std::string& name : output_names) offsets_.push_back(engine::signal_offsets(d_, name, "test").at(0));
  }
  VectorXd initial(double t0) {
    VectorXd x = VectorXd::Zero(d_.num_states + d_.num_quadratures);
    std::vector<double> x0(std::max(d_.num_states, 1));
    ev_.set_segment_start(t0);
    ev_.initial_state(t0, x0.data());
    for (int i = 0; i < d_.num_states; ++i) x[i] = x0[i];
    return x;
  }
  void evaluate(double t, const VectorXd& x, VectorXd& f, MatrixXd& jac) override {
    const int nx = d_.num_states, nq = d_.num_quadratures;
    ev_.derivatives(t, x.data(), f.data());
    if (nq) ev_.quadratures(t, x.data(), f.data() + nx);
    MatrixXd eye = MatrixXd::Identity(nx, nx), dxdot(nx, nx), dqdot(std::max(nq, 1), nx);
    ev_.tangents(t, x.data(), nx, {eye.data(), nx}, false, {dxdot.data(), nx}, {nq ? dqdot.data() : nullptr, nq});
    jac.setZero();
    jac.topLeftCorner(nx, nx) = dxdot;
    if (nq) jac.bottomLeftCorner(nq, nx) = dqdot.topRows(nq);
  }
  std::vector<double> outputs(double t, const VectorXd& x) override {
    ev_.outputs(t, x.data());
    std::vector<double> y;
    for (int o : offsets_) y.push_back(ev_.signals()[o]);
    return y;
  }
  engine::Diagram& diagram() { return d_; }

 private:
  engine::Diagram d_;
  engine::Evaluator ev_;
  std::vector<int> offsets_;
};

/// Instantiation up to Continuous-Time Mode, as an importer's ME loop does it.
fmi3Instance start_me(Fmu& fmu, double stop) {
  const Fmi3Functions& f = fmu.f();
  fmi3Instance inst = fmu.instantiate_me();
  EXPECT_NE(inst, nullptr) << fmu.last_error();
  EXPECT_EQ(f.fmi3EnterInitializationMode(inst, false, 0.0, 0.0, true, stop), fmi3OK) << fmu.last_error();
  EXPECT_EQ(f.fmi3ExitInitializationMode(inst), fmi3OK) << fmu.last_error();
  fmi3Boolean update = false, terminate = false, nominals = false, values = false, defined = false;
  fmi3Float64 next = 0.0;
  EXPECT_EQ(f.fmi3UpdateDiscreteStates(inst, &update, &terminate, &nominals, &values, &defined, &next), fmi3OK);
  EXPECT_EQ(f.fmi3EnterContinuousTimeMode(inst), fmi3OK);
  return inst;
}

std::vector<std::string> output_names(const Fmu& fmu) {
  std::vector<std::string> names;
  for (fmi3ValueReference vr : fmu.description().of("output"))
    for (const DescribedVariable& v : fmu.description().variables)
      if (v.value_reference == vr) names.push_back(v.name);
  return names;
}

struct Case {
  std::string source, scene, name;
  bool inputs;
  double h;
  int steps;
};

class ModelExchange : public ::testing::TestWithParam<Case> {};

std::vector<double> rig_inputs(double t) { return {rig_stroke(t), rig_stroke_rate(t)}; }

TEST_P(ModelExchange, OutputsOverARunEqualTheNativeDiagramUnderTheSameIntegrator) {
  const Case c = GetParam();
  auto fmu = load_fmu(c.source, c.name, "run");
  const double stop = c.h * c.steps;
  fmi3Instance inst = start_me(*fmu, stop);
  size_t n = 0;
  ASSERT_EQ(fmu->f().fmi3GetNumberOfContinuousStates(inst, &n), fmi3OK);
  VectorXd x_fmu(n);
  ASSERT_EQ(fmu->f().fmi3GetContinuousStates(inst, x_fmu.data(), n), fmi3OK);

  const std::vector<std::string> names = output_names(*fmu);
  // The quarter car's objectives (no signals) are compared in the Co-Simulation test.
  std::vector<std::string> signals;
  for (const std::string& s : names)
    if (s.find('.') != std::string::npos) signals.push_back(s);
  NativeRhs native(c.scene, signals);
  VectorXd x_native = native.initial(0.0);
  ASSERT_EQ(x_native.size(), static_cast<long>(n));
  for (size_t i = 0; i < n; ++i) EXPECT_EQ(x_fmu[i], x_native[i]) << "initial state " << i;

  FmuRhs through_fmu(*fmu, inst, rig_inputs);
  const std::clock_t t0 = std::clock();
  const auto y_fmu = integrate(through_fmu, x_fmu, 0.0, c.h, c.steps);
  const std::clock_t t1 = std::clock();
  const auto y_native = integrate(native, x_native, 0.0, c.h, c.steps);
  const std::clock_t t2 = std::clock();
  std::printf("[measure] %s ME: CPU per step (derivatives, %ld directional derivatives, outputs) %.3g ms through the FMU, "
              "%.3g ms native\n", c.name.c_str(), static_cast<long>(n), 1e3 * (t1 - t0) / CLOCKS_PER_SEC / c.steps,
              1e3 * (t2 - t1) / CLOCKS_PER_SEC / c.steps);
  for (size_t j = 0; j < signals.size(); ++j) {
    std::vector<double> a, b;
    const size_t col = std::find(names.begin(), names.end(), signals[j]) - names.begin();
    for (size_t k = 0; k < y_fmu.size(); ++k) a.push_back(y_fmu[k][col]), b.push_back(y_native[k][j]);
    const double e = column_error(a, b);
    EXPECT_LE(e, 1e-8) << signals[j];
    std::printf("[measure] %s ME %s: FMU against native, %d steps of %g s: %.2g (relative to the column's largest value)\n",
                c.name.c_str(), signals[j].c_str(), c.steps, c.h, e);
  }
  // The run went somewhere: the states moved from their start.
  EXPECT_GT((x_fmu - native.initial(0.0)).norm(), 0.0);
  for (size_t i = 0; i < n; ++i) EXPECT_NEAR(x_fmu[i], x_native[i], 1e-8 * std::max(1.0, std::fabs(x_native[i]))) << i;
  fmu->f().fmi3FreeInstance(inst);
}

TEST_P(ModelExchange, DirectionalAndAdjointDerivativesAreTheTangents) {
  const Case c = GetParam();
  auto fmu = load_fmu(c.source, c.name, "derivatives");
  const Fmi3Functions& f = fmu->f();
  const Description& desc = fmu->description();
  // An operating point away from the start: a short run of the ME integrator.
  const int steps = c.steps / 4;
  fmi3Instance inst = start_me(*fmu, c.h * steps);
  size_t n = 0;
  f.fmi3GetNumberOfContinuousStates(inst, &n);
  VectorXd x(n);
  f.fmi3GetContinuousStates(inst, x.data(), n);
  FmuRhs through_fmu(*fmu, inst, rig_inputs);
  integrate(through_fmu, x, 0.0, c.h, steps);
  const double t = c.h * steps;
  through_fmu.set(t, x);

  const auto states = desc.of("state"), derivatives = desc.of("derivative"), inputs = desc.of("input");
  std::vector<fmi3ValueReference> outputs;  // signals: the objectives' rms is not differentiable at 0
  for (fmi3ValueReference vr : desc.of("output"))
    for (const DescribedVariable& v : desc.variables)
      if (v.value_reference == vr && v.name.find('.') != std::string::npos) outputs.push_back(vr);
  std::vector<fmi3ValueReference> knowns = states, unknowns = derivatives;
  knowns.insert(knowns.end(), inputs.begin(), inputs.end());
  unknowns.insert(unknowns.end(), outputs.begin(), outputs.end());
  const size_t nk = knowns.size(), nu = unknowns.size();

  // J column by column from fmi3GetDirectionalDerivative.
  MatrixXd jac(nu, nk);
  for (size_t j = 0; j < nk; ++j) {
    const double one = 1.0;
    ASSERT_EQ(f.fmi3GetDirectionalDerivative(inst, unknowns.data(), nu, &knowns[j], 1, &one, 1, jac.col(j).data(), nu), fmi3OK)
        << fmu->last_error();
  }

  // Typical magnitudes of the knowns (states: their nominals; inputs: 1) and, per unknown, the
  // largest change a typical move of one known makes: entries are compared relative to that,
  // so an output's row is held to its own size, not to a pressure derivative's.
  std::vector<double> nominal(n);
  f.fmi3GetNominalsOfContinuousStates(inst, nominal.data(), n);
  VectorXd typical(nk);
  for (size_t j = 0; j < nk; ++j) typical[j] = j < n ? nominal[j] : 1.0;
  auto row_error = [&](const MatrixXd& a, const MatrixXd& b, const std::vector<bool>& compared, std::string& worst) {
    double largest = 0.0;
    for (size_t i = 0; i < nu; ++i) {
      const double row = std::max((b.row(i).cwiseAbs().transpose().cwiseProduct(typical)).maxCoeff(), 1e-300);
      for (size_t j = 0; j < nk; ++j) {
        if (!compared[i * nk + j]) continue;
        const double e = std::fabs(a(i, j) - b(i, j)) * typical[j] / row;
        if (e > largest) largest = e, worst = desc.variables[unknowns[i]].name + " / " + desc.variables[knowns[j]].name;
      }
    }
    return largest;
  };

  // 1. Against the native linearisation (A, B, C, D from the blocks' tangents, engine/linear).
  engine::Diagram d = engine::load_scene(c.scene);
  const int nx = d.num_states;
  std::vector<std::string> input_names, out_names;
  for (fmi3ValueReference vr : inputs) input_names.push_back(desc.variables[vr].name);
  for (fmi3ValueReference vr : outputs) out_names.push_back(desc.variables[vr].name);
  const std::vector<double> xb(x.data(), x.data() + nx);
  const engine::LinearModel lin = engine::linearize(d, t, xb, input_names, out_names);
  MatrixXd native = MatrixXd::Zero(nu, nk);
  const size_t ni = inputs.size(), no = outputs.size();
  native.block(0, 0, nx, nx) = lin.A;
  if (ni) native.block(0, n, nx, ni) = lin.B;
  native.block(n, 0, no, nx) = lin.C;
  if (ni) native.block(n, n, no, ni) = lin.D;
  std::vector<bool> in_linearisation(nu * nk, true), everything(nu * nk, true);
  for (size_t i = 0; i < nu; ++i)
    for (size_t j = 0; j < nk; ++j)  // the integrals and their rates are not in A, B, C, D
      in_linearisation[i * nk + j] = !((j >= static_cast<size_t>(nx) && j < n) || (i >= static_cast<size_t>(nx) && i < n));
  std::string worst;
  const double e_native = row_error(jac, native, in_linearisation, worst);
  EXPECT_LE(e_native, 1e-12) << worst;

  // 2. Against central differences of fmi3GetContinuousStateDerivatives and fmi3GetFloat64.
  auto unknowns_at = [&](const VectorXd& xs, const std::vector<double>& u) {
    VectorXd values(nu);
    EXPECT_EQ(f.fmi3SetContinuousStates(inst, xs.data(), n), fmi3OK);
    if (ni) {
      EXPECT_EQ(f.fmi3SetFloat64(inst, inputs.data(), ni, u.data(), ni), fmi3OK);
    }
    EXPECT_EQ(f.fmi3GetContinuousStateDerivatives(inst, values.data(), n), fmi3OK) << fmu->last_error();
    EXPECT_EQ(f.fmi3GetFloat64(inst, outputs.data(), no, values.data() + n, no), fmi3OK);
    return values;
  };
  const std::vector<double> u0 = ni ? rig_inputs(t) : std::vector<double>{};
  MatrixXd fd(nu, nk);
  for (size_t j = 0; j < nk; ++j) {
    VectorXd xp = x, xm = x;
    std::vector<double> up = u0, um = u0;
    double h;
    if (j < n) {
      h = 1e-6 * nominal[j];
      xp[j] += h, xm[j] -= h;
    } else {
      h = 1e-6 * std::max(std::fabs(u0[j - n]), 1e-3);
      up[j - n] += h, um[j - n] -= h;
    }
    fd.col(j) = (unknowns_at(xp, up) - unknowns_at(xm, um)) / (2 * h);
  }
  unknowns_at(x, u0);
  const double e_fd = row_error(fd, jac, everything, worst);
  EXPECT_LE(e_fd, 1e-6) << worst;

  // 3. The adjoint: <w, J v> = <J^T w, v> for random v (scaled by the knowns' magnitudes) and
  // w (scaled by each row's size, so that every row counts).
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  VectorXd v(nk), w(nu), jv(nu), jtw(nk);
  for (size_t j = 0; j < nk; ++j) v[j] = uniform(rng) * typical[j];
  for (size_t i = 0; i < nu; ++i)
    w[i] = uniform(rng) / std::max((jac.row(i).cwiseAbs().transpose().cwiseProduct(typical)).maxCoeff(), 1e-300);
  ASSERT_EQ(f.fmi3GetDirectionalDerivative(inst, unknowns.data(), nu, knowns.data(), nk, v.data(), nk, jv.data(), nu), fmi3OK);
  ASSERT_EQ(f.fmi3GetAdjointDerivative(inst, unknowns.data(), nu, knowns.data(), nk, w.data(), nu, jtw.data(), nk), fmi3OK);
  EXPECT_LE((jv - jac * v).cwiseAbs().maxCoeff(), 1e-12 * (jac.cwiseAbs() * v.cwiseAbs()).maxCoeff());
  const double lhs = w.dot(jv), rhs = jtw.dot(v);
  const double e_dot = std::fabs(lhs - rhs) / (w.cwiseAbs().dot((jac.cwiseAbs() * v.cwiseAbs())));
  EXPECT_LE(e_dot, 1e-12);
  EXPECT_GT(std::fabs(lhs), 0.0);
  std::printf("[measure] %s at t = %g s, %zu x %zu: directional derivatives against the native linearisation %.2g, "
              "against central differences %.2g (relative to each row), <w, Jv> - <J^T w, v> %.2g (relative)\n",
              c.name.c_str(), t, nu, nk, e_native, e_fd, e_dot);
  f.fmi3FreeInstance(inst);
}

TEST(ModelExchangeEquilibrium, ASceneThatStartsAtItsEquilibriumStartsThereWithTheImportersInputs) {
  // The CDC damper's FMU with its rig scene starting at `initial: equilibrium`: the hydraulics'
  // steady state at the stroke and stroke rate the importer sets before initialisation ends.
  const std::string rig = scene_at_equilibrium(kDamperRig, "cdc_damper_rig_at_rest.yaml");
  const std::string description = (FmuFolder::path() / "cdc_damper_at_rest.yml").string();
  std::ofstream(description) << "fmu: cdc_damper_at_rest\nscene: cdc_damper_rig_at_rest.yaml\n"
                                "inputs: [stroke.y, stroke_rate.y]\noutputs: [damper.force]\n"
                                "parameters: [valve_current, pipe_length]\n";
  auto fmu = load_fmu(description, "cdc_damper_at_rest", "equilibrium");
  const Fmi3Functions& f = fmu->f();
  fmi3Instance inst = fmu->instantiate_me();
  ASSERT_NE(inst, nullptr) << fmu->last_error();
  ASSERT_EQ(f.fmi3EnterInitializationMode(inst, false, 0.0, 0.0, true, 1.0), fmi3OK) << fmu->last_error();
  const std::vector<fmi3ValueReference> inputs = fmu->description().of("input");
  ASSERT_EQ(inputs.size(), 2u);
  const std::vector<double> u = {0.004, 0.1};  // [m], [m/s]
  ASSERT_EQ(f.fmi3SetFloat64(inst, inputs.data(), u.size(), u.data(), u.size()), fmi3OK) << fmu->last_error();
  ASSERT_EQ(f.fmi3ExitInitializationMode(inst), fmi3OK) << fmu->last_error();
  size_t n = 0;
  ASSERT_EQ(f.fmi3GetNumberOfContinuousStates(inst, &n), fmi3OK);
  VectorXd x(n), xdot(n), nominal(n);
  ASSERT_EQ(f.fmi3GetContinuousStates(inst, x.data(), n), fmi3OK);
  ASSERT_EQ(f.fmi3GetContinuousStateDerivatives(inst, xdot.data(), n), fmi3OK);
  ASSERT_EQ(f.fmi3GetNominalsOfContinuousStates(inst, nominal.data(), n), fmi3OK);

  // dydp's own equilibrium with the same inputs held, and the one at the scene's own inputs.
  engine::Diagram d = engine::load_scene(rig);
  std::vector<std::pair<int, double>> held;
  for (size_t j = 0; j < inputs.size(); ++j)
    held.emplace_back(engine::signal_offsets(d, fmu->description().variables[inputs[j]].name, "test").at(0), u[j]);
  ASSERT_TRUE(engine::start_at_equilibrium(d, 0.0, held).has_value());
  const std::vector<double> at_inputs = d.start.x;
  ASSERT_TRUE(engine::start_at_equilibrium(d, 0.0, {}).has_value());
  const std::vector<double> at_scene_inputs = d.start.x;
  ASSERT_EQ(at_inputs.size() + static_cast<size_t>(d.num_quadratures), n);
  double moved = 0.0, rest = 0.0;
  for (int i = 0; i < d.num_states; ++i) {
    EXPECT_NEAR(x[i], at_inputs[i], 1e-12 * nominal[i]) << "state " << i;
    moved = std::max(moved, std::fabs(at_inputs[i] - at_scene_inputs[i]) / nominal[i]);
    rest = std::max(rest, std::fabs(xdot[i]) / nominal[i]);
  }
  EXPECT_GT(moved, 1e-3);  // the importer's inputs, not the scene's, set the equilibrium
  EXPECT_LT(rest, 1e-8);   // nominal units per second: the FMU's state derivatives vanish there
  std::printf("equilibrium: %d states, %.3g nominal units from the one at the scene's inputs, largest rate %.2g /s\n",
              d.num_states, moved, rest);
  f.fmi3FreeInstance(inst);
}

TEST(ModelExchangeParameters, DerivativesAlongTunableParametersAreCentralDifferences) {
  auto fmu = load_fmu(kDamper, "cdc_damper", "parameters");
  const Fmi3Functions& f = fmu->f();
  const Description& desc = fmu->description();
  fmi3Instance inst = start_me(*fmu, 0.1);
  FmuRhs through_fmu(*fmu, inst, rig_inputs);
  size_t n = 0;
  f.fmi3GetNumberOfContinuousStates(inst, &n);
  VectorXd x(n);
  f.fmi3GetContinuousStates(inst, x.data(), n);
  integrate(through_fmu, x, 0.0, 2e-4, 100);
  through_fmu.set(0.02, x);
  std::vector<fmi3ValueReference> unknowns = desc.of("derivative");
  for (fmi3ValueReference vr : desc.of("output")) unknowns.push_back(vr);
  ASSERT_EQ(f.fmi3EnterEventMode(inst), fmi3OK);  // tunable parameters change in Event Mode
  for (const char* name : {"valve_current", "pipe_length"}) {
    const fmi3ValueReference p = desc.vr(name);
    std::vector<double> exact(unknowns.size()), plus(unknowns.size()), minus(unknowns.size());
    const double one = 1.0;
    ASSERT_EQ(f.fmi3GetDirectionalDerivative(inst, unknowns.data(), unknowns.size(), &p, 1, &one, 1, exact.data(), exact.size()), fmi3OK)
        << fmu->last_error();
    double p0 = 0.0;
    f.fmi3GetFloat64(inst, &p, 1, &p0, 1);
    const double h = 1e-6 * p0;
    auto values = [&](double value, std::vector<double>& out) {
      ASSERT_EQ(f.fmi3SetFloat64(inst, &p, 1, &value, 1), fmi3OK) << fmu->last_error();
      ASSERT_EQ(f.fmi3GetContinuousStateDerivatives(inst, out.data(), n), fmi3OK);
      ASSERT_EQ(f.fmi3GetFloat64(inst, unknowns.data() + n, unknowns.size() - n, out.data() + n, unknowns.size() - n), fmi3OK);
    };
    std::vector<double> back(unknowns.size());
    values(p0 + h, plus);
    values(p0 - h, minus);
    values(p0, back);
    double scale = 1e-300, err = 0.0;
    for (size_t i = 0; i < unknowns.size(); ++i) {
      scale = std::max(scale, std::fabs(exact[i]));
      err = std::max(err, std::fabs((plus[i] - minus[i]) / (2 * h) - exact[i]));
    }
    EXPECT_LE(err, 1e-6 * scale) << name;
    EXPECT_GT(scale, 1e-300) << name << ": the parameter moves something";
  }
  f.fmi3FreeInstance(inst);
}

INSTANTIATE_TEST_SUITE_P(
    Fmus, ModelExchange,
    ::testing::Values(Case{kQuarterCar, kQuarterCar, "quarter_car_cdc", false, 1e-4, 400},
                      Case{kDamper, kDamperRig, "cdc_damper", true, 2e-4, 400}),
    [](const ::testing::TestParamInfo<Case>& info) { return info.param.name; });

}  // namespace
}  // namespace dydp::test
