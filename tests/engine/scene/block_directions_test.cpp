// Sensitivity directions named by block parameters: a single block parameter gives the same
// derivative as a scene parameter driving it, a group is the sum of its members' directions
// and matches central differences of the group's value, and every malformed entry is an
// InputError naming file, line and field.
//
// Each scene is a raw string literal whose first line is line 1 of the file.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "engine/analysis/run.hpp"
#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"
#include "tests/temp_folder_test.hpp"

namespace dydp::engine {
namespace {

/// Two independent masses on springs and dampers; `sensitivities` and `parameters` are spliced in.
std::string two_masses(const std::string& parameters, const std::string& sensitivities,
                       const std::string& k2 = "40.0") {
  return "scene: two\n"
         "time: {stop: 4.0, output_step: 0.01}\n"
         "solver: {method: rk4, step: 0.001}\n" +
         parameters + sensitivities +
         "blocks:\n"
         "  force: {type: source.sine, amplitude: 2.0, frequency: 0.8}\n"
         "  body1: {type: mass_spring_damper, m: 1.5, k: 40.0, c: 1.2, x0: 0.05}\n"
         "  body2: {type: mass_spring_damper, m: 2.5, k: " + k2 + ", c: 0.7}\n"
         "  x1: {type: objective.rms, window: [1.0, 4.0]}\n"
         "  x2: {type: objective.rms, window: [1.0, 4.0]}\n"
         "connections:\n"
         "  - force.y -> body1.f\n"
         "  - force.y -> body2.f\n"
         "  - body1.x -> x1.in\n"
         "  - body2.x -> x2.in\n"
         "outputs: [x1, x2]\n";
}

class BlockDirections : public test::TempFolderTest {
 protected:
  BlockDirections() : TempFolderTest("dydp_block_directions_") {}

  static InputError load_error(const std::string& path,
                               const std::vector<std::pair<std::string, std::string>>& overrides = {}) {
    try {
      load_scene(path, overrides);
    } catch (const InputError& e) {
      return e;
    }
    ADD_FAILURE() << path << " loaded without an InputError";
    return InputError("", -1, "", "no error");
  }

