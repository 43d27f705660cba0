// The sedan's suspension kinematics (symbolic/mbs/suspension_kinematics.hpp) against what they
// must equal by other routes: the motion ratio against central differences of the spring's
// compression along the travel (a step study), the front motion ratio and its derivative with
// respect to the strut's lower mount against the mount's lever arm about the lower arm's axis
// worked by hand from the model file, the exact derivatives of the position curves against
// central differences of whole sweeps (a step study), the kinematic roll centre against the
// height about which the body rolls without moving the contact points sideways, and a model
// without corners refused by name.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "generated_models/registry.hpp"
#include "symbolic/mbs/kinematic_pose.hpp"
#include "symbolic/mbs/model.hpp"
#include "symbolic/mbs/suspension_kinematics.hpp"

namespace dydp::mbs {
namespace {

const GeneratedModel& sedan() {
  const GeneratedModel* g = generated::find_model("sedan");
  if (!g) throw std::runtime_error("no sedan model");
  return *g;
}

std::vector<double> nominal(const GeneratedModel& g) { return {g.parameter_values, g.parameter_values + g.parameters}; }

int parameter(const GeneratedModel& g, const std::string& name) {
  for (int j = 0; j < g.parameters; ++j)
    if (name == g.parameter_names[j]) return j;
  throw std::runtime_error("no parameter " + name);
}

const KinematicsCurve& curve(const KinematicsResult& r, const std::string& sweep, const std::string& quantity,
                             const std::string& corner) {
  for (const auto& s : r.sweeps)
    if (s.name == sweep)
      for (const auto& c : s.curves)
        if (c.quantity == quantity && c.corner == corner) return c;
  throw std::runtime_error("no curve " + sweep + "/" + quantity + "/" + corner);
}

const KinematicsSweep& sweep(const KinematicsResult& r, const std::string& name) {
  for (const auto& s : r.sweeps)
    if (s.name == name) return s;
  throw std::runtime_error("no sweep " + name);
}

KinematicsResult bump_only(const std::vector<double>& p, int points, const std::vector<int>& parameters = {}) {
  KinematicsOptions o;
  o.bump_points = points;
  o.roll_points = 3;
  o.rack_points = 3;
  o.parameters = parameters;
  return suspension_kinematics(sedan(), p, o);
}

TEST(SuspensionKinematics, FindsTheSedansFourCornersAndTheCoordinateThatMovesEachWheel) {
  const GeneratedModel& g = sedan();
  const auto corners = suspension_corners(g, nominal(g));
  ASSERT_EQ(corners.size(), 4u);
  const std::array<std::string, 4> names{"fl", "fr", "rl", "rr"}, travel{"lca_fl", "lca_fr", "trailing_rl_pitch",
                                                                          "trailing_rr_pitch"};
  for (size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(corners[k].name, names[k]);
    EXPECT_EQ(std::string(g.coordinate_names[corners[k].travel]), travel[k]);
    EXPECT_EQ(corners[k].side, k % 2 == 0 ? 1.0 : -1.0);
    EXPECT_GE(corners[k].spring, 0);
    EXPECT_GE(corners[k].damper, 0);
  }
}

// The motion ratios are rates along the travel; central differences of the compression curves
// on grids of 5, 2.5 and 1.25 mm must converge to them as h^2.
TEST(SuspensionKinematics, MotionRatiosAreTheDerivativesOfTheCompressionAlongTheTravel) {
  const auto p = nominal(sedan());
  const KinematicsResult coarse = bump_only(p, 33), mid = bump_only(p, 65), fine = bump_only(p, 129);
  const std::array<const KinematicsResult*, 3> runs{&coarse, &mid, &fine};
  for (const std::string corner : {"fl", "fr", "rl", "rr"})
    for (const auto& [length, ratio] : {std::pair<std::string, std::string>{"spring_compression", "spring_ratio"},
                                        {"damper_compression", "damper_ratio"}}) {
      // at -60, -40, ..., +60 mm: index of s on each grid
      for (const double s : {-0.06, -0.04, -0.02, 0.0, 0.02, 0.04, 0.06}) {
        std::array<double, 3> error{};
        double exact = 0;
        for (size_t r = 0; r < 3; ++r) {
          const auto& x = sweep(*runs[r], "bump").x;
          const double h = x[1] - x[0];
          const size_t i = static_cast<size_t>(std::lround((s - x[0]) / h));
          ASSERT_NEAR(x[i], s, 1e-12);
          const auto& L = curve(*runs[r], "bump", length, corner).values;
          exact = curve(*runs[r], "bump", ratio, corner).values[i];
          error[r] = (L[i + 1] - L[i - 1]) / (2 * h) - exact;
        }
        EXPECT_GT(std::abs(exact), 0.4) << corner << " " << ratio << " at " << s;
        EXPECT_LT(std::abs(exact), 1.0) << corner << " " << ratio << " at " << s;
        // the h^2 regime: the error quarters with each halving of the grid, and is small
        EXPECT_NEAR(error[0] / error[1], 4.0, 0.2) << corner << " " << ratio << " at " << s;
        EXPECT_NEAR(error[1] / error[2], 4.0, 0.2) << corner << " " << ratio << " at " << s;
        EXPECT_LT(std::abs(error[2]), 1e-4) << corner << " " << ratio << " at " << s;
      }
    }
}

// The strut is a force element: moving its lower mount along the lower arm (strut_arm_y_front)
// leaves the kinematics alone, so the motion ratio scales with the mount's lever arm about the
// arm's axis, -u . (a x r) (u along the strut, a the axis, r from the axis to the mount), worked
// here from the model file's hardpoints at the design position.
TEST(SuspensionKinematics, FrontMotionRatioFollowsTheStrutMountsLeverArmWorkedByHand) {
  const Model m = load_model(DYDP_MODELS_DIR "/sedan.mbs.yaml");
  auto joint = [&](const std::string& name) -> const Joint& {
    for (const auto& j : m.joints)
      if (j.name == name) return j;
    throw std::runtime_error("no joint " + name);
  };
  auto anchor = [&](const std::string& body, const std::string& name) {
    for (const auto& b : m.bodies)
      if (b.name == body)
        for (const auto& a : b.anchors)
          if (a.name == name) return a.position;
    throw std::runtime_error("no anchor " + body + "." + name);
  };
  auto vec = [&](const Vec3Value& v) { return Eigen::Vector3d(m.value(v[0]), m.value(v[1]), m.value(v[2])); };
  const Joint& lca = joint("lca_fl");
  const Eigen::Vector3d axis(lca.axis[0], lca.axis[1], lca.axis[2]), pivot = vec(lca.offset);
  const Eigen::Vector3d top = vec(anchor("chassis", "strut_fl"));  // the chassis frame is the ground's at q = 0
  Eigen::Vector3d mount = vec(anchor("lca_fl", "strut"));          // with y = strut_arm_y_front
  const GeneratedModel& g = sedan();
  const int y = parameter(g, "strut_arm_y_front");
  const double y0 = nominal(g)[static_cast<size_t>(y)];
  ASSERT_DOUBLE_EQ(mount.y(), y0);
  auto lever = [&](double arm_y) {
    Eigen::Vector3d r = mount;
    r.y() = arm_y;  // from the pivot, in the arm's frame = the ground's at the design position
    const Eigen::Vector3d u = (pivot + r - top).normalized();
    return -u.dot(axis.cross(r));
  };
  auto lever_rate = [&](double arm_y) {  // d lever / d arm_y, by hand
    Eigen::Vector3d r = mount;
    r.y() = arm_y;
    const Eigen::Vector3d d = pivot + r - top, e_y = Eigen::Vector3d::UnitY();
    const Eigen::Vector3d u = d.normalized(), du = (e_y - u * u.dot(e_y)) / d.norm();
    return -du.dot(axis.cross(r)) - u.dot(axis.cross(e_y));
  };

  auto p = nominal(g);
  const KinematicsResult at_nominal = bump_only(p, 3, {y});
  p[static_cast<size_t>(y)] = 0.23;
  const KinematicsResult moved = bump_only(p, 3);
  for (const std::string corner : {"fl", "fr"}) {
    const auto& c0 = curve(at_nominal, "bump", "spring_ratio", corner);
    const double mr0 = c0.values[1], mr1 = curve(moved, "bump", "spring_ratio", corner).values[1];
    EXPECT_NEAR(mr1 / mr0, lever(0.23) / lever(y0), 1e-10) << corner;
    // The right strut's mount is at -strut_arm_y_front: mirrored, the same ratio.
    const double dmr = c0.sensitivity[0][1];
    EXPECT_FALSE(c0.exact);
    EXPECT_NEAR(dmr, mr0 * lever_rate(y0) / lever(y0), 1e-7 * std::abs(dmr)) << corner;
  }
  EXPECT_NEAR(lever(0.23) / lever(y0), 1.13, 0.05);  // a mount 30 mm further out: 13 % more ratio
}

// Exact derivatives of the position curves (implicit function theorem) against central
// differences of whole sweeps at p +- h and p +- h/2: the differences' error falls 4x.
TEST(SuspensionKinematics, PositionCurvesDerivativesEqualCentralDifferencesOfWholeSweeps) {
  const GeneratedModel& g = sedan();
  const std::vector<int> which{parameter(g, "strut_arm_y_front"), parameter(g, "shock_arm_x_rear"),
                               parameter(g, "spring_arm_x_rear")};
  const auto p = nominal(g);
  const KinematicsResult r = bump_only(p, 9, which);
  int checked = 0;
  for (size_t k = 0; k < which.size(); ++k) {
    const size_t j = static_cast<size_t>(which[k]);
    std::array<KinematicsResult, 4> runs;
    const double h = 2e-3;
    for (int side = 0; side < 4; ++side) {
      auto q = p;
      q[j] += (side % 2 ? -1.0 : 1.0) * (side < 2 ? h : h / 2);
      runs[static_cast<size_t>(side)] = bump_only(q, 9);
    }
    for (const auto& c : sweep(r, "bump").curves) {
      if (!c.exact) continue;
      const auto& plus = curve(runs[0], "bump", c.quantity, c.corner).values;
      const auto& minus = curve(runs[1], "bump", c.quantity, c.corner).values;
      const auto& plus2 = curve(runs[2], "bump", c.quantity, c.corner).values;
      const auto& minus2 = curve(runs[3], "bump", c.quantity, c.corner).values;
      for (size_t i = 0; i < c.values.size(); ++i) {
        const double exact = c.sensitivity[k][i];
        const double e1 = (plus[i] - minus[i]) / (2 * h) - exact, e2 = (plus2[i] - minus2[i]) / h - exact;
        if (std::abs(exact) < 1e-6) {  // a quantity the parameter does not move (toe, camber, the other axle)
          EXPECT_LT(std::abs(e1), 1e-9) << c.quantity << " " << c.corner << " " << g.parameter_names[j];
          continue;
        }
        ++checked;
        EXPECT_LT(std::abs(e2), 1e-5 * std::abs(exact)) << c.quantity << " " << c.corner << " " << g.parameter_names[j];
        if (std::abs(e2) > 1e-10 * std::abs(exact)) {
          EXPECT_NEAR(e1 / e2, 4.0, 0.3) << c.quantity << " " << c.corner << " " << g.parameter_names[j] << " at " << i;
        }
      }
    }
  }
  // spring (front, rear) and damper (front, rear) compression over 9 points, less the design
  // point where a compression is zero for every mount
  EXPECT_GE(checked, 8 * 4);
}

// A body rolled about an axis at height h0 with its contact points held on the ground moves
// them sideways by -(h_rc - h0) per radian, where h_rc is the kinematic roll centre (about which
// it rolls without moving them): the roll centre from the contact's lateral motion in bump,
// found by another motion.
TEST(SuspensionKinematics, RollCentreIsWhereTheBodyRollsWithoutMovingTheContactsSideways) {
  const GeneratedModel& g = sedan();
  const auto p = nominal(g);
  const KinematicsResult r = bump_only(p, 3);
  const auto corners = suspension_corners(g, p);
  // The design pose as the analysis holds it, the body rolling about its x axis at z = 0.
  PoseSpec spec;
  spec.q.assign(static_cast<size_t>(g.n), 0.0);
  for (int i = 0; i < g.driven_count; ++i) spec.q[static_cast<size_t>(g.driven[i])] = g.initial_q[g.driven[i]];
  std::vector<char> fixed(static_cast<size_t>(g.n), 0);
  for (int i = 0; i < g.independent_count; ++i) fixed[static_cast<size_t>(g.independent[i])] = 1;
  for (int i = 0; i < g.driven_count; ++i) fixed[static_cast<size_t>(g.driven[i])] = 1;
  for (const auto& c : corners) fixed[static_cast<size_t>(c.travel)] = 0;
  for (int j = 0; j < g.n; ++j)
    if (!fixed[static_cast<size_t>(j)]) spec.free.push_back(j);
  int roll = -1;
  for (int j = 0; j < g.n; ++j)
    if (std::string(g.coordinate_names[j]) == "roll") roll = j;
  ASSERT_GE(roll, 0);
  spec.q_rate.assign(static_cast<size_t>(g.n), 0.0);
  spec.q_rate[static_cast<size_t>(roll)] = 1.0;
  // contacts at the design height: solve the design pose first for their values
  PoseSpec design = spec;
  design.free.clear();
  for (int j = 0; j < g.n; ++j)
    if (!fixed[static_cast<size_t>(j)] && std::find_if(corners.begin(), corners.end(), [&](const SuspensionCorner& c) {
                                             return c.travel == j;
                                           }) == corners.end())
      design.free.push_back(j);
  design.q_rate.clear();
  const Pose d0 = solve_pose(g, p, design, {});
  spec.q.assign(d0.q.data(), d0.q.data() + g.n);
  for (const auto& c : corners) spec.targets.push_back({c.contact + 2, d0.sensors[c.contact + 2], 0.0});
  const Pose rolled = solve_pose(g, p, spec, {});
  for (const auto& c : corners) {
    const double lateral = rolled.sensors_rate[c.contact + 1];  // dy/dphi [m/rad]
    const double h_rc = 0.0 - lateral - d0.sensors[c.contact + 2];
    const double bump = curve(r, "bump", "roll_centre_height", c.name).values[1];
    EXPECT_NEAR(h_rc, bump, 1e-9) << c.name;
  }
  // Where an engineer expects them: above the ground, below the wheel centre.
  for (const std::string corner : {"fl", "rl"}) {
    const double h = curve(r, "bump", "roll_centre_height", corner).values[1];
    EXPECT_GT(h, 0.0) << corner;
    EXPECT_LT(h, 0.3) << corner;
  }
}

TEST(SuspensionKinematics, LeftAndRightAreMirrorImages) {
  const KinematicsResult r = bump_only(nominal(sedan()), 9);
  for (const auto& [left, right] : {std::pair<std::string, std::string>{"fl", "fr"}, {"rl", "rr"}})
    for (const auto& c : sweep(r, "bump").curves) {
      if (c.corner != left) continue;
      const auto& mirrored = curve(r, "bump", c.quantity, right).values;
      for (size_t i = 0; i < c.values.size(); ++i)
        EXPECT_NEAR(c.values[i], mirrored[i], 1e-9 * (1 + std::abs(c.values[i]))) << c.quantity << " " << left;
    }
  // A rack moving left steers both wheels the same way: toe-in on one side, toe-out on the other.
  const KinematicsResult s = suspension_kinematics(sedan(), nominal(sedan()), {});
  const double fl = curve(s, "steer", "steering_gain", "fl").values[8];
  const double fr = curve(s, "steer", "steering_gain", "fr").values[8];
  EXPECT_NEAR(fl, -fr, 1e-9 * std::abs(fl));
  EXPECT_GT(std::abs(fl), 0.0);
}

TEST(SuspensionKinematics, AModelWithoutWheelSensorsIsRefusedNamingTheSensorsItNeeds) {
  const GeneratedModel* quarter = generated::find_model("quarter_car");
  ASSERT_NE(quarter, nullptr);
  try {
    suspension_kinematics(*quarter, nominal(*quarter), {});
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("axle_pos_C"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("quarter_car"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace dydp::mbs
