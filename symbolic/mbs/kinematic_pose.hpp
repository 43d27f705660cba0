// Quasi-static poses of a generated model: its coordinates split into held ones (given values)
// and free ones, solved by Newton-Raphson from the loop constraints h(q) = 0 and targets on
// kinematic sensor components (a wheel centre's height, say). Each pose comes with the
// derivatives of every kinematic sensor output along a sweep variable s (the targets and the
// held coordinates may move with s) and with respect to the model's parameters, by the implicit
// function theorem: one LU of the pose's Jacobian [J_free; dS_targets/dq_free], one solve per
// direction. Used by the kinematics analyses (dydp kc).
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "symbolic/mbs/generated_model.hpp"

namespace dydp::mbs {

/// Where each sensor port's components sit among the kinematic sensors' outputs (the ports
/// that read no acceleration, in port order, as `sensors_kinematic` writes them).
class KinematicSensors {
 public:
  explicit KinematicSensors(const GeneratedModel& g);
  int size() const { return size_; }
  /// The output index of `port`'s component (0 for a scalar port), or -1: no such port, or a
  /// port that reads accelerations.
  int index(const std::string& port, int component = 0) const;

 private:
  const GeneratedModel& g_;
  std::vector<int> offset_;  ///< per port: first output index, or -1 (an acceleration port)
  int size_ = 0;
};

struct PoseTarget {
  int sensor = 0;     ///< kinematic sensor output index
  double value = 0;   ///< required value
  double rate = 0;    ///< d value / d s
};

struct PoseSpec {
  std::vector<double> q;       ///< n: the held coordinates' values; the free ones' start
  std::vector<double> q_rate;  ///< n, or empty (zero): d q / d s of the held coordinates
  std::vector<int> free;       ///< coordinates solved for: m + targets of them
  std::vector<PoseTarget> targets;
};

struct Pose {
  Eigen::VectorXd q;
  Eigen::VectorXd sensors;       ///< every kinematic sensor output
  Eigen::VectorXd sensors_rate;  ///< their derivatives along s
  Eigen::MatrixXd sensors_dp;    ///< their derivatives w.r.t. the parameters asked (one column each)
  int iterations = 0;
  double residual = 0;           ///< max |h|, |S - target| at the solution
};

/// The pose `spec` describes, with parameters p (g.parameters values) and derivatives with
/// respect to the parameters `parameters` (indices into p). Throws std::runtime_error naming
/// the failure when the pose's Jacobian is singular or Newton does not converge.
Pose solve_pose(const GeneratedModel& g, const std::vector<double>& p, const PoseSpec& spec,
                const std::vector<int>& parameters);

}  // namespace dydp::mbs
