// The .mbs.yaml loader's errors (file:line: field: message, and exit status 2 with that message
// from dydp-gen), the new description features (joints about arbitrary axes, link forces,
// sensor components), and what recursion saves on chain9's tip Jacobian against the in-extenso
// expansion.
#include <gtest/gtest.h>
#include <unistd.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "symbolic/eqs_reader.hpp"
#include "symbolic/expand.hpp"
#include "symbolic/mbs/model.hpp"
#include "symbolic/mbs/newton_euler.hpp"
#include "symbolic/op_count.hpp"

namespace dydp::mbs {
namespace {

namespace fs = std::filesystem;

const std::string kBase = R"(model: tiny
parameters:
  l: 0.5
ground:
  anchors: {C: [0, 0, 1]}
bodies:
  - name: arm
    joints: [{name: q1, type: Rz}]
    mass: 1.0
    anchors: {tip: [$l, 0, 0]}
)";

// The message of the error parsing `text`, or "" when it parses.
std::string error_of(const std::string& text) {
  try {
    parse_model(text, "tiny.mbs.yaml");
  } catch (const symbolic::ParseError& e) {
    return e.what();
  }
  return "";
}

struct Case {
  std::string yaml;      // appended to kBase (or replacing it when it starts with "model:")
  std::string expected;  // file:line: field: message
};

TEST(ModelLoader, ErrorsNameFileLineAndField) {
  const std::vector<Case> cases{
      {"  - name: b2\n    joints: [{name: q2, type: Rw}]\n    mass: 1\n",
       "tiny.mbs.yaml:12: bodies.b2.joints[0].type: expected one of Rx Ry Rz Tx Ty Tz R T"},
      {"  - name: b2\n    joints: [{name: q2, type: R}]\n    mass: 1\n",
       "tiny.mbs.yaml:12: bodies.b2.joints[0].axis: missing (a joint of type R or T needs an axis [x, y, z])"},
      {"  - name: b2\n    joints: [{name: q2, type: R, axis: [0, 0, 0]}]\n    mass: 1\n",
       "tiny.mbs.yaml:12: bodies.b2.joints[0].axis: the axis is zero"},
      {"  - name: b2\n    joints: [{name: q2, type: Rx, axis: [1, 0, 0]}]\n    mass: 1\n",
       "tiny.mbs.yaml:12: bodies.b2.joints[0].axis: only joints of type R or T take an axis"},
      {"  - name: b2\n    joints: [{name: q1, type: Rx}]\n    mass: 1\n",
       "tiny.mbs.yaml:12: bodies.b2.joints[0].name: duplicate joint name 'q1'"},
      {"  - name: b2\n    parent: nobody\n    joints: [{type: Rx}]\n    mass: 1\n",
       "tiny.mbs.yaml:12: bodies.b2.parent: unknown body 'nobody'"},
      {"  - name: b2\n    joints: [{type: Rx}]\n    mass: $m2\n",
       "tiny.mbs.yaml:13: bodies.b2.mass: unknown parameter 'm2'"},
      {"  - name: b2\n    joints: [{type: Rx}]\n    mass: 1\n    colour: red\n",
       "tiny.mbs.yaml:14: bodies[1].colour: unknown key"},
      {"cuts:\n  - {name: c1, type: ball, a: arm.tip, b: ground.D}\n",
       "tiny.mbs.yaml:12: cuts.c1.b: body 'ground' has no anchor 'D'"},
      {"cuts:\n  - {name: c1, type: slot, a: arm.tip, b: ground.C}\n",
       "tiny.mbs.yaml:12: cuts.c1.type: expected ball, distance or hinge"},
      {"cuts:\n  - {name: c1, type: hinge, a: arm.tip, b: ground.C}\n",
       "tiny.mbs.yaml:12: cuts.c1.axis_a: missing (a hinge needs axis, or axis_a and axis_b: x, y, z or [x, y, z])"},
      {"cuts:\n  - {name: c1, type: hinge, a: arm.tip, b: ground.C, axis_a: z}\n",
       "tiny.mbs.yaml:12: cuts.c1.axis_b: missing (a hinge needs axis, or axis_a and axis_b: x, y, z or [x, y, z])"},
      {"cuts:\n  - {name: c1, type: hinge, a: arm.tip, b: ground.C,\n     axis: w}\n",
       "tiny.mbs.yaml:13: cuts.c1.axis: expected x, y, z or [x, y, z], got 'w'"},
      {"cuts:\n  - {name: c1, type: hinge, a: arm.tip, b: ground.C, axis_a: x,\n     axis_b: [0, 1]}\n",
       "tiny.mbs.yaml:13: cuts.c1.axis_b: expected x, y, z or [x, y, z]"},
      {"cuts:\n  - {name: c1, type: hinge, a: arm.tip, b: ground.C, axis: [0, 0, 0]}\n",
       "tiny.mbs.yaml:12: cuts.c1.axis: the axis is zero"},
      {"cuts:\n  - {name: c1, type: hinge, a: arm.tip, b: ground.C, axis: z, length: 0.1}\n",
       "tiny.mbs.yaml:12: cuts.c1.length: not a key of a hinge"},
      {"cuts:\n  - {name: c1, type: ball, a: arm.tip, b: ground.C, axis: z}\n",
       "tiny.mbs.yaml:12: cuts.c1.axis: only a hinge takes axis"},
      {"loads:\n  - {name: f, type: link_force, a: arm.tip, b: ground.C, sense: sideways}\n",
       "tiny.mbs.yaml:12: loads.f.sense: expected tension or compression"},
      {"loads:\n  - {name: f, type: link_force, a: arm.tip, b: ground.C, frame: arm}\n",
       "tiny.mbs.yaml:12: loads.f.frame: not a key of a link force"},
      {"loads:\n  - {name: f, type: force, point: arm.tip, components: [x, w]}\n",
       "tiny.mbs.yaml:12: loads.f.components: expected one of x, y, z, got 'w'"},
      {"loads:\n  - {name: f, type: force, point: arm.tip, reaction: arm}\n",
       "tiny.mbs.yaml:12: loads.f.reaction: only a torque takes a reaction body"},
      {"sensors:\n  - {name: s, type: length, a: arm.tip, b: ground.C, components: [length, length]}\n",
       "tiny.mbs.yaml:12: sensors.s.components: 'length' is listed twice"},
      {"sensors:\n  - {name: s, type: position, point: arm.tip, reference: 0.1}\n",
       "tiny.mbs.yaml:12: sensors.s.reference: only a length sensor takes reference"},
      {"sensors:\n  - {name: s, type: angular_velocity, point: arm.tip}\n",
       "tiny.mbs.yaml:12: sensors.s.body: missing"},
      {"sensors:\n  - {name: s, type: force, point: arm.tip}\n",
       "tiny.mbs.yaml:12: sensors.s.type: expected position, velocity, acceleration, angular_velocity, length or joint"},
      {"independent: [q7]\n", "tiny.mbs.yaml:11: independent: unknown joint 'q7'"},
  };
  for (const Case& c : cases) EXPECT_EQ(error_of(kBase + c.yaml), c.expected) << c.yaml;
  EXPECT_EQ(error_of(kBase), "");
}

// A flag (a parameter's fold, a joint's driven) that is not a boolean is an error at its line,
// not a yaml-cpp conversion exception (found by mbs_model_fuzz: `fold: treu` ended dydp-gen with
// an uncaught YAML::TypedBadConversion).
TEST(ModelLoader, FlagsThatAreNotBooleansAreErrors) {
  const std::string body = "ground: {}\nbodies:\n  - name: arm\n    joints: [{name: q1, type: Rz";
  EXPECT_EQ(error_of("model: tiny\nparameters:\n  l: {value: 0.5, fold: treu}\n" + body + "}]\n    mass: 1.0\n"),
            "tiny.mbs.yaml:3: parameters.l.fold: expected true or false, got 'treu'");
  EXPECT_EQ(error_of("model: tiny\nparameters:\n  l: {value: 0.5, fold: [1]}\n" + body + "}]\n    mass: 1.0\n"),
            "tiny.mbs.yaml:3: parameters.l.fold: expected true or false");
  EXPECT_EQ(error_of("model: tiny\n" + body + ",\n                driven: 2}]\n    mass: 1.0\n"),
            "tiny.mbs.yaml:6: bodies.arm.joints[0].driven: expected true or false, got '2'");
  // the booleans YAML spells are still read
  EXPECT_EQ(error_of("model: tiny\nparameters:\n  l: {value: 0.5, fold: false}\n" + body + ", driven: yes}]\n    mass: 1.0\n"), "");
}

TEST(ModelLoader, ReadsTheNewFeatures) {
  const Model m = parse_model(kBase + R"(  - name: b2
    parent: arm
    joints: [{name: q2, type: R, axis: [3, 0, 4]}, {name: q3, type: T, axis: [0, 2, 0]}]
    mass: 1
    anchors: {P: [0, 0, 0]}
loads:
  - {name: spring, type: link_force, a: ground.C, b: b2.P, sense: compression}
  - {name: side, type: force, point: b2.P, frame: arm, components: [z, x]}
  - {name: drive, type: torque, body: b2, components: [y], reaction: arm}
sensors:
  - {name: travel, type: length, a: ground.C, b: b2.P, sense: compression, reference: $l, components: [rate]}
  - {name: spin, type: angular_velocity, body: b2, frame: arm}
)", "tiny.mbs.yaml");
  EXPECT_NEAR(m.joints[1].axis[0], 0.6, 1e-15);
  EXPECT_NEAR(m.joints[1].axis[2], 0.8, 1e-15);
  EXPECT_EQ(m.joints[2].axis[1], 1.0);
  EXPECT_EQ(m.input_count(), 1 + 2 + 1);
  EXPECT_EQ(m.input_names(), (std::vector<std::string>{"spring", "side.z", "side.x", "drive.y"}));
  EXPECT_TRUE(m.loads[0].compression);
  EXPECT_EQ(m.loads[2].reaction, 1);
  EXPECT_EQ(m.sensor_output_names(), (std::vector<std::string>{"travel.rate", "spin.x", "spin.y", "spin.z"}));
  EXPECT_TRUE(m.sensors[0].compression);
  EXPECT_EQ(m.sensors[0].reference.param, 0);
}

TEST(ModelLoader, ReadsHingeCuts) {
  const Model m = parse_model(kBase + R"(  - name: b2
    joints: [{name: q2, type: Rx}]
    mass: 1
    anchors: {P: [0, 0, 0]}
cuts:
  - {name: both, type: hinge, a: arm.tip, b: b2.P, axis: z}
  - {name: own, type: hinge, a: b2.P, b: ground.C, axis_a: [0, 3, 4], axis_b: x}
)", "tiny.mbs.yaml");
  ASSERT_EQ(m.cuts.size(), 2u);
  EXPECT_EQ(m.constraint_count(), 10);
  const Cut& both = m.cuts[0];
  EXPECT_EQ(both.type, Cut::Type::Hinge);
  EXPECT_EQ(both.axis_a, (std::array<double, 3>{0, 0, 1}));
  EXPECT_EQ(both.axis_b, (std::array<double, 3>{0, 0, 1}));
  EXPECT_EQ(both.normals_a[0], (std::array<double, 3>{1, 0, 0}));
  EXPECT_EQ(both.normals_a[1], (std::array<double, 3>{0, 1, 0}));
  const Cut& own = m.cuts[1];
  EXPECT_NEAR(own.axis_a[1], 0.6, 1e-15);
  EXPECT_NEAR(own.axis_a[2], 0.8, 1e-15);
  EXPECT_EQ(own.axis_b, (std::array<double, 3>{1, 0, 0}));
  // the normals and the axis are an orthonormal frame
  for (const auto& n : own.normals_a) {
    EXPECT_NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1.0, 1e-15);
    EXPECT_NEAR(n[0] * own.axis_a[0] + n[1] * own.axis_a[1] + n[2] * own.axis_a[2], 0.0, 1e-15);
  }
  const auto& n1 = own.normals_a[0];
  const auto& n2 = own.normals_a[1];
  EXPECT_NEAR(n1[0] * n2[0] + n1[1] * n2[1] + n1[2] * n2[2], 0.0, 1e-15);
}

