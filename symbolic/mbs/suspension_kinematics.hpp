// The kinematics of a car's suspension corners on its generated model, as a K&C rig measures
// them with the body clamped in its design attitude (every coordinate that moves more than one
// wheel held at zero): quasi-static sweeps of
// - wheel travel (bump and rebound, all wheels together): toe, camber, track change, spring and
//   damper compression, and their rates: bump steer, camber gain, the spring's and the damper's
//   motion ratios, the kinematic roll centre height;
// - body roll (the chassis's `roll` coordinate, the contact points held at their design
//   height): roll steer and roll camber (camber to the ground);
// - steering (the first driven coordinate, the rack, the wheel centres at their design height):
//   each steered wheel's toe and the steering gain.
// A corner is found by its sensors: axle_pos_C (a point on the spin axis, outboard of the
// centre), wheel_pos_C, contact_pos_C, and optionally spring_defl_C and damper_stroke_C.
// Every curve comes with its derivatives with respect to the model parameters asked: exact
// (implicit function theorem) for the position-level quantities; for the rates (bump steer,
// motion ratios, roll centre, ...) central differences of their exact values, which are
// themselves first derivatives (the generated code has no second derivatives).
#pragma once

#include <string>
#include <vector>

#include "symbolic/mbs/generated_model.hpp"

namespace dydp::mbs {

struct SuspensionCorner {
  std::string name;    ///< the sensors' suffix: fl, fr, ...
  double side = 1;     ///< +1 left (y > 0), -1 right
  int travel = -1;     ///< the coordinate that moves this wheel alone
  int axle = -1, centre = -1, contact = -1;  ///< x of the position sensors (kinematic outputs)
  int spring = -1, damper = -1;              ///< the length sensors, or -1
};

struct KinematicsOptions {
  double bump = 0.08;      ///< wheel travel swept: -bump .. +bump [m]
  int bump_points = 33;
  double roll = 4.0;       ///< body roll swept: -roll .. +roll [deg]
  int roll_points = 17;
  double rack = 0.04;      ///< rack travel swept [m]
  int rack_points = 17;
  std::vector<int> parameters;  ///< model parameters to differentiate in
  /// Central-difference step of the rates' derivatives, relative to max(|p|, 0.01).
  double relative_step = 1e-4;
};

struct KinematicsCurve {
  std::string corner, quantity, unit;
  std::vector<double> values;                    ///< one per sweep point
  std::vector<std::vector<double>> sensitivity;  ///< [parameter][point]
  bool exact = true;  ///< false: central differences of exact rates (KinematicsOptions::relative_step)
};

struct KinematicsSweep {
  std::string name;      ///< bump, roll, steer
  std::string variable;  ///< wheel_travel, body_roll, rack_travel
  std::string unit;
  std::vector<double> x;
  std::vector<KinematicsCurve> curves;
};

struct KinematicsResult {
  std::vector<SuspensionCorner> corners;
  std::vector<KinematicsSweep> sweeps;
  std::vector<std::string> notes;  ///< sweeps left out and why
  int poses = 0;                   ///< poses solved, the finite differences' included
};

/// The corners of a model (throws std::runtime_error naming what is missing when it has none).
std::vector<SuspensionCorner> suspension_corners(const GeneratedModel& g, const std::vector<double>& p);

KinematicsResult suspension_kinematics(const GeneratedModel& g, const std::vector<double>& p,
                                       const KinematicsOptions& options);

}  // namespace dydp::mbs
