// damper.cdc: a semi-active (CDC-type) twin-tube hydraulic damper with oil compressibility.
// States: rebound, compression and reservoir pressures [Pa] and the flow in the pipe to the
// external electro-valve [m^3/s]. Conventions: stroke > 0 is extension (rod out), force > 0 is
// tension (resists extension). Laws in docs/blocks.md, section damper.cdc.
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

#include "blocks/hydraulics.hpp"
#include "engine/framework/registry.hpp"

namespace dydp::blocks {
namespace {

using engine::Block;
using engine::DirView;
using engine::Eval;
using engine::OutOfDomain;
using engine::Seeds;
namespace hyd = hydraulics;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kCurrentMin = 0.3, kCurrentMax = 1.6;  // [A] the electro-valve's range

enum Param {
  kCurrent, kSectionHard, kSectionSoft, kPortSection, kPistonDiameter, kRodDiameter, kDensity,
  kBulkModulus, kDischarge, kTransition, kPistonRebound, kPistonCheck, kBaseCompression,
  kBaseIntake, kPipeLength, kPipeSection, kReboundVolume, kCompressionVolume, kGasVolume,
  kPrecharge, kPolytropic, kAtmosphere, kFriction, kFrictionVelocity, kNumParams
};
enum State { kPReb, kPComp, kPRes, kQValve };
enum Output { kForce, kPRebOut, kPCompOut, kPResOut, kPower };

/// Every intermediate of the damper's laws at one point, with the partials the tangent needs.
struct Point {
  double area_piston, area_rod, area_annulus;        // [m^2]
  double xi, valve_section;                          // current fraction, electro-valve [m^2]
  double root2rho;                                   // sqrt(2 / rho)
  double k_valve, k_port, k_pr, k_pc, k_bc, k_bi;    // orifice coefficients
  double v_reb, v_comp, v_gas;                       // volumes [m^3]
  double inertance;                                  // rho L / A_pipe [kg/m^4]
  hyd::DirectionalFlow piston, base;                 // flows reb->comp, comp->res
  hyd::Loss valve, port;                             // losses along the pipe for flow q
  double rate;                                       // stroke rate [m/s]
  double th;                                         // tanh(v / v_f)
  double pdot_reb, pdot_comp, pdot_res, qdot;
  double force, power;
};

/// Section of the electro-valve: geometric interpolation between the hard section at 0.3 A and
/// the soft one at 1.6 A, A_v = A_hard (A_soft / A_hard)^xi, xi = (i - 0.3) / 1.3.
/// with_inputs: also what the stroke and its rate enter (the chambers' derivatives); forces:
/// also the force and the power (not needed for the derivatives alone).
Point evaluate(const Eval& e, bool with_inputs, bool forces = true) {
  const double* p = e.p;
  const double* x = e.x;
  Point o{};
  o.area_piston = std::numbers::pi / 4 * p[kPistonDiameter] * p[kPistonDiameter];
  o.area_rod = std::numbers::pi / 4 * p[kRodDiameter] * p[kRodDiameter];
  o.area_annulus = o.area_piston - o.area_rod;
  o.xi = (p[kCurrent] - kCurrentMin) / (kCurrentMax - kCurrentMin);
  o.valve_section = p[kSectionHard] * std::pow(p[kSectionSoft] / p[kSectionHard], o.xi);
  o.root2rho = std::sqrt(2.0 / p[kDensity]);
  const double cd = p[kDischarge];
  o.k_valve = cd * o.valve_section * o.root2rho;
  o.k_port = cd * p[kPortSection] * o.root2rho;
  o.k_pr = cd * p[kPistonRebound] * o.root2rho;
  o.k_pc = cd * p[kPistonCheck] * o.root2rho;
  o.k_bc = cd * p[kBaseCompression] * o.root2rho;
  o.k_bi = cd * p[kBaseIntake] * o.root2rho;
  const double pt = p[kTransition];
  o.piston = hyd::directional_flow(x[kPReb] - x[kPComp], o.k_pr, o.k_pc, pt);
  o.base = hyd::directional_flow(x[kPComp] - x[kPRes], o.k_bc, o.k_bi, pt);
  o.valve = hyd::pressure_from_flow(x[kQValve], o.k_valve, pt);
  o.port = hyd::pressure_from_flow(x[kQValve], o.k_port, pt);
  if (!(x[kPRes] > 0)) throw OutOfDomain{"reservoir pressure is not positive"};
  o.v_gas = p[kGasVolume] * std::pow(p[kPrecharge] / x[kPRes], 1.0 / p[kPolytropic]);
  o.inertance = p[kDensity] * p[kPipeLength] / p[kPipeSection];
  o.pdot_res = p[kPolytropic] * x[kPRes] / o.v_gas * (o.base.q + x[kQValve]);
  o.qdot = (x[kPReb] - x[kPRes] - o.valve.dp - o.port.dp) / o.inertance;
  if (!with_inputs) return o;
  const double stroke = e.u[0][0];
  o.rate = e.u[1][0];
  o.v_reb = p[kReboundVolume] - o.area_annulus * stroke;
  o.v_comp = p[kCompressionVolume] + o.area_piston * stroke;
  if (!(o.v_reb > 0) || !(o.v_comp > 0)) throw OutOfDomain{"stroke beyond the chambers' length"};
  const double b = p[kBulkModulus];
  o.pdot_reb = b / o.v_reb * (o.area_annulus * o.rate - o.piston.q - x[kQValve]);
  o.pdot_comp = b / o.v_comp * (o.piston.q - o.base.q - o.area_piston * o.rate);
  if (!forces) return o;
  const double hydraulic_power =
      o.piston.q * (x[kPReb] - x[kPComp]) + o.base.q * (x[kPComp] - x[kPRes]) +
      x[kQValve] * (o.valve.dp + o.port.dp);
  o.th = std::tanh(o.rate / p[kFrictionVelocity]);
  const double friction = p[kFriction] * o.th;
  o.force = x[kPReb] * o.area_annulus - x[kPComp] * o.area_piston + p[kAtmosphere] * o.area_rod + friction;
  o.power = hydraulic_power + friction * o.rate;
  return o;
}

/// Tangents of the quantities of evaluate() in direction d, in the same order.
struct PointTangent {
  double pdot_reb, pdot_comp, pdot_res, qdot, force, power;
};

/// The logarithms the tangent reads, the same for every direction: ln(A_soft / A_hard) and
/// ln(p0 / p_res).
struct TangentLogs {
  double section_ratio, precharge_ratio;
};
TangentLogs tangent_logs(const Eval& e) {
  return {std::log(e.p[kSectionSoft] / e.p[kSectionHard]), std::log(e.p[kPrecharge] / e.x[kPRes])};
}

PointTangent tangent(const Eval& e, const Point& o, const TangentLogs& logs, const Seeds& s, int d, bool with_inputs) {
  const double* p = e.p;
  const double* x = e.x;
  const auto dp = [&](int j) { return s.p(j, d); };
  const double dx_reb = s.x(kPReb, d), dx_comp = s.x(kPComp, d), dx_res = s.x(kPRes, d),
               dx_q = s.x(kQValve, d);
  const double d_area_piston = std::numbers::pi / 2 * p[kPistonDiameter] * dp(kPistonDiameter);
  const double d_area_rod = std::numbers::pi / 2 * p[kRodDiameter] * dp(kRodDiameter);
  const double d_area_annulus = d_area_piston - d_area_rod;
  const double d_xi = dp(kCurrent) / (kCurrentMax - kCurrentMin);
  const double log_ratio = logs.section_ratio;
  const double d_valve_section =
      o.valve_section * ((1 - o.xi) * dp(kSectionHard) / p[kSectionHard] +
                         o.xi * dp(kSectionSoft) / p[kSectionSoft] + log_ratio * d_xi);
  // dK / K = dCd / Cd + dA / A - drho / (2 rho)
  const double common = dp(kDischarge) / p[kDischarge] - 0.5 * dp(kDensity) / p[kDensity];
  const auto d_k = [&](double k, double section, double d_section) {
    return k * (common + d_section / section);
  };
  const double dk_valve = d_k(o.k_valve, o.valve_section, d_valve_section);
  const double dk_port = d_k(o.k_port, p[kPortSection], dp(kPortSection));
  const double dk_pr = d_k(o.k_pr, p[kPistonRebound], dp(kPistonRebound));
  const double dk_pc = d_k(o.k_pc, p[kPistonCheck], dp(kPistonCheck));
  const double dk_bc = d_k(o.k_bc, p[kBaseCompression], dp(kBaseCompression));
  const double dk_bi = d_k(o.k_bi, p[kBaseIntake], dp(kBaseIntake));
  const double dpt = dp(kTransition);
  const double d_piston_q = o.piston.q_dp * (dx_reb - dx_comp) + o.piston.q_kfwd * dk_pr +
                            o.piston.q_krev * dk_pc + o.piston.q_pt * dpt;
  const double d_base_q = o.base.q_dp * (dx_comp - dx_res) + o.base.q_kfwd * dk_bc +
                          o.base.q_krev * dk_bi + o.base.q_pt * dpt;
  const double d_valve_dp = o.valve.dp_q * dx_q + o.valve.dp_k * dk_valve + o.valve.dp_pt * dpt;
  const double d_port_dp = o.port.dp_q * dx_q + o.port.dp_k * dk_port + o.port.dp_pt * dpt;
  // V_gas = V_g0 (p0 / p_res)^(1/n)
  const double n = p[kPolytropic];
  const double log_p = logs.precharge_ratio;
  const double d_v_gas = o.v_gas * (dp(kGasVolume) / p[kGasVolume] +
                                    (dp(kPrecharge) / p[kPrecharge] - dx_res / x[kPRes]) / n -
                                    dp(kPolytropic) / (n * n) * log_p);
  const double d_inertance = o.inertance * (dp(kDensity) / p[kDensity] +
                                            dp(kPipeLength) / p[kPipeLength] -
                                            dp(kPipeSection) / p[kPipeSection]);
  PointTangent t{};
  // pdot_res = n p_res (Q_base + q) / V_gas
  const double inflow = o.base.q + x[kQValve];
  t.pdot_res = (dp(kPolytropic) * x[kPRes] + n * dx_res) * inflow / o.v_gas +
               n * x[kPRes] * (d_base_q + dx_q) / o.v_gas - o.pdot_res * d_v_gas / o.v_gas;
  t.qdot = (dx_reb - dx_res - d_valve_dp - d_port_dp) / o.inertance - o.qdot * d_inertance / o.inertance;
  const double d_hydraulic_power =
      d_piston_q * (x[kPReb] - x[kPComp]) + o.piston.q * (dx_reb - dx_comp) +
      d_base_q * (x[kPComp] - x[kPRes]) + o.base.q * (dx_comp - dx_res) +
      dx_q * (o.valve.dp + o.port.dp) + x[kQValve] * (d_valve_dp + d_port_dp);
  if (!with_inputs) return t;
  const double stroke = e.u[0][0], d_stroke = s.u[0](0, d), d_rate = s.u[1](0, d);
  const double d_v_reb = dp(kReboundVolume) - d_area_annulus * stroke - o.area_annulus * d_stroke;
  const double d_v_comp = dp(kCompressionVolume) + d_area_piston * stroke + o.area_piston * d_stroke;
  const double b = p[kBulkModulus], db = dp(kBulkModulus);
  const double net_reb = o.area_annulus * o.rate - o.piston.q - x[kQValve];
  const double d_net_reb = d_area_annulus * o.rate + o.area_annulus * d_rate - d_piston_q - dx_q;
  t.pdot_reb = (db * net_reb + b * d_net_reb) / o.v_reb - o.pdot_reb * d_v_reb / o.v_reb;
  const double net_comp = o.piston.q - o.base.q - o.area_piston * o.rate;
  const double d_net_comp = d_piston_q - d_base_q - d_area_piston * o.rate - o.area_piston * d_rate;
  t.pdot_comp = (db * net_comp + b * d_net_comp) / o.v_comp - o.pdot_comp * d_v_comp / o.v_comp;
  // friction = F_c tanh(v / v_f)
  const double vf = p[kFrictionVelocity];
  const double sech2 = 1 - o.th * o.th;
  const double d_th = sech2 * (d_rate / vf - o.rate * dp(kFrictionVelocity) / (vf * vf));
  const double friction = p[kFriction] * o.th;
  const double d_friction = dp(kFriction) * o.th + p[kFriction] * d_th;
  t.force = dx_reb * o.area_annulus + x[kPReb] * d_area_annulus - dx_comp * o.area_piston -
            x[kPComp] * d_area_piston + dp(kAtmosphere) * o.area_rod + p[kAtmosphere] * d_area_rod +
            d_friction;
  t.power = d_hydraulic_power + d_friction * o.rate + friction * d_rate;
  return t;
}

class DamperCdc : public Block {
 public:
  DamperCdc() {
    declare_input("stroke", 1, "m", false);
    declare_input("stroke_rate", 1, "m/s", true);
    declare_output("force", 1, "N", true);
    declare_output("p_rebound", 1, "Pa", false);
    declare_output("p_compression", 1, "Pa", false);
    declare_output("p_reservoir", 1, "Pa", false);
    declare_output("power", 1, "W", true);
    // Nominal magnitudes, the peaks of a comfort run: chamber pressures of the order of 1 MPa
    // (pre-charge 0.5 MPa), valve flow of the annulus area (4.9 cm^2) times 0.2 m/s, 1e-4 m^3/s.
    declare_states({"p_rebound", "p_compression", "p_reservoir", "q_valve"}, {1e6, 1e6, 1e6, 1e-4});
  }

