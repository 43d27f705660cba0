// The static equilibrium of a scene with its inputs held at their values at one time: the
// state x* where every state derivative vanishes, by damped Newton on xdot(x) = 0 in the
// states' nominal units, from the scene's initial state; and dx*/dp for the scene's parameters
// and directions by the implicit function theorem, A dx*/dp = -df/dp (one solve with the
// diagram's Jacobian for them all). A diagram with conserved quantities (the oil in a damper, a
// free body's momentum: A singular) has a family of equilibria: the one found keeps them at
// their initial values, as a run from the initial state would; coordinates that no force holds
// (a free body's position, a wheel's spin) stay where the settling motion leaves them.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "engine/framework/diagram.hpp"

namespace dydp::engine {

struct EquilibriumOptions {
  double time = 0.0;          ///< the inputs are held at their values at this time
  std::vector<std::pair<int, double>> held;  ///< signals held at other values (held_signals)
  int max_iterations = 60;
  double tolerance = 1e-12;   ///< on the largest Newton step in nominal units
  /// With conserved quantities: the time [s] and the implicit Euler steps (and twice as many)
  /// over which the state first moves toward x* (see equilibrium.cpp, settle).
  double settle_time = 4.0;
  int settle_steps = 400;
};

struct Equilibrium {
  double t = 0.0;
  std::vector<double> x;              ///< x*
  std::vector<double> initial;        ///< the scene's initial state it started from
  std::vector<std::string> states;    ///< block.state
  /// max_i |xdot_i(x*)| / nominal_i [1/s]: what is left of the state derivatives.
  double residual = 0.0;
  int iterations = 0;
  int rank_deficiency = 0;            ///< conserved quantities and free coordinates (A's left null space)
  std::vector<std::pair<int, double>> held;  ///< as the options gave them
  std::vector<int> parameters;        ///< scene parameter indices of the columns of dx_dp
  Eigen::MatrixXd dx_dp;              ///< n x parameters
};

/// Throws SolverError (t, the block whose state derivative is largest, the residual) when
/// Newton does not reach the tolerance: a scene with no equilibrium in reach (a car driving
/// on, a steady flow).
Equilibrium find_equilibrium(Diagram& d, const EquilibriumOptions& options = {});

}  // namespace dydp::engine
