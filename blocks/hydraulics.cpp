#include "blocks/hydraulics.hpp"

#include <cmath>

namespace dydp::blocks::hydraulics {

namespace {

/// g(z; pt) = z (z^2 + pt^2)^(-1/4) with dg/dz = (z^2/2 + pt^2)(z^2 + pt^2)^(-5/4) and
/// dg/dpt = -z pt / 2 (z^2 + pt^2)^(-5/4).
struct Shape {
  double g, g_z, g_pt;
};
Shape shape(double z, double pt) {
  const double r = z * z + pt * pt;
  const double r14 = 1.0 / std::sqrt(std::sqrt(r));  // r^(-1/4), by square roots (cheaper than pow)
  const double r54 = r14 / r;
  return {z * r14, (0.5 * z * z + pt * pt) * r54, -0.5 * z * pt * r54};
}

}  // namespace

double orifice_coefficient(double discharge_coefficient, double section, double density) {
  return discharge_coefficient * section * std::sqrt(2.0 / density);
}

Flow flow_from_pressure(double dp, double k, double pt) {
  const Shape s = shape(dp, pt);
  return {k * s.g, k * s.g_z, s.g, k * s.g_pt};
}

Loss pressure_from_flow(double q, double k, double pt) {
  const double r = std::sqrt(q * q + k * k * pt);
  const double k2 = k * k;
  const double dp = q * r / k2;
  return {dp, (r + q * q / r) / k2, q * pt / (k * r) - 2.0 * dp / k, q / (2.0 * r)};
}

DirectionalFlow directional_flow(double dp, double k_forward, double k_reverse, double pt) {
  const double w = 0.1 * pt;
  const double root = std::sqrt(dp * dp + w * w);
  const double pos_f = 0.5 * (dp + root), pos_r = 0.5 * (-dp + root);
  // d pos / d dp and d pos / d pt (through w = pt / 10).
  const double posf_dp = 0.5 * (1.0 + dp / root), posr_dp = 0.5 * (-1.0 + dp / root);
  const double pos_pt = 0.5 * w / root * 0.1;
  const Shape f = shape(pos_f, pt), r = shape(pos_r, pt), z = shape(0.5 * w, pt);
  const double z_pt = z.g_z * 0.05 + z.g_pt;  // d g(pt/20; pt) / d pt
  DirectionalFlow out;
  out.q = k_forward * (f.g - z.g) - k_reverse * (r.g - z.g);
  out.q_dp = k_forward * f.g_z * posf_dp - k_reverse * r.g_z * posr_dp;
  out.q_kfwd = f.g - z.g;
  out.q_krev = -(r.g - z.g);
  out.q_pt = k_forward * (f.g_z * pos_pt + f.g_pt - z_pt) - k_reverse * (r.g_z * pos_pt + r.g_pt - z_pt);
  return out;
}

}  // namespace dydp::blocks::hydraulics
