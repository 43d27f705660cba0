// Scalar laws of oil hydraulics shared by the damper blocks: the orifice law smooth through zero
// pressure drop (flow from pressure, and pressure from flow for a restriction in series with a
// fluid inertia), and a directional (check-valve) orifice. Each returns its partial derivatives
// beside its value so a block's tangent applies the chain rule next to its value function.
#pragma once

namespace dydp::blocks::hydraulics {

/// K = Cd A sqrt(2 / rho) [m^3/s/Pa^0.5]: the turbulent orifice coefficient, Q = K sqrt(dp).
double orifice_coefficient(double discharge_coefficient, double section, double density);

/// Q = K dp (dp^2 + pt^2)^(-1/4) [m^3/s]: laminar Q = (K / sqrt(pt)) dp for |dp| << pt, turbulent
/// Q = K sqrt(|dp|) sign(dp) for |dp| >> pt; smooth (C-infinity) and strictly increasing in dp.
struct Flow {
  double q = 0;       ///< [m^3/s]
  double q_dp = 0;    ///< dQ/d(dp)
  double q_k = 0;     ///< dQ/dK
  double q_pt = 0;    ///< dQ/d(pt)
};
Flow flow_from_pressure(double dp, double k, double pt);

/// dp = Q sqrt(Q^2 + K^2 pt) / K^2 [Pa]: the same asymptotes as flow_from_pressure (laminar
/// dp = (sqrt(pt) / K) Q, turbulent dp = Q |Q| / K^2), written for a given flow.
struct Loss {
  double dp = 0;      ///< [Pa]
  double dp_q = 0;    ///< d(dp)/dQ
  double dp_k = 0;    ///< d(dp)/dK
  double dp_pt = 0;   ///< d(dp)/d(pt)
};
Loss pressure_from_flow(double q, double k, double pt);

/// A valve with coefficient K_fwd for dp > 0 and K_rev for dp < 0:
///   Q = K_fwd [g(pos(dp)) - g(w/2)] - K_rev [g(pos(-dp)) - g(w/2)],
/// with g(z) = z (z^2 + pt^2)^(-1/4), pos(z) = (z + sqrt(z^2 + w^2)) / 2, w = pt / 10.
/// Q(0) = 0, strictly increasing in dp, and tends to the orifice law of each side's section.
struct DirectionalFlow {
  double q = 0;
  double q_dp = 0;
  double q_kfwd = 0;
  double q_krev = 0;
  double q_pt = 0;
};
DirectionalFlow directional_flow(double dp, double k_forward, double k_reverse, double pt);

}  // namespace dydp::blocks::hydraulics
