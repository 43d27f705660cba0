#include "symbolic/mbs/suspension_kinematics.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>

#include "symbolic/mbs/kinematic_pose.hpp"

namespace dydp::mbs {
namespace {

constexpr double kDegrees = 57.29577951308232;

// A value with its derivative along one direction (the sweep variable, or a parameter).
struct Dual {
  double v = 0, d = 0;
};
Dual operator-(Dual a, Dual b) { return {a.v - b.v, a.d - b.d}; }
Dual operator*(double s, Dual a) { return {s * a.v, s * a.d}; }
Dual atan2(Dual y, Dual x) {
  const double r2 = x.v * x.v + y.v * y.v;
  return {std::atan2(y.v, x.v), (x.v * y.d - y.v * x.d) / r2};
}
Dual hypot(Dual a, Dual b) {
  const double r = std::hypot(a.v, b.v);
  return {r, (a.v * a.d + b.v * b.d) / r};
}

// The kinematic sensors with their derivatives along one direction.
class Sensors {
 public:
  Sensors(const Eigen::VectorXd& s, const Eigen::VectorXd& ds) : s_(s), ds_(ds) {}
  Dual operator[](int i) const { return {s_[i], ds_[i]}; }

 private:
  const Eigen::VectorXd& s_;
  const Eigen::VectorXd& ds_;
};

// Toe-in (the wheel's front turned towards the centre line) and camber (the top leaning out),
// in degrees, from the spin axis's outboard direction r = axle - centre.
Dual toe(const Sensors& s, const SuspensionCorner& c) {
  const Dual rx = s[c.axle] - s[c.centre], ry = s[c.axle + 1] - s[c.centre + 1];
  return kDegrees * atan2(rx, c.side * ry);
}
Dual camber(const Sensors& s, const SuspensionCorner& c) {
  const Dual rx = s[c.axle] - s[c.centre], ry = s[c.axle + 1] - s[c.centre + 1], rz = s[c.axle + 2] - s[c.centre + 2];
  return -kDegrees * atan2(rz, hypot(rx, ry));
}

// A quantity of one corner at one pose: from the sensors and their derivatives along one
// direction. A position-level quantity's value is `v` and its derivative `d`; a rate is a
// derivative itself (its value reads the sensors' rates).
struct Quantity {
  std::string name, unit;
  /// From the pose's sensors and the design pose's (`design`: the reference of a change, whose
  /// derivative w.r.t. a parameter is the design pose's and along s zero).
  std::function<Dual(const Sensors&, const Sensors& design, const SuspensionCorner&)> position;  // or
  std::function<double(const Sensors&, const SuspensionCorner&)> rate;
};

struct SweepPlan {
  std::string name, variable, unit;
  double scale = 1;  ///< x in the sweep's unit per unit of s (degrees per radian for roll)
  std::vector<double> s;
  std::function<PoseSpec(double s)> spec;
  std::vector<Quantity> quantities;
  std::vector<int> corners;
};

// The poses of a sweep, solved outwards from its middle point (each from its neighbour).
std::vector<Pose> solve_sweep(const GeneratedModel& g, const std::vector<double>& p, const SweepPlan& plan,
                              const std::vector<int>& parameters, const std::vector<Pose>* guesses, int& count) {
  const int n = static_cast<int>(plan.s.size()), middle = n / 2;
  std::vector<Pose> poses(static_cast<size_t>(n));
  auto solve = [&](int i, const Pose* from) {
    PoseSpec spec = plan.spec(plan.s[static_cast<size_t>(i)]);
    const Pose* start = guesses ? &(*guesses)[static_cast<size_t>(i)] : from;
    if (start)
      for (const int j : spec.free) spec.q[static_cast<size_t>(j)] = start->q[j];
    poses[static_cast<size_t>(i)] = solve_pose(g, p, spec, parameters);
    ++count;
  };
  solve(middle, nullptr);
  for (int i = middle + 1; i < n; ++i) solve(i, &poses[static_cast<size_t>(i - 1)]);
  for (int i = middle - 1; i >= 0; --i) solve(i, &poses[static_cast<size_t>(i + 1)]);
  return poses;
}

std::vector<double> grid(double half_range, int points) {
  if (points < 3 || points % 2 == 0) throw std::runtime_error("a sweep needs an odd number of points, at least 3");
  std::vector<double> x;
  for (int i = 0; i < points; ++i) x.push_back(half_range * (2.0 * i / (points - 1) - 1.0));
  return x;
}

// Rates of position sensors along s at one pose, per corner: the wheel centre's height rate
// (which coordinate moves the wheel) over every coordinate.
std::vector<int> dependent_coordinates(const GeneratedModel& g) {
  std::vector<char> fixed(static_cast<size_t>(g.n), 0);
  for (int i = 0; i < g.independent_count; ++i) fixed[static_cast<size_t>(g.independent[i])] = 1;
  for (int i = 0; i < g.driven_count; ++i) fixed[static_cast<size_t>(g.driven[i])] = 1;
  std::vector<int> free;
  for (int j = 0; j < g.n; ++j)
    if (!fixed[static_cast<size_t>(j)]) free.push_back(j);
  return free;
}

int coordinate(const GeneratedModel& g, const std::string& name) {
  for (int j = 0; j < g.n; ++j)
    if (name == g.coordinate_names[j]) return j;
  return -1;
}

}  // namespace

std::vector<SuspensionCorner> suspension_corners(const GeneratedModel& g, const std::vector<double>& p) {
  const KinematicSensors ks(g);
  std::vector<SuspensionCorner> corners;
  const std::string prefix = "axle_pos_";
  for (int s = 0; s < g.sensor_count; ++s) {
    const std::string port = g.sensor_ports[s];
    if (port.rfind(prefix, 0) != 0) continue;
    SuspensionCorner c;
    c.name = port.substr(prefix.size());
    c.axle = ks.index(port);
    c.centre = ks.index("wheel_pos_" + c.name);
    c.contact = ks.index("contact_pos_" + c.name);
    c.spring = ks.index("spring_defl_" + c.name);
    c.damper = ks.index("damper_stroke_" + c.name);
    if (c.axle < 0 || c.centre < 0 || c.contact < 0 || g.sensor_widths[s] != 3)
      throw std::runtime_error("model " + std::string(g.name) + ": corner " + c.name +
                               " needs the position sensors axle_pos_" + c.name + ", wheel_pos_" + c.name +
                               " and contact_pos_" + c.name);
    corners.push_back(c);
  }
  if (corners.empty())
    throw std::runtime_error("model " + std::string(g.name) +
                             " has no suspension corners: the kinematics need, per wheel C, the position sensors "
                             "axle_pos_C (a point on the spin axis), wheel_pos_C and contact_pos_C");

  // Assemble the model's initial pose, then find which independent coordinate moves each wheel
  // alone (its travel) and which move several (the body's: held at zero).
  PoseSpec spec;
  spec.q.assign(g.initial_q, g.initial_q + g.n);
  spec.free = dependent_coordinates(g);
  const Pose start = solve_pose(g, p, spec, {});
  spec.q.assign(start.q.data(), start.q.data() + g.n);
  for (auto& c : corners) c.side = start.sensors[c.centre + 1] >= 0 ? 1.0 : -1.0;
  for (int i = 0; i < g.independent_count; ++i) {
    const int j = g.independent[i];
    spec.q_rate.assign(static_cast<size_t>(g.n), 0.0);
    spec.q_rate[static_cast<size_t>(j)] = 1.0;
    const Pose moved = solve_pose(g, p, spec, {});
    int moving = 0, which = -1;
    for (size_t k = 0; k < corners.size(); ++k)
      if (std::abs(moved.sensors_rate[corners[k].centre + 2]) > 1e-6) ++moving, which = static_cast<int>(k);
    if (moving == 1) {
      SuspensionCorner& c = corners[static_cast<size_t>(which)];
      if (c.travel >= 0)
        throw std::runtime_error("model " + std::string(g.name) + ": two coordinates (" + g.coordinate_names[c.travel] +
                                 ", " + g.coordinate_names[j] + ") move wheel " + c.name + " alone");
      c.travel = j;
    }
  }
  for (const auto& c : corners)
    if (c.travel < 0)
      throw std::runtime_error("model " + std::string(g.name) + ": no independent coordinate moves wheel " + c.name +
                               " alone (its travel)");
  return corners;
}

KinematicsResult suspension_kinematics(const GeneratedModel& g, const std::vector<double>& p,
                                       const KinematicsOptions& o) {
  KinematicsResult result;
  result.corners = suspension_corners(g, p);
  const auto& corners = result.corners;

  // The design pose: the body's coordinates (independent, moving no wheel alone) at zero, the
  // wheels' travel at zero, spins and driven joints as the model starts.
  std::vector<double> q0(g.initial_q, g.initial_q + g.n);
  std::vector<char> travel(static_cast<size_t>(g.n), 0);
  for (const auto& c : corners) travel[static_cast<size_t>(c.travel)] = 1;
  for (int i = 0; i < g.independent_count; ++i) {
    const int j = g.independent[i];
    if (!travel[static_cast<size_t>(j)]) q0[static_cast<size_t>(j)] = 0.0;
  }
  for (const auto& c : corners) q0[static_cast<size_t>(c.travel)] = 0.0;
  const std::vector<int> dependent = dependent_coordinates(g);
  PoseSpec design_spec;
  design_spec.q = q0;
  design_spec.free = dependent;
  const Pose design = solve_pose(g, p, design_spec, o.parameters);
  ++result.poses;
  const Eigen::VectorXd& S0 = design.sensors;

  // Wheel travel and the other sweeps hold the wheels by targets on their positions: the
  // travel coordinates are free with the dependent ones.
  std::vector<int> free = dependent;
  for (const auto& c : corners) free.push_back(c.travel);
  auto targets = [&](bool contact, double rate) {
    std::vector<PoseTarget> t;
    for (const auto& c : corners) {
      const int z = (contact ? c.contact : c.centre) + 2;
      t.push_back({z, S0[z], rate});
    }
    return t;
  };
  std::vector<double> design_q(design.q.data(), design.q.data() + g.n);

  // The quantities.
  const Quantity toe_q{"toe", "deg", [](const Sensors& s, const Sensors&, const SuspensionCorner& c) { return toe(s, c); },
                      nullptr};
  const Quantity camber_q{"camber", "deg",
                          [](const Sensors& s, const Sensors&, const SuspensionCorner& c) { return camber(s, c); }, nullptr};
  const Quantity track_q{"track_change", "m",
                         [](const Sensors& s, const Sensors& d, const SuspensionCorner& c) {
                           return c.side * (s[c.contact + 1] - d[c.contact + 1]);
                         },
                         nullptr};
  const Quantity spring_q{"spring_compression", "m",
                          [](const Sensors& s, const Sensors& d, const SuspensionCorner& c) { return s[c.spring] - d[c.spring]; },
                          nullptr};
  const Quantity damper_q{"damper_compression", "m",
                          [](const Sensors& s, const Sensors& d, const SuspensionCorner& c) { return d[c.damper] - s[c.damper]; },
                          nullptr};
  const Eigen::VectorXd no_change = Eigen::VectorXd::Zero(S0.size());
  const Sensors design_along_s(S0, no_change);
  auto rate_of = [&](const std::string& name, const std::string& unit, const Quantity& of, double per) {
    return Quantity{name, unit, nullptr, [f = of.position, per, &design_along_s](const Sensors& s, const SuspensionCorner& c) {
                      return f(s, design_along_s, c).d / per;
                    }};
  };
  // Kinematic roll centre: the contact point moves at right angles to its line to the wheel's
  // instant centre, so that line rises by (side dy/dz) per metre inboard; over the half track
  // |y| it meets the centre plane at |y| side dy/dz above the contact point.
  const Quantity rch_q{"roll_centre_height", "m", nullptr, [](const Sensors& s, const SuspensionCorner& c) {
                         const Dual y = s[c.contact + 1], z = s[c.contact + 2];
                         return std::abs(y.v) * c.side * y.d / z.d;
                       }};

  std::vector<SweepPlan> plans;
  {
    SweepPlan bump{"bump", "wheel_travel", "m", 1.0, grid(o.bump, o.bump_points), nullptr, {}, {}};
    bump.spec = [=](double s) {
      PoseSpec spec{design_q, {}, free, targets(false, 1.0)};
      for (auto& t : spec.targets) t.value += s;
      return spec;
    };
    bump.quantities = {toe_q, camber_q, track_q};
    const bool springs = std::all_of(corners.begin(), corners.end(), [](const auto& c) { return c.spring >= 0; });
    const bool dampers = std::all_of(corners.begin(), corners.end(), [](const auto& c) { return c.damper >= 0; });
    if (springs) bump.quantities.push_back(spring_q);
    if (dampers) bump.quantities.push_back(damper_q);
    bump.quantities.push_back(rate_of("bump_steer", "deg/m", toe_q, 1.0));
    bump.quantities.push_back(rate_of("camber_gain", "deg/m", camber_q, 1.0));
    if (springs) bump.quantities.push_back(rate_of("spring_ratio", "m/m", spring_q, 1.0));
    if (dampers) bump.quantities.push_back(rate_of("damper_ratio", "m/m", damper_q, 1.0));
    bump.quantities.push_back(rch_q);
    for (size_t k = 0; k < corners.size(); ++k) bump.corners.push_back(static_cast<int>(k));
    plans.push_back(bump);
  }
  const int roll = coordinate(g, "roll");
  if (roll >= 0 && !travel[static_cast<size_t>(roll)]) {
    SweepPlan sweep{"roll", "body_roll", "deg", kDegrees, grid(o.roll / kDegrees, o.roll_points), nullptr, {}, {}};
    sweep.spec = [=](double s) {
      PoseSpec spec{design_q, std::vector<double>(static_cast<size_t>(g.n), 0.0), free, targets(true, 0.0)};
      spec.q[static_cast<size_t>(roll)] = s;
      spec.q_rate[static_cast<size_t>(roll)] = 1.0;
      return spec;
    };
    sweep.quantities = {toe_q, camber_q, rate_of("roll_steer", "deg/deg", toe_q, kDegrees),
                        rate_of("roll_camber", "deg/deg", camber_q, kDegrees)};
    for (size_t k = 0; k < corners.size(); ++k) sweep.corners.push_back(static_cast<int>(k));
    plans.push_back(sweep);
  } else {
    result.notes.push_back("no body roll sweep: the model has no coordinate named roll");
  }
  if (g.driven_count > 0) {
    const int rack = g.driven[0];
    SweepPlan sweep{"steer", std::string(g.coordinate_names[rack]) + "_travel", "m", 1.0,
                    grid(o.rack, o.rack_points), nullptr, {}, {}};
    sweep.spec = [=](double s) {
      PoseSpec spec{design_q, std::vector<double>(static_cast<size_t>(g.n), 0.0), free, targets(false, 0.0)};
      spec.q[static_cast<size_t>(rack)] = s;
      spec.q_rate[static_cast<size_t>(rack)] = 1.0;
      return spec;
    };
    sweep.quantities = {toe_q, rate_of("steering_gain", "deg/m", toe_q, 1.0)};
    // the wheels the rack steers
    const Pose at = solve_pose(g, p, sweep.spec(0.0), {});
    ++result.poses;
    for (size_t k = 0; k < corners.size(); ++k)
      if (std::abs(toe(Sensors(at.sensors, at.sensors_rate), corners[k]).d) > 1e-6)
        sweep.corners.push_back(static_cast<int>(k));
    plans.push_back(sweep);
  } else {
    result.notes.push_back("no steering sweep: the model has no driven coordinate");
  }

  const int np = static_cast<int>(o.parameters.size());
  for (const auto& plan : plans) {
    const std::vector<Pose> poses = solve_sweep(g, p, plan, o.parameters, nullptr, result.poses);
    // The rates' derivatives: central differences of the exact rates at p +- h.
    std::vector<std::vector<Pose>> plus, minus;
    std::vector<double> steps;
    const bool has_rates =
        std::any_of(plan.quantities.begin(), plan.quantities.end(), [](const Quantity& q) { return bool(q.rate); });
    for (int j = 0; has_rates && j < np; ++j) {
      const int pj = o.parameters[static_cast<size_t>(j)];
      const double h = o.relative_step * std::max(std::abs(p[static_cast<size_t>(pj)]), 0.01);
      std::vector<double> pp = p, pm = p;
      pp[static_cast<size_t>(pj)] += h;
      pm[static_cast<size_t>(pj)] -= h;
      plus.push_back(solve_sweep(g, pp, plan, {}, &poses, result.poses));
      minus.push_back(solve_sweep(g, pm, plan, {}, &poses, result.poses));
      steps.push_back(h);
    }
    KinematicsSweep sweep{plan.name, plan.variable, plan.unit, {}, {}};
    for (const double s : plan.s) sweep.x.push_back(s * plan.scale);
    for (const auto& quantity : plan.quantities) {
      for (const int k : plan.corners) {
        const SuspensionCorner& c = corners[static_cast<size_t>(k)];
        KinematicsCurve curve{c.name, quantity.name, quantity.unit, {}, {}, !quantity.rate};
        curve.sensitivity.assign(static_cast<size_t>(np), {});
        for (size_t i = 0; i < poses.size(); ++i) {
          const Pose& pose = poses[i];
          if (quantity.position) {
            curve.values.push_back(quantity.position(Sensors(pose.sensors, pose.sensors_rate), design_along_s, c).v);
            for (int j = 0; j < np; ++j) {
              const Eigen::VectorXd column = pose.sensors_dp.col(j), design_column = design.sensors_dp.col(j);
              const Sensors reference(S0, design_column);
              curve.sensitivity[static_cast<size_t>(j)].push_back(
                  quantity.position(Sensors(pose.sensors, column), reference, c).d);
            }
          } else {
            curve.values.push_back(quantity.rate(Sensors(pose.sensors, pose.sensors_rate), c));
            for (int j = 0; j < np; ++j) {
              const Pose& a = plus[static_cast<size_t>(j)][i];
              const Pose& b = minus[static_cast<size_t>(j)][i];
              const double up = quantity.rate(Sensors(a.sensors, a.sensors_rate), c);
              const double down = quantity.rate(Sensors(b.sensors, b.sensors_rate), c);
              curve.sensitivity[static_cast<size_t>(j)].push_back((up - down) / (2 * steps[static_cast<size_t>(j)]));
            }
          }
        }
        sweep.curves.push_back(std::move(curve));
      }
    }
    result.sweeps.push_back(std::move(sweep));
  }
  return result;
}

}  // namespace dydp::mbs
