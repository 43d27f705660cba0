// tyre.mf: handling tyre forces by a simplified Magic Formula: pure-slip curves with load-
// dependent friction, combined slip by cosine weighting functions, aligning torque through a
// pneumatic trail, and relaxation lengths as first-order lags on the slips (the states).
// Wheel frame: x forward, y left, z up. Coefficients and signs in docs/blocks.md.
#include <cmath>
#include <limits>

#include "engine/framework/registry.hpp"

namespace dydp::blocks {
namespace {

using engine::Block;
using engine::DirView;
using engine::Eval;
using engine::Seeds;

constexpr double kInf = std::numeric_limits<double>::infinity();

enum Param {
  kRadius, kMu, kFzNominal, kLoadFriction, kBx, kCx, kEx, kBy, kCy, kEy, kBxAlpha, kByKappa,
  kRelaxX, kRelaxY, kTrail, kTrailDecay, kSpeedFloor, kCorneringLoad
};
enum Input { kFz, kVx, kVy, kOmega };
enum State { kKappa, kAlpha };
enum Output { kFx, kFy, kMz, kSlipRatio, kSlipAngle };

/// y = sin(C atan(B x - E (B x - atan(B x)))) and its tangent for seeds dx, dB, dC, dE.
struct MagicFormula {
  double y, w, v, u, cos_cw;
  MagicFormula(double x, double b, double c, double e) {
    u = b * x;
    v = u - e * (u - std::atan(u));
    w = std::atan(v);
    y = std::sin(c * w);
    cos_cw = std::cos(c * w);
  }
  double tangent(double x, double b, double c, double e, double dx, double db, double dc, double de) const {
    const double du = db * x + b * dx;
    const double dv = du - de * (u - std::atan(u)) - e * (du - du / (1 + u * u));
    const double dw = dv / (1 + v * v);
    return cos_cw * (dc * w + c * dw);
  }
};

/// Lateral stiffness factor at load Fz: B_y(Fz) = By (k^2 + 1) / ((k^2 + f^2) (1 + pD2 (f - 1))),
/// f = Fz / Fz0, k = cornering_load, so that the cornering stiffness B_y Cy mu Fz equals
/// By Cy mu0 Fz0 sin(2 atan(f / k)) / sin(2 atan(1 / k)) (the MF 5.2 law of pKy1, pKy2): it
/// is By Cy mu0 Fz0 at Fz0, peaks at Fz = k Fz0, and grows less than the load (so a load
/// transfer across an axle costs the axle cornering stiffness). Returns B and its tangent.
struct LateralStiffness {
  double b;
  LateralStiffness(const double* p, double fz) {
    const double f = fz / p[kFzNominal], k = p[kCorneringLoad];
    b = p[kBy] * (k * k + 1) / ((k * k + f * f) * (1 + p[kLoadFriction] * (f - 1)));
  }
  double tangent(const double* p, double fz, double dfz, double dby, double dfz0, double dpd2, double dk) const {
    const double fz0 = p[kFzNominal], f = fz / fz0, k = p[kCorneringLoad], m = 1 + p[kLoadFriction] * (f - 1);
    const double df = dfz / fz0 - f * dfz0 / fz0;
    const double dm = dpd2 * (f - 1) + p[kLoadFriction] * df;
    return b * (dby / p[kBy] + 2 * k * dk / (k * k + 1) - 2 * (k * dk + f * df) / (k * k + f * f) - dm / m);
  }
};

/// Weighting G(x) = cos(atan(B x)) = 1 / sqrt(1 + (B x)^2), and its tangent.
double weight(double b, double x) { return 1 / std::sqrt(1 + b * b * x * x); }
double weight_tangent(double b, double x, double db, double dx) {
  const double g = weight(b, x);
  return -g * g * g * b * x * (db * x + b * dx);
}

class TyreMf : public Block {
 public:
  TyreMf() {
    declare_input("fz", 1, "N", true);
    declare_input("vx", 1, "m/s", false);
    declare_input("vy", 1, "m/s", false);
    declare_input("omega", 1, "rad/s", false);
    declare_output("fx", 1, "N", true);
    declare_output("fy", 1, "N", true);
    declare_output("mz", 1, "N m", true);
    declare_output("slip_ratio", 1, "", false);
    declare_output("slip_angle", 1, "rad", false);
    // Nominal magnitudes: 0.1, where the force curves bend (peak slip ratio ~0.1, slip angle ~0.1 rad).
    declare_states({"slip_ratio", "slip_angle"}, {0.1, 0.1});
  }

  void initial_state(const Eval&, double* x0) const override { x0[kKappa] = x0[kAlpha] = 0.0; }
  void initial_state_tangent(const Eval&, const Seeds& s, DirView dx0) const override {
    for (int d = 0; d < s.directions; ++d) dx0(kKappa, d) = dx0(kAlpha, d) = 0.0;
  }

