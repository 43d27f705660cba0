// The cases of every registered block type: where its states, inputs and parameters are drawn
// (inside the block's domain, across its corners), shared by the registry's tangent check and its
// adjoint (dot-product) check, so that a new block type gets one table entry for both.
#pragma once

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "generated_models/registry.hpp"
#include "tests/blocks/scene_helpers.hpp"
#include "tests/blocks/tangent_check.hpp"
#include "tests/symbolic/mbs/oracle_compare.hpp"

namespace dydp::test {

using Settings = std::map<std::string, std::vector<std::string>>;

inline BlockCase make_case(const std::string& type, Settings settings = {}, std::map<std::string, double> params = {},
                    std::vector<std::vector<Range>> inputs = {}) {
  BlockCase c;
  c.type = type;
  c.settings = std::move(settings);
  c.params = std::move(params);
  c.inputs = std::move(inputs);
  return c;
}

// Sources read time only: a few times, one sample each (before and after any corner).
inline BlockCase source_case(const std::string& type, std::map<std::string, double> params, std::vector<double> times,
                      Settings settings = {}) {
  BlockCase c = make_case(type, std::move(settings), std::move(params));
  c.times = std::move(times);
  c.samples = 1;
  return c;
}

// Objectives: inside and outside their window; psi from quadratures or output samples.
inline BlockCase objective_case(const std::string& type, Settings settings = {}) {
  BlockCase c = make_case(type, std::move(settings), {}, {{{0.3, 1.0}}});
  c.times = {0.1, 0.37, 0.7};
  c.samples = 2;
  return c;
}

// A generated multibody model as a block: independent coordinates near the model's assembly
// configuration (closed loops stay closable), velocities of order one, loads of order 500 N,
// driven joints near their initial values. Each evaluation is a whole solve of the model, so:
// one sample and fewer steps.
inline BlockCase multibody_case(const std::string& type, const std::string& model) {
  const mbs::GeneratedModel* g = generated::find_model(model);
  if (!g) throw std::runtime_error("no generated model " + model);
  BlockCase c;
  c.type = type;
  if (type == "multibody") c.settings = {{"model", {model}}};
  for (int i = 0; i < g->independent_count; ++i) c.states.push_back({g->initial_q[g->independent[i]], 0.05});
  for (int i = 0; i < g->independent_count; ++i) c.states.push_back({0.0, 1.0});
  for (int k = 0; k < g->loads; ++k) c.inputs.emplace_back(g->load_widths[k], Range{0.0, 500.0});
  for (int i = 0; i < g->driven_count; ++i) {
    c.inputs.push_back({{g->initial_q[g->driven[i]], 0.05}});
    c.inputs.push_back({{0.0, 1.0}});
    c.inputs.push_back({{0.0, 1.0}});
  }
  c.samples = 1;
  c.times = {0.0};
  c.steps = {1e-3, 1e-4, 1e-5, 1e-6};
  return c;
}

// Condition number of a model's mass matrix at its assembly configuration, default parameters.
inline double mass_condition(const mbs::GeneratedModel& g) {
  mbs::testing::Args a;
  a.q = Eigen::Map<const Eigen::VectorXd>(g.initial_q, g.n);
  a.qd = a.qdd = Eigen::VectorXd::Zero(g.n);
  a.lam = Eigen::VectorXd::Zero(std::max(g.m, 1));
  a.inp = Eigen::VectorXd::Zero(std::max(g.inputs, 1));
  a.p = Eigen::VectorXd::Zero(std::max(g.parameters, 1));
  for (int i = 0; i < g.parameters; ++i) a.p[i] = g.parameter_values[i];
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(mbs::testing::generated_mass(g, a));
  return svd.singularValues()(0) / svd.singularValues()(g.n - 1);
}

inline const Settings kProfile = {{"bumps", {"3.0", "0.5", "0.04"}},
                           {"potholes", {"7.0", "0.6", "0.03"}},
                           {"steps", {"12.0", "0.02"}}};

inline std::map<std::string, std::vector<BlockCase>> build_cases() {
  std::map<std::string, std::vector<BlockCase>> cases;
  const auto add = [&](BlockCase c) { cases[c.type].push_back(std::move(c)); };

  // math.*
  add(make_case("math.gain", {{"width", {"2"}}}, {{"k", 1.7}}));
  add(make_case("math.sum", {{"signs", {"+-+"}}, {"width", {"2"}}}));
  add(make_case("math.product", {{"width", {"2"}}}));
  add(make_case("math.integrator", {{"width", {"2"}}}, {{"initial", 0.4}}));
  add(make_case("math.lag", {{"width", {"2"}}}, {{"initial", 0.4}, {"tau", 0.2}}));
  add(make_case("math.demux", {{"width", {"3"}}, {"indices", {"2", "0"}}}));
  add(make_case("math.mux", {{"inputs", {"3"}}}));

  // source.*
  add(source_case("source.constant", {{"value", 2.5}}, {0.0, 0.37}));
  add(source_case("source.step", {{"time", 0.5}, {"before", 0.3}, {"after", 1.2}}, {0.2, 0.5, 0.8}));
  add(source_case("source.ramp", {{"start", 0.3}, {"slope", 2.0}, {"offset", 0.5}}, {0.1, 0.3, 0.9}));
  add(source_case("source.sine", {{"amplitude", 0.7}, {"frequency", 1.3}, {"phase", 0.2}, {"offset", 0.1}},
                  {0.0, 0.37, 1.9}));
  const std::string table = write_scene("registry_table.csv", "t,y\n0.0,0.0\n1.0,0.5\n2.0,-0.25\n3.0,1.0\n");
  add(source_case("source.table", {}, {0.25, 1.5, 3.5}, {{"file", {table}}, {"column", {"y"}}}));

  // objective.*: the whole run, and a window the times straddle.
  for (const char* type :
       {"objective.integral", "objective.mean", "objective.rms", "objective.max_abs", "objective.final"}) {
    add(objective_case(type));
    add(objective_case(type, {{"window", {"0.2", "0.6"}}}));
  }
  BlockCase slip = objective_case("objective.slip_angle", {{"window", {"0.2", "0.6"}}});
  slip.inputs = {{{15.0, 10.0}}, {{0.0, 3.0}}};
  add(slip);

  // mechanics and suspension
  add(make_case("mechanics.link_force", {}, {},
                {{{0, 0.5}, {0, 0.5}, {0, 0.5}}, {{1.0, 0.3}, {0.5, 0.3}, {-0.4, 0.3}}, {{0.0, 2000.0}}}));
  add(make_case("mass_spring_damper", {}, {{"m", 2.0}, {"k", 30.0}, {"c", 0.7}, {"x0", 0.1}, {"v0", -0.2}}));
  for (const char* type : {"spring.linear", "spring.progressive"}) {
    BlockCase c = make_case(type, {}, {{"preload", 3000.0}}, {{{0.0, 0.1}}});  // reaches both stops
    c.samples = 12;
    add(c);
  }
  BlockCase arb = make_case("anti_roll_bar", {}, {}, {{{0.0, 0.12}}, {{0.0, 0.12}}});
  arb.samples = 10;
  add(arb);
  for (double current : {0.3, 1.1}) {
    BlockCase c = make_case("damper.cdc", {}, {{"current", current}}, {{{0.0, 0.03}}, {{0.0, 0.6}}});
    c.states = {{3e6, 2e6}, {1e6, 8e5}, {5e5, 1e5}, {5e-5, 1.5e-4}};
    add(c);
  }
  BlockCase still = make_case("damper.cdc", {}, {{"current", 0.8}}, {{{0.0, 0.001}}, {{0.0, 0.005}}});
  still.states = {{5e5, 3e4}, {5e5, 3e4}, {5e5, 3e4}, {0.0, 1e-6}};  // near zero pressure drops
  add(still);

  // comfort, roads, manoeuvres
  add(make_case("filter.iso2631", {{"weighting", {"Wk"}}}));
  add(make_case("filter.iso2631", {{"weighting", {"Wd"}}}));
  add(source_case("road.fourposter", {}, {0.0, 0.41, 1.37, 2.9}));
  // The pads from a recording (a replay): no parameter moves them, both outputs' tangents are
  // zero (scripts/mutate.sh found the rate's tangent left unset passing every test).
  const std::string pads = write_scene("registry_pads.csv", "t,fl,fr,rl,rr\n0.0,0,0,0,0\n1.0,0.01,-0.02,0.005,0\n"
                                                            "2.0,0.0,0.01,-0.01,0.02\n3.0,-0.01,0,0.01,-0.005\n");
  add(source_case("road.fourposter", {}, {0.41, 1.37, 2.9}, {{"input_file", {pads}}}));
  add(source_case("road.iso8608", {}, {0.0, 0.41, 1.37, 2.9}, {{"components", {"40"}}}));
  add(source_case("road.profile", {{"speed", 10.0}, {"wheelbase", 2.5}}, {0.33, 0.73, 1.0, 1.23, 1.7}, kProfile));
  for (const char* mode : {"step", "ramp_hold", "sine"})
    add(source_case("steering", {{"amplitude", 0.02}, {"start", 1.0}, {"ramp_time", 0.5}, {"frequency", 0.7}},
                    {0.5, 1.2, 1.37, 2.3}, {{"mode", {mode}}}));
  const std::string rack = write_scene("registry_rack.csv", "t,rack\n0.0,0.0\n1.0,0.01\n2.0,0.01\n3.0,-0.02\n");
  add(source_case("steering", {}, {0.5, 1.5, 2.5}, {{"mode", {"csv"}}, {"file", {rack}}}));

  // tyres
  BlockCase vertical = make_case("tyre.vertical", {}, {}, {{{0.01, 0.02}}, {{0.0, 0.5}}, {{0.31, 0.02}}, {{0.0, 0.5}}});
  vertical.samples = 10;
  add(vertical);
  vertical.inputs = {{{0.0, 2e-4}}, {{0.0, 0.05}}, {{0.32, 2e-4}}, {{0.0, 0.05}}};  // contact onset
  add(vertical);
  // Force near zero while deflected: separating at the rate where damping cancels the spring
  // (k delta = 50 N against c rate = -50 N), where the no-pull rounding acts.
  vertical.inputs = {{{0.0, 1e-5}}, {{-0.25, 0.02}}, {{0.32 - 2e-4, 1e-5}}, {{0.0, 0.02}}};
  add(vertical);
  BlockCase mf = make_case("tyre.mf", {}, {}, {{{4000, 2000}}, {{15, 10}}, {{0, 3}}, {{50, 30}}});
  mf.states = {{0.0, 0.3}, {0.0, 0.3}};
  mf.samples = 6;
  add(mf);
  mf.inputs = {{{4000, 2000}}, {{0.0, 0.3}}, {{0.0, 0.3}}, {{0.0, 2.0}}};  // near standstill: vx ~ 0
  add(mf);
  mf.inputs = {{{0.0, 50.0}}, {{15, 10}}, {{0, 3}}, {{50, 30}}};  // near lift-off: fz ~ 0
  add(mf);

  // multibody: the block with a model's defaults, and multibody.NAME for every model
  for (const char* model : {"quarter_car", "sedan", "slider_crank", "fourbar"}) add(multibody_case("multibody", model));
  for (const mbs::GeneratedModel* g : generated::all_models()) {
    BlockCase c = multibody_case(std::string("multibody.") + g->name, g->name);
    const double condition = mass_condition(*g);
    if (condition > 1e6) {
      // The 200-body chain (condition ~5e8): central differences of its accelerations, through
      // M^-1, carry roundoff noise of order condition * eps / step, which larger steps keep near
      // 1e-12 * condition. Its tangent is checked to that; mbs_test_generated checks it by
      // backward error, and the block's seeding is the same code as on the other models.
      c.tolerance = std::max(c.tolerance, 1e-12 * condition);
      c.steps = {1e-2, 3e-3, 1e-3};
      c.direction_limit = 16;
      c.parameter_sets = 1;
    }
    add(c);
  }
  return cases;
}

inline const std::map<std::string, std::vector<BlockCase>>& registry_cases() {
  static const std::map<std::string, std::vector<BlockCase>> all = build_cases();
  return all;
}

/// The names of the registered block types.
inline std::vector<std::string> registered_types() {
  std::vector<std::string> names;
  for (const engine::BlockType* t : engine::Registry::global().all()) names.push_back(t->name);
  return names;
}

}  // namespace dydp::test