TEST(DydpGen, ModelErrorsExitWithStatusTwoAndTheMessage) {
  const fs::path dir = fs::temp_directory_path() / ("mbs_loader_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path model = dir / "bad.mbs.yaml";
  std::ofstream(model) << kBase << "  - name: b2\n    joints: [{name: q2, type: R}]\n    mass: 1\n";
  const std::string command = std::string("\"") + DYDP_GEN_EXE + "\" \"" + model.string() + "\" --out \"" +
                              (dir / "out").string() + "\" 2> \"" + (dir / "err.txt").string() + "\"";
  const int raw = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(raw));
  EXPECT_EQ(WEXITSTATUS(raw), 2);
  std::stringstream err;
  err << std::ifstream(dir / "err.txt").rdbuf();
  EXPECT_NE(err.str().find(model.string() + ":12: bodies.b2.joints[0].axis: missing"), std::string::npos) << err.str();
  fs::remove_all(dir);
}

// Recursion against in extenso on chain9's 3 x 9 tip Jacobian (the colleague's figures: 1157
// against 5264 operations): the recursive form needs at most a third.
TEST(Chain9, RecursiveTipJacobianCostsAtMostAThirdOfTheExpansion) {
  const Model m = load_model(std::string(DYDP_MODELS_DIR) + "/chain9.mbs.yaml");
  const ModelLists lists = build_model_lists(m);
  ASSERT_EQ(lists.jacobians.size(), 1u);
  const auto recursive = symbolic::count_ops(*lists.jacobians[0].list).total();
  const auto expanded = symbolic::count_ops(symbolic::expand(*lists.jacobians[0].list)).total();
  RecordProperty("recursive_ops", std::to_string(recursive));
  RecordProperty("expanded_ops", std::to_string(expanded));
  EXPECT_GT(recursive, 0u);
  EXPECT_LE(3 * recursive, expanded) << recursive << " against " << expanded;
}

}  // namespace
}  // namespace dydp::mbs