  /// mu(Fz) = mu0 (1 + pD2 (Fz - Fz0) / Fz0); Fx = mu Fz MFx(kappa) G(alpha);
  /// Fy = mu Fz MFy(alpha; B_y(Fz)) G(kappa); Mz = -t(alpha) Fy, t = t0 / sqrt(1 + (Bt alpha)^2).
  void outputs(const Eval& e, double* const* y) const override {
    const double* p = e.p;
    const double kappa = e.x[kKappa], alpha = e.x[kAlpha];
    y[kSlipRatio][0] = kappa;
    y[kSlipAngle][0] = alpha;
    if (!e.inputs_ready) return;
    const double fz = e.u[kFz][0];
    const double mu = p[kMu] * (1 + p[kLoadFriction] * (fz - p[kFzNominal]) / p[kFzNominal]);
    const LateralStiffness by(p, fz);
    const MagicFormula mx(kappa, p[kBx], p[kCx], p[kEx]), my(alpha, by.b, p[kCy], p[kEy]);
    const double fy = mu * fz * my.y * weight(p[kByKappa], kappa);
    y[kFx][0] = mu * fz * mx.y * weight(p[kBxAlpha], alpha);
    y[kFy][0] = fy;
    y[kMz][0] = -p[kTrail] * weight(p[kTrailDecay], alpha) * fy;
  }
  void outputs_tangent(const Eval& e, const Seeds& s, const DirView* dy) const override {
    const double* p = e.p;
    const double kappa = e.x[kKappa], alpha = e.x[kAlpha];
    for (int d = 0; d < s.directions; ++d) {
      dy[kSlipRatio](0, d) = s.x(kKappa, d);
      dy[kSlipAngle](0, d) = s.x(kAlpha, d);
    }
    if (!e.inputs_ready) return;
    const double fz = e.u[kFz][0], fz0 = p[kFzNominal];
    const double load = (fz - fz0) / fz0;
    const double mu = p[kMu] * (1 + p[kLoadFriction] * load);
    const LateralStiffness by(p, fz);
    const MagicFormula mx(kappa, p[kBx], p[kCx], p[kEx]), my(alpha, by.b, p[kCy], p[kEy]);
    const double gx = weight(p[kBxAlpha], alpha), gy = weight(p[kByKappa], kappa), gt = weight(p[kTrailDecay], alpha);
    const double fy = mu * fz * my.y * gy;
    for (int d = 0; d < s.directions; ++d) {
      const auto dp = [&](int j) { return s.p(j, d); };
      const double dk = s.x(kKappa, d), da = s.x(kAlpha, d), dfz = s.u[kFz](0, d);
      const double d_load = (dfz - dp(kFzNominal)) / fz0 - load * dp(kFzNominal) / fz0;
      const double d_mu = dp(kMu) * (1 + p[kLoadFriction] * load) + p[kMu] * (dp(kLoadFriction) * load + p[kLoadFriction] * d_load);
      const double d_mufz = d_mu * fz + mu * dfz;
      const double d_mx = mx.tangent(kappa, p[kBx], p[kCx], p[kEx], dk, dp(kBx), dp(kCx), dp(kEx));
      const double d_by = by.tangent(p, fz, dfz, dp(kBy), dp(kFzNominal), dp(kLoadFriction), dp(kCorneringLoad));
      const double d_my = my.tangent(alpha, by.b, p[kCy], p[kEy], da, d_by, dp(kCy), dp(kEy));
      const double d_gx = weight_tangent(p[kBxAlpha], alpha, dp(kBxAlpha), da);
      const double d_gy = weight_tangent(p[kByKappa], kappa, dp(kByKappa), dk);
      const double d_gt = weight_tangent(p[kTrailDecay], alpha, dp(kTrailDecay), da);
      const double d_fy = d_mufz * my.y * gy + mu * fz * (d_my * gy + my.y * d_gy);
      dy[kFx](0, d) = d_mufz * mx.y * gx + mu * fz * (d_mx * gx + mx.y * d_gx);
      dy[kFy](0, d) = d_fy;
      dy[kMz](0, d) = -(dp(kTrail) * gt * fy + p[kTrail] * (d_gt * fy + gt * d_fy));
    }
  }