  static void expect_error(const InputError& e, const std::string& file, int line, const std::string& field,
                           const std::string& phrase) {
    EXPECT_EQ(e.file(), file) << e.what();
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_EQ(e.field(), field) << e.what();
    EXPECT_NE(std::string(e.what()).find(phrase), std::string::npos) << "'" << phrase << "' not in: " << e.what();
  }
};

TEST_F(BlockDirections, ABlockParameterGivesTheDerivativeOfTheSceneParameterDrivingIt) {
  const std::string direct = write("direct.yaml", two_masses("", "sensitivities: [body1.k, body1.c]\n"));
  std::string through = two_masses(
      "parameters:\n  k1: {value: 40.0, unit: N/m}\n  c1: {value: 1.2, unit: N s/m}\n", "sensitivities: [k1, c1]\n");
  through.replace(through.find("k: 40.0, c: 1.2"), 15, "k: $k1, c: $c1");
  const std::string scene = write("scene.yaml", through);

  const Diagram a = load_scene(direct), b = load_scene(scene);
  ASSERT_EQ(a.sensitivities.size(), 2u);
  EXPECT_EQ(a.parameters[a.sensitivities[0]].name, "body1.k");
  EXPECT_EQ(a.parameters[a.sensitivities[0]].unit, "N/m");
  EXPECT_EQ(a.parameters[a.sensitivities[0]].value, 40.0);
  const RunResult ra = run(a), rb = run(b);
  for (int o = 0; o < 2; ++o)
    for (int dir = 0; dir < 2; ++dir)
      EXPECT_EQ(ra.objectives[o].sensitivity[dir], rb.objectives[o].sensitivity[dir]) << o << " " << dir;
  EXPECT_NE(ra.objectives[0].sensitivity[0], 0.0);
  EXPECT_EQ(ra.objectives[1].sensitivity[0], 0.0);  // body2 does not see body1's spring
}

TEST_F(BlockDirections, AGroupIsTheSumOfItsMembersAndMatchesCentralDifferences) {
  const std::string group = write("group.yaml",
                                  two_masses("", "sensitivities:\n  - {name: springs, of: \"body*.k\", range: [20.0, 80.0]}\n"));
  const std::string single = write("single.yaml", two_masses("", "sensitivities: [body1.k, body2.k]\n"));
  Diagram g = load_scene(group);
  const int index = g.find_parameter("springs");
  ASSERT_GE(index, 0);
  EXPECT_EQ(g.parameters[index].lower, 20.0);
  EXPECT_EQ(g.parameters[index].upper, 80.0);
  const RunResult rg = run(g), rs = run(load_scene(single));
  for (int o = 0; o < 2; ++o) {
    const double sum = rs.objectives[o].sensitivity[0] + rs.objectives[o].sensitivity[1];
    EXPECT_NEAR(rg.objectives[o].sensitivity[0], sum, 1e-12 * std::fabs(sum)) << o;
  }
  // Central differences of the group's value (both springs move): the error falls as h^2.
  auto psi = [&](double k, int o) {
    Diagram d = load_scene(group);
    d.set_parameter(index, k);
    RunOptions opt;
    opt.sensitivities = false;
    return run(d, opt).objectives[o].value;
  };
  for (int o = 0; o < 2; ++o) {
    const double exact = rg.objectives[o].sensitivity[0];
    double previous = INFINITY;
    for (double h : {1.0, 0.1, 0.01}) {
      const double fd = (psi(40.0 + h, o) - psi(40.0 - h, o)) / (2 * h);
      const double error = std::fabs(fd - exact) / std::fabs(exact);
      EXPECT_LT(error, previous / 20) << "h = " << h;
      previous = error;
    }
    EXPECT_LT(previous, 1e-6);
  }
}

TEST_F(BlockDirections, SetReachesADirectionNamedByBlockParameters) {
  const std::string path = write("s.yaml", two_masses("", "sensitivities:\n  - {name: springs, of: [body1.k, body2.k], range: [20.0, 80.0]}\n"));
  const Diagram d = load_scene(path, {{"springs", "50"}});
  for (const Node& n : d.nodes) {
    if (n.name == "body1" || n.name == "body2") {
      EXPECT_EQ(n.p[1], 50.0) << n.name;
    }
  }
  expect_error(load_error(path, {{"springs", "90"}}), path, 5, "sensitivities.springs", "outside its range");
  expect_error(load_error(path, {{"sprngs", "50"}}), "--set", 0, "sprngs", "no scene parameter of that name");
}

TEST_F(BlockDirections, UnknownBlockParameterNamesTheBlocksParameters) {
  const std::string path = write("s.yaml", two_masses("", "sensitivities: [body1.stiffness]\n"));
  expect_error(load_error(path), path, 4, "sensitivities.body1.stiffness", "has parameters: m k c x0 v0");
  const std::string none = write("n.yaml", two_masses("", "sensitivities:\n  - {name: all, of: \"wheel*.k\"}\n"));
  expect_error(load_error(none), none, 5, "sensitivities.all", "no block parameter 'wheel*.k'");
}

TEST_F(BlockDirections, AParameterDrivenByASceneParameterIsRefused) {
  std::string text = two_masses("parameters:\n  k1: {value: 40.0, unit: N/m}\n", "sensitivities:\n  - body1.k\n");
  text.replace(text.find("k: 40.0, c: 1.2"), 15, "k: $k1, c: 1.2");
  const std::string path = write("s.yaml", text);
  expect_error(load_error(path), path, 7, "sensitivities.body1.k", "driven by scene parameter 'k1'");
}

TEST_F(BlockDirections, NonDifferentiableParameterIsRefused) {
  std::string text = two_masses("", "sensitivities: [st.time]\n");
  text.replace(text.find("blocks:\n"), 8, "blocks:\n  st: {type: source.step, after: 1.0, time: 0.5}\n");
  text.replace(text.find("outputs: [x1, x2]"), 17, "outputs: [x1, x2, st.y]");
  const std::string path = write("s.yaml", text);
  expect_error(load_error(path), path, 4, "sensitivities.st.time", "not differentiable");
}

TEST_F(BlockDirections, MembersOfAGroupMustShareTheirValue) {
  const std::string path =
      write("s.yaml", two_masses("", "sensitivities:\n  - {name: springs, of: [body1.k, body2.k]}\n", "45.0"));
  expect_error(load_error(path), path, 5, "sensitivities.springs", "body2.k is 45");
}

TEST_F(BlockDirections, RangesStayInsideTheBlocksBoundsAndHoldTheValue) {
  const std::string wide = write("w.yaml", two_masses("", "sensitivities:\n  - {of: body1.c, range: [-1.0, 5.0]}\n"));
  expect_error(load_error(wide), wide, 5, "sensitivities.body1.c.range", "leaves the bounds [0, inf]");
  const std::string off = write("o.yaml", two_masses("", "sensitivities:\n  - {of: body1.c, range: [2.0, 5.0]}\n"));
  expect_error(load_error(off), off, 5, "sensitivities.body1.c.range", "value 1.2 of body1.c is outside");
  const std::string unit = write("u.yaml", two_masses("", "sensitivities:\n  - {of: body1.c, unit: N/m}\n"));
  expect_error(load_error(unit), unit, 5, "sensitivities.body1.c.unit", "body1.c is in N s/m");
}

TEST_F(BlockDirections, MalformedEntriesAreRefusedWhereWritten) {
  const std::string unnamed = write("a.yaml", two_masses("", "sensitivities:\n  - {of: [body1.k, body2.k]}\n"));
  expect_error(load_error(unnamed), unnamed, 5, "sensitivities.name", "needs a name");
  const std::string twice = write("b.yaml", two_masses("", "sensitivities:\n  - body1.k\n  - {name: springs, of: \"body*.k\"}\n"));
  expect_error(load_error(twice), twice, 6, "sensitivities.springs", "body1.k is already in direction 'body1.k' (line 5)");
  const std::string again = write("c.yaml", two_masses("", "sensitivities: [body1.k, body1.k]\n"));
  expect_error(load_error(again), again, 4, "sensitivities", "listed twice");
  const std::string key = write("d.yaml", two_masses("", "sensitivities:\n  - {of: body1.k, rnage: [1, 2]}\n"));
  expect_error(load_error(key), key, 5, "sensitivities.rnage", "unknown key");
  const std::string plain = write("e.yaml", two_masses("", "sensitivities: [stiffnes]\n"));
  expect_error(load_error(plain), plain, 4, "sensitivities", "unknown scene parameter 'stiffnes'");
  const std::string clash = write("f.yaml", two_masses("parameters:\n  k1: 3.0\n", "sensitivities:\n  - {name: k1, of: body1.k}\n"));
  expect_error(load_error(clash), clash, 7, "sensitivities.name", "is a scene parameter already");
}

TEST_F(BlockDirections, DeclaredDirectionsAreSceneParametersComputedOnlyWhenListed) {
  const std::string declared = two_masses("", "directions:\n  - {name: springs, of: \"body*.k\", range: [20.0, 80.0]}\n  - body1.c\n");
  const std::string quiet = write("q.yaml", declared);
  const Diagram q = load_scene(quiet);
  EXPECT_TRUE(q.sensitivities.empty());
  const int springs = q.find_parameter("springs");
  ASSERT_GE(springs, 0);
  EXPECT_EQ(q.parameters[springs].direction_list, "directions");
  EXPECT_GE(q.find_parameter("body1.c"), 0);
  const std::string listed = write("l.yaml", declared + "sensitivities: [body1.c, springs]\n");
  const Diagram l = load_scene(listed);
  ASSERT_EQ(l.sensitivities.size(), 2u);
  EXPECT_EQ(l.sensitivities[0], l.find_parameter("body1.c"));
  EXPECT_EQ(l.sensitivities[1], l.find_parameter("springs"));
  // A declared direction's block parameter cannot be named again in sensitivities.
  const std::string again = write("a.yaml", declared + "sensitivities: [body2.k]\n");
  expect_error(load_error(again), again, 19, "sensitivities.body2.k", "already in direction 'springs' (line 5)");
  const std::string scene_param = write("s.yaml", two_masses("parameters:\n  k1: 3.0\n", "directions: [k1]\n"));
  expect_error(load_error(scene_param), scene_param, 6, "directions", "is a scene parameter already");
  // set_sensitivities refuses a direction that reaches a parameter its block cannot differentiate.
  std::string step = two_masses("parameters:\n  t1: 0.5\n", "");
  step.replace(step.find("blocks:\n"), 8, "blocks:\n  st: {type: source.step, after: 1.0, time: $t1}\n");
  step.replace(step.find("outputs: [x1, x2]"), 17, "outputs: [x1, x2, st.y]");
  const std::string step_path = write("t.yaml", step);
  Diagram t = load_scene(step_path);
  try {
    t.set_sensitivities({t.find_parameter("t1")});
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& e) {
    expect_error(e, step_path, 7, "st.time", "not differentiable");
  }
}

TEST_F(BlockDirections, ShippedSedanScenesDeclareTheirSuspensionDirectionsWithoutComputingThem) {
  const std::string scenes = std::string(DYDP_SOURCE_DIR) + "/scenarios/";
  struct Expected {
    const char* scene;
    std::vector<std::pair<const char*, int>> members;  ///< direction, block parameters it drives
    const char* computed;                              ///< the scene's one sensitivity
  };
  for (const Expected& x : {Expected{"fourposter_comfort.yaml",
                                     {{"piston_rebound_section", 4}, {"damper_friction", 4}, {"spring_front", 2},
                                      {"spring_rear", 2}, {"tyre_stiffness", 4}, {"gas_precharge", 4},
                                      {"strut_mount_front", 1}, {"shock_mount_rear", 1}, {"com_height", 1}},
                                     "valve_current"},
                            Expected{"cornering_arb.yaml",
                                     {{"valve_current", 4}, {"piston_check_section", 4}, {"arb_lever_front", 1},
                                      {"spring_seat_rear", 1}, {"com_height", 1}},
                                     "arb_front"}}) {
    SCOPED_TRACE(x.scene);
    const Diagram d = load_scene(scenes + x.scene);
    ASSERT_EQ(d.sensitivities.size(), 1u);
    EXPECT_EQ(d.parameters[d.sensitivities[0]].name, x.computed);
    for (const auto& [name, count] : x.members) {
      const int i = d.find_parameter(name);
      ASSERT_GE(i, 0) << name;
      const SceneParameter& p = d.parameters[i];
      EXPECT_EQ(p.direction_list, "directions") << name;
      EXPECT_TRUE(std::isfinite(p.lower) && std::isfinite(p.upper) && p.lower < p.value && p.value < p.upper) << name;
      int driven = 0;
      for (const Node& n : d.nodes)
        for (int s : n.p_scene) driven += s == i;
      EXPECT_EQ(driven, count) << name;
    }
  }
}

}  // namespace
}  // namespace dydp::engine
