// The diagram linearised about an operating point (t, x) with the inputs held at their values
// at t: xdot = A dx + B du, y = C dx + D du, between named signals. Every matrix comes from the
// blocks' tangents (one tangent pass per group of columns: exact, no differences). An input
// is a signal whose wire is cut: the blocks it feeds see u instead of what drives it.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "engine/framework/diagram.hpp"

namespace dydp::engine {

class Evaluator;

struct LinearModel {
  double t = 0.0;
  std::vector<double> x;                ///< the operating point
  std::vector<std::string> states;      ///< block.state
  std::vector<std::string> inputs;      ///< as named (a whole port moves all its elements)
  std::vector<std::string> outputs;     ///< one per element: block.port or block.port[i]
  Eigen::MatrixXd A, B, C, D;
  std::vector<std::pair<int, double>> held;  ///< signals held at a value (offset, value)
};

/// Signals held at given values, `NAME=VALUE` (a pad's rate at 0, so that a rig whose sine
/// starts moving at t0 holds its pads still): their wires cut, the value forced. Throws
/// InputError naming `field`.
std::vector<std::pair<int, double>> held_signals(const Diagram& d, const std::vector<std::string>& specs,
                                                 const std::string& field);

/// d(xdot)/dx at (t, x) with the signals at `held` offsets held (their tangents zero): n x n.
Eigen::MatrixXd state_jacobian(Evaluator& e, int num_states, double t, const std::vector<double>& x,
                               const std::vector<int>& held = {});

/// Linearises about (t, x). inputs, outputs: signal names (signal_lookup.hpp); an empty
/// outputs list means the scene's logged signals. Throws InputError (field --input/--output).
LinearModel linearize(const Diagram& d, double t, const std::vector<double>& x,
                      const std::vector<std::string>& inputs, const std::vector<std::string>& outputs,
                      const std::vector<std::pair<int, double>>& held = {});

/// The values of the named signals (signal_lookup.hpp, one per element) at (t, x).
std::vector<double> signal_values(const Diagram& d, double t, const std::vector<double>& x,
                                  const std::vector<std::string>& names,
                                  const std::vector<std::pair<int, double>>& held = {});

/// d(A, B, C, D)/dp for scene parameter `parameter` along the operating point's own path
/// x(p) = x + dx_dp (p - p0) (the equilibrium's, dx*/dp; zero for a fixed point): a central
/// difference of exact linearisations at p0 +- h, h = relative_step * max(|p0|, 1e-3 * its
/// range, 1e-8). Its error is O(h^2) (second derivatives of the blocks are not generated);
/// on the sedan 1e-4 and 2e-5 give the same eigenvalue derivatives to the tests' 1e-6.
struct LinearModelDerivative {
  Eigen::MatrixXd A, B, C, D;
};
LinearModelDerivative linear_model_derivative(Diagram& d, const LinearModel& m, int parameter,
                                              const Eigen::VectorXd& dx_dp, double relative_step = 1e-4);

}  // namespace dydp::engine