  /// Static equilibrium at zero stroke: every chamber at the gas pre-charge, no flow.
  void initial_state(const Eval& e, double* x0) const override {
    x0[kPReb] = x0[kPComp] = x0[kPRes] = e.p[kPrecharge];
    x0[kQValve] = 0.0;
  }
  void initial_state_tangent(const Eval&, const Seeds& s, DirView dx0) const override {
    for (int d = 0; d < s.directions; ++d) {
      dx0(kPReb, d) = dx0(kPComp, d) = dx0(kPRes, d) = s.p(kPrecharge, d);
      dx0(kQValve, d) = 0.0;
    }
  }

  void outputs(const Eval& e, double* const* y) const override {
    y[kPRebOut][0] = e.x[kPReb];
    y[kPCompOut][0] = e.x[kPComp];
    y[kPResOut][0] = e.x[kPRes];
    if (!e.inputs_ready) return;
    const Point o = evaluate(e, true);
    y[kForce][0] = o.force;
    y[kPower][0] = o.power;
  }
  void outputs_tangent(const Eval& e, const Seeds& s, const DirView* dy) const override {
    for (int d = 0; d < s.directions; ++d) {
      dy[kPRebOut](0, d) = s.x(kPReb, d);
      dy[kPCompOut](0, d) = s.x(kPComp, d);
      dy[kPResOut](0, d) = s.x(kPRes, d);
    }
    if (!e.inputs_ready) return;
    const Point o = evaluate(e, true);
    const TangentLogs logs = tangent_logs(e);
    for (int d = 0; d < s.directions; ++d) {
      const PointTangent t = tangent(e, o, logs, s, d, true);
      dy[kForce](0, d) = t.force;
      dy[kPower](0, d) = t.power;
    }
  }
  void derivatives(const Eval& e, double* xdot) const override {
    const Point o = evaluate(e, true, false);
    xdot[kPReb] = o.pdot_reb;
    xdot[kPComp] = o.pdot_comp;
    xdot[kPRes] = o.pdot_res;
    xdot[kQValve] = o.qdot;
  }
  void derivatives_tangent(const Eval& e, const Seeds& s, DirView dxdot) const override {
    const Point o = evaluate(e, true);
    const TangentLogs logs = tangent_logs(e);
    for (int d = 0; d < s.directions; ++d) {
      const PointTangent t = tangent(e, o, logs, s, d, true);
      dxdot(kPReb, d) = t.pdot_reb;
      dxdot(kPComp, d) = t.pdot_comp;
      dxdot(kPRes, d) = t.pdot_res;
      dxdot(kQValve, d) = t.qdot;
    }
  }
  // The pressures' derivatives are what makes the damper stiff and nonlinear (orifice laws over
  // small chamber volumes); this 4 x 4 block costs one tangent of this block alone.
  bool local_jacobian(const Eval& e, DirView jac) const override {
    double identity[16] = {};
    for (int i = 0; i < 4; ++i) identity[i * 4 + i] = 1.0;
    const engine::ConstDirView held[2] = {};  // stroke and stroke rate held
    const Seeds s{4, {identity, 4}, held, {}};
    const Point o = evaluate(e, true, false);  // the derivatives' tangents read no force
    const TangentLogs logs = tangent_logs(e);
    for (int d = 0; d < 4; ++d) {
      const PointTangent t = tangent(e, o, logs, s, d, true);
      jac(kPReb, d) = t.pdot_reb;
      jac(kPComp, d) = t.pdot_comp;
      jac(kPRes, d) = t.pdot_res;
      jac(kQValve, d) = t.qdot;
    }
    return true;
  }
};

const engine::BlockRegistration damper_cdc({
    "damper.cdc", "suspension",
    "Semi-active twin-tube hydraulic damper: chamber pressures with oil compressibility, piston, "
    "base and electro-valve orifices, pipe inertia, gas reservoir. Stroke > 0 extends; force > 0 is tension.",
    {{"current", "A", 0.8, false, kCurrentMin, kCurrentMax, "electro-valve current (larger: softer)"},
     {"valve_section_hard", "m^2", 0.5e-6, false, 1e-10, kInf, "electro-valve section at 0.3 A"},
     {"valve_section_soft", "m^2", 8.0e-6, false, 1e-10, kInf, "electro-valve section at 1.6 A"},
     {"valve_port_section", "m^2", 3.0e-6, false, 1e-10, kInf, "fixed restriction in series with the electro-valve"},
     {"piston_diameter", "m", 0.032, false, 1e-3, kInf, "piston (bore) diameter"},
     {"rod_diameter", "m", 0.020, false, 1e-3, kInf, "piston rod diameter"},
     {"density", "kg/m^3", 870.0, false, 1.0, kInf, "oil density"},
     {"bulk_modulus", "Pa", 1.5e9, false, 1e5, kInf, "effective bulk modulus of the oil"},
     {"discharge_coefficient", "", 0.7, false, 1e-3, 1.0, "discharge coefficient of every orifice"},
     {"transition_pressure", "Pa", 1.0e5, false, 1.0, kInf, "laminar/turbulent transition pressure drop"},
     {"piston_rebound_section", "m^2", 2.0e-6, false, 1e-10, kInf, "piston valve section, rebound to compression chamber"},
     {"piston_check_section", "m^2", 20e-6, false, 1e-10, kInf, "piston check valve section, compression to rebound chamber"},
     {"base_compression_section", "m^2", 1.3e-6, false, 1e-10, kInf, "base valve section, compression chamber to reservoir"},
     {"base_intake_section", "m^2", 20e-6, false, 1e-10, kInf, "base intake (check) valve section, reservoir to compression chamber"},
     {"pipe_length", "m", 0.1, false, 1e-4, kInf, "length of the pipe to the external valve"},
     {"pipe_section", "m^2", 20e-6, false, 1e-10, kInf, "section of the pipe to the external valve"},
     {"rebound_volume", "m^3", 40e-6, false, 1e-9, kInf, "rebound chamber volume at zero stroke"},
     {"compression_volume", "m^3", 50e-6, false, 1e-9, kInf, "compression chamber volume at zero stroke"},
     {"gas_volume", "m^3", 80e-6, false, 1e-9, kInf, "reservoir gas volume at zero stroke (at the pre-charge)"},
     {"precharge", "Pa", 5.0e5, false, 1e3, kInf, "reservoir gas pre-charge, absolute"},
     {"polytropic_exponent", "", 1.2, false, 1.0, 1.67, "polytropic exponent of the gas"},
     {"atmospheric_pressure", "Pa", 1.01325e5, false, 0.0, kInf, "pressure outside, on the rod end"},
     {"friction", "N", 30.0, false, 0.0, kInf, "seal friction (Coulomb level)"},
     {"friction_velocity", "m/s", 0.01, false, 1e-6, kInf, "stroke rate at which friction reaches 76 % of its level"}},
    {},
    [](const engine::BlockSettings&) -> std::unique_ptr<Block> { return std::make_unique<DamperCdc>(); },
    // The annulus A_piston - A_rod carries the rebound pressure: a rod as wide as the piston
    // leaves none, a wider one a negative area and forces of the wrong size and sign.
    {{"rod_diameter < piston_diameter", "rod_diameter", engine::BlockCheck::Severity::error,
      [](const engine::CheckInput& in) -> std::optional<std::string> {
        if (in.p[kRodDiameter] < in.p[kPistonDiameter]) return std::nullopt;
        std::ostringstream why;
        why << "rod " << in.p[kRodDiameter] << " m is not narrower than the piston "
            << in.p[kPistonDiameter] << " m (piston_diameter)";
        return why.str();
      }}}});

}  // namespace
}  // namespace dydp::blocks