  /// Kinematic slips with the smoothed speed V = sqrt(vx^2 + v0^2):
  ///   kappa = (omega R - vx) / V,  alpha = atan(-vy / V);
  /// relaxation: dkappa_t/dt = V / sigma_x (kappa - kappa_t), dalpha_t/dt = V / sigma_y (alpha - alpha_t).
  void derivatives(const Eval& e, double* xdot) const override {
    const double* p = e.p;
    const double vx = e.u[kVx][0], vy = e.u[kVy][0], omega = e.u[kOmega][0];
    const double speed = std::sqrt(vx * vx + p[kSpeedFloor] * p[kSpeedFloor]);
    const double kappa = (omega * p[kRadius] - vx) / speed, alpha = std::atan(-vy / speed);
    xdot[kKappa] = speed / p[kRelaxX] * (kappa - e.x[kKappa]);
    xdot[kAlpha] = speed / p[kRelaxY] * (alpha - e.x[kAlpha]);
  }
  void derivatives_tangent(const Eval& e, const Seeds& s, DirView dxdot) const override {
    const double* p = e.p;
    const double vx = e.u[kVx][0], vy = e.u[kVy][0], omega = e.u[kOmega][0], v0 = p[kSpeedFloor];
    const double speed = std::sqrt(vx * vx + v0 * v0);
    const double kappa = (omega * p[kRadius] - vx) / speed, ratio = -vy / speed, alpha = std::atan(ratio);
    const double gap_k = kappa - e.x[kKappa], gap_a = alpha - e.x[kAlpha];
    for (int d = 0; d < s.directions; ++d) {
      const double dvx = s.u[kVx](0, d), dvy = s.u[kVy](0, d), domega = s.u[kOmega](0, d);
      const double d_speed = (vx * dvx + v0 * s.p(kSpeedFloor, d)) / speed;
      const double d_kappa = (domega * p[kRadius] + omega * s.p(kRadius, d) - dvx) / speed - kappa * d_speed / speed;
      const double d_ratio = -dvy / speed - ratio * d_speed / speed;
      const double d_alpha = d_ratio / (1 + ratio * ratio);
      const double sx = p[kRelaxX], sy = p[kRelaxY];
      dxdot(kKappa, d) = (d_speed / sx - speed * s.p(kRelaxX, d) / (sx * sx)) * gap_k +
                         speed / sx * (d_kappa - s.x(kKappa, d));
      dxdot(kAlpha, d) = (d_speed / sy - speed * s.p(kRelaxY, d) / (sy * sy)) * gap_a +
                         speed / sy * (d_alpha - s.x(kAlpha, d));
    }
  }
};

const engine::BlockRegistration tyre_mf({
    "tyre.mf", "tyres",
    "Simplified Magic Formula tyre: Fx, Fy (combined slip), Mz (pneumatic trail); slips lagged by relaxation lengths.",
    {{"rolling_radius", "m", 0.31, false, 1e-3, kInf, "effective rolling radius R"},
     {"mu", "", 1.0, false, 0.0, kInf, "friction coefficient at the nominal load"},
     {"fz_nominal", "N", 4000.0, false, 1.0, kInf, "nominal load Fz0"},
     {"load_friction", "", -0.1, false, -1.0, 1.0, "pD2: relative change of friction per relative load change"},
     {"bx", "", 10.0, false, 0.0, kInf, "longitudinal stiffness factor B"},
     {"cx", "", 1.65, false, 0.0, 2.0, "longitudinal shape factor C"},
     {"ex", "", 0.97, false, -kInf, 1.0, "longitudinal curvature factor E"},
     {"by", "", 10.0, false, 0.0, kInf, "lateral stiffness factor B"},
     {"cy", "", 1.9, false, 0.0, 2.0, "lateral shape factor C"},
     {"ey", "", 0.97, false, -kInf, 1.0, "lateral curvature factor E"},
     {"bx_alpha", "", 10.0, false, 0.0, kInf, "combined slip: reduction of Fx with slip angle"},
     {"by_kappa", "", 10.0, false, 0.0, kInf, "combined slip: reduction of Fy with slip ratio"},
     {"relaxation_x", "m", 0.15, false, 1e-4, kInf, "longitudinal relaxation length"},
     {"relaxation_y", "m", 0.45, false, 1e-4, kInf, "lateral relaxation length"},
     {"trail", "m", 0.03, false, 0.0, kInf, "pneumatic trail at zero slip angle"},
     {"trail_decay", "", 8.0, false, 0.0, kInf, "decay of the trail with slip angle"},
     {"speed_floor", "m/s", 0.5, false, 1e-6, kInf, "speed below which slips are rounded (V = sqrt(vx^2 + v0^2))"},
     {"cornering_load", "", 2.0, false, 1e-3, kInf, "pKy2: load (in units of fz_nominal) at which the cornering stiffness peaks"}},
    {},
    [](const engine::BlockSettings&) -> std::unique_ptr<Block> { return std::make_unique<TyreMf>(); }});

}  // namespace
}  // namespace dydp::blocks
