// A generic tangent checker for registered block types: made through the registry factory with
// given settings and parameters, evaluated at random states and inputs and at the defaults and
// perturbed values of the parameters, every tangent function (outputs, derivatives, quadratures,
// initial state, and an objective block's psi) is compared, entry by entry, with central
// differences of the matching value function over a study of steps relative to each variable's
// size, keeping the best step; a value that is not finite at any step fails the check.
// Outputs are evaluated as the engine does: state-only outputs first with the inputs not ready
// (inputs poisoned with NaN, so reading them shows), then all outputs with the inputs ready.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "engine/framework/block.hpp"
#include "engine/framework/objective.hpp"
#include "engine/framework/registry.hpp"

namespace dydp::test {

/// A value drawn uniformly in [center - spread, center + spread]; `spread` also sets the
/// finite-difference step scale of the variable.
struct Range {
  double center = 0.0;
  double spread = 1.0;
};

struct BlockCase {
  std::string type;
  std::map<std::string, std::vector<std::string>> settings;  ///< one item: a scalar setting
  std::map<std::string, double> params;                      ///< others keep their defaults
  std::vector<Range> states;                                 ///< default: 0 +- 1 each
  std::vector<std::vector<Range>> inputs;                    ///< per port, per element; default 0 +- 1
  std::vector<double> times = {0.37};
  int samples = 6;
  double tolerance = 1e-6;
  unsigned seed = 12345;
  /// Parameter values checked: the case's (`params` over the defaults), then parameter_sets - 1
  /// draws with every differentiable parameter scaled by 1 +- parameter_spread (a zero one
  /// moved by +- parameter_spread), reflected into the parameter's bounds.
  int parameter_sets = 3;
  double parameter_spread = 0.1;
  /// Finite-difference steps, relative to each variable's scale: a state's or input's spread,
  /// a parameter's magnitude (zero_parameter_scale for a parameter that is zero).
  std::vector<double> steps = {1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7};
  double zero_parameter_scale = 1e-3;
  /// At most this many directions are finite-differenced (0: all): large blocks check a spread
  /// of their states, inputs and parameters that keeps the first and last of each kind.
  int direction_limit = 0;
  /// Objective blocks: the quadratures' values at the end of the run (default 1 +- 0.5 each),
  /// and the number of output samples of the first input over [0, 1] s.
  std::vector<Range> quadrature_values;
  int objective_samples = 9;
};

/// The block of a case, made through the registry.
inline std::unique_ptr<engine::Block> make_block(const BlockCase& c, std::vector<double>* p = nullptr) {
  const engine::BlockType* type = engine::Registry::global().find(c.type);
  if (!type) throw std::runtime_error("unknown block type " + c.type);
  engine::BlockSettings settings("test", "test.yaml", 1);
  for (const auto& spec : type->settings)
    if (!c.settings.count(spec.name)) settings.set(spec.name, {{spec.default_value}, false, 1});
  for (const auto& [name, items] : c.settings) settings.set(name, {items, items.size() != 1, 1});
  if (p) {
    p->clear();
    for (const auto& spec : type->parameters) p->push_back(spec.default_value);
    for (const auto& [name, value] : c.params) {
      size_t j = 0;
      while (j < type->parameters.size() && type->parameters[j].name != name) ++j;
      if (j == type->parameters.size()) throw std::runtime_error(c.type + ": no parameter " + name);
      (*p)[j] = value;
    }
  }
  return type->make(settings);
}

namespace detail {

struct Point {
  double t = 0;
  std::vector<double> x, p;
  std::vector<std::vector<double>> u;
};

inline bool any_state_only_output(const engine::Block& b) {
  for (const auto& port : b.outputs()) if (!port.feedthrough) return true;
  return false;
}
inline bool any_feedthrough_output(const engine::Block& b) {
  for (const auto& port : b.outputs()) if (port.feedthrough) return true;
  return false;
}

/// Flattened values of the four value functions at a point: outputs, xdot, qdot, x0.
struct Values {
  std::vector<double> y, xdot, qdot, x0;
};

inline Values evaluate(const engine::Block& b, const Point& pt) {
  const int nx = b.num_states(), nq = b.num_quadratures();
  std::vector<const double*> u;
  std::vector<std::vector<double>> poisoned;
  for (const auto& v : pt.u) {
    u.push_back(v.data());
    poisoned.emplace_back(v.size(), std::numeric_limits<double>::quiet_NaN());
  }
  std::vector<const double*> u_poisoned;
  for (const auto& v : poisoned) u_poisoned.push_back(v.data());
  engine::Eval e;
  e.t = pt.t;
  e.segment_start = pt.t;
  e.x = pt.x.data();
  e.p = pt.p.data();
  Values out;
  int ny = 0;
  for (const auto& port : b.outputs()) ny += port.width;
  out.y.assign(ny, std::numeric_limits<double>::quiet_NaN());
  std::vector<double*> y;
  int off = 0;
  for (const auto& port : b.outputs()) { y.push_back(out.y.data() + off); off += port.width; }
  if (any_state_only_output(b)) {
    e.inputs_ready = false;
    e.u = u_poisoned.data();
    b.outputs(e, y.data());
    off = 0;
    for (const auto& port : b.outputs()) {
      for (int i = 0; i < port.width; ++i) {
        if (!port.feedthrough) {
          EXPECT_TRUE(std::isfinite(out.y[off + i])) << "state-only output " << port.name
                                                     << " not set (or reads inputs) in the first pass";
        }
      }
      off += port.width;
    }
  }
  const std::vector<double> first = out.y;
  e.u = u.data();
  e.inputs_ready = true;
  if (any_feedthrough_output(b)) {
    b.outputs(e, y.data());
    off = 0;
    for (const auto& port : b.outputs()) {
      for (int i = 0; i < port.width; ++i) {
        if (!port.feedthrough) {
          EXPECT_EQ(out.y[off + i], first[off + i]) << "state-only output " << port.name
                                                    << " changed in the second pass";
        }
      }
      off += port.width;
    }
  }
  out.xdot.assign(nx, 0.0);
  if (nx) b.derivatives(e, out.xdot.data());
  out.qdot.assign(nq, 0.0);
  if (nq) b.quadratures(e, out.qdot.data());
  out.x0.assign(nx, 0.0);
  if (nx) {
    e.u = u_poisoned.data();
    b.initial_state(e, out.x0.data());
  }
  return out;
}

/// Seeds of nd directions: sx[d*nx + i] for state i, su[k][d*width_k + i] for element i of
/// input port k, sp[d*np + j] for parameter j.
struct SeedSet {
  std::vector<double> sx, sp;
  std::vector<std::vector<double>> su;
};

/// One direction per variable (states, inputs, parameters), in that order.
inline SeedSet unit_seeds(const engine::Block& b, const Point& pt, int nd) {
  const int nx = b.num_states(), np = static_cast<int>(pt.p.size());
  int nu = 0;
  for (const auto& v : pt.u) nu += static_cast<int>(v.size());
  SeedSet seeds;
  seeds.sx.assign(static_cast<size_t>(std::max(nx, 1)) * nd, 0.0);
  for (int i = 0; i < nx; ++i) seeds.sx[i * nx + i] = 1.0;
  int off = nx;
  for (const auto& v : pt.u) {
    const int w = static_cast<int>(v.size());
    seeds.su.emplace_back(static_cast<size_t>(w) * nd, 0.0);
    for (int i = 0; i < w; ++i) seeds.su.back()[(off + i) * w + i] = 1.0;
    off += w;
  }
  seeds.sp.assign(static_cast<size_t>(std::max(np, 1)) * nd, 0.0);
  for (int j = 0; j < np; ++j) seeds.sp[(nx + nu + j) * np + j] = 1.0;
  return seeds;
}

/// Tangents of the four functions in the nd directions of `seeds`, as the engine asks for them.
inline Values tangents(const engine::Block& b, const Point& pt, int nd, const SeedSet& seeds) {
  const int nx = b.num_states(), nq = b.num_quadratures(), np = static_cast<int>(pt.p.size());
  std::vector<engine::ConstDirView> su_view, su_poisoned;
  std::vector<std::vector<double>> su_nan;
  for (const auto& v : pt.u)
    su_nan.emplace_back(static_cast<size_t>(v.size()) * nd, std::numeric_limits<double>::quiet_NaN());
  for (size_t k = 0; k < seeds.su.size(); ++k) {
    su_view.push_back({seeds.su[k].data(), static_cast<int>(pt.u[k].size())});
    su_poisoned.push_back({su_nan[k].data(), static_cast<int>(pt.u[k].size())});
  }
  engine::Seeds s;
  s.directions = nd;
  s.x = nx ? engine::ConstDirView{seeds.sx.data(), nx} : engine::ConstDirView{};
  s.p = np ? engine::ConstDirView{seeds.sp.data(), np} : engine::ConstDirView{};

  std::vector<const double*> u;
  std::vector<std::vector<double>> poisoned;
  for (const auto& v : pt.u) {
    u.push_back(v.data());
    poisoned.emplace_back(v.size(), std::numeric_limits<double>::quiet_NaN());
  }
  std::vector<const double*> u_poisoned;
  for (const auto& v : poisoned) u_poisoned.push_back(v.data());
  engine::Eval e;
  e.t = pt.t;
  e.segment_start = pt.t;
  e.x = pt.x.data();
  e.p = pt.p.data();

  Values out;
  int ny = 0;
  for (const auto& port : b.outputs()) ny += port.width;
  out.y.assign(static_cast<size_t>(ny) * nd, std::numeric_limits<double>::quiet_NaN());
  std::vector<engine::DirView> dy;
  int off = 0;
  for (const auto& port : b.outputs()) { dy.push_back({out.y.data() + off, ny}); off += port.width; }
  if (any_state_only_output(b)) {
    e.inputs_ready = false;
    e.u = u_poisoned.data();
    s.u = su_poisoned.data();
    b.outputs_tangent(e, s, dy.data());
  }
  e.u = u.data();
  s.u = su_view.data();
  e.inputs_ready = true;
  if (any_feedthrough_output(b)) b.outputs_tangent(e, s, dy.data());
  out.xdot.assign(static_cast<size_t>(nx) * nd, 0.0);
  if (nx) b.derivatives_tangent(e, s, {out.xdot.data(), nx});
  out.qdot.assign(static_cast<size_t>(nq) * nd, 0.0);
  if (nq) b.quadratures_tangent(e, s, {out.qdot.data(), nq});
  out.x0.assign(static_cast<size_t>(nx) * nd, 0.0);
  if (nx) {
    // The initial state depends on the parameters only: state and input seeds are zero there.
    engine::Seeds s0 = s;
    s0.x = {};
    std::vector<std::vector<double>> zero_u;
    std::vector<engine::ConstDirView> zero_view;
    for (const auto& v : pt.u) zero_u.emplace_back(v.size() * nd, 0.0);
    for (size_t k = 0; k < zero_u.size(); ++k) zero_view.push_back({zero_u[k].data(), static_cast<int>(pt.u[k].size())});
    s0.u = zero_view.data();
    e.u = u_poisoned.data();
    b.initial_state_tangent(e, s0, {out.x0.data(), nx});
  }
  return out;
}

/// Tangents of the four functions, one direction per variable (states, inputs, parameters).
inline Values tangents(const engine::Block& b, const Point& pt, int nd) {
  return tangents(b, pt, nd, unit_seeds(b, pt, nd));
}

/// Block::local_jacobian at the point (nx x nx, column-major), or empty when not provided.
inline std::vector<double> local_jacobian(const engine::Block& b, const Point& pt) {
  const int nx = b.num_states();
  std::vector<const double*> u;
  for (const auto& v : pt.u) u.push_back(v.data());
  engine::Eval e;
  e.t = pt.t;
  e.segment_start = pt.t;
  e.x = pt.x.data();
  e.u = u.data();
  e.p = pt.p.data();
  std::vector<double> jac(static_cast<size_t>(nx) * nx, std::numeric_limits<double>::quiet_NaN());
  if (nx == 0 || !b.local_jacobian(e, {jac.data(), nx})) return {};
  return jac;
}

/// Parameter sets of a case: its own values, then perturbed draws (see BlockCase).
inline std::vector<std::vector<double>> parameter_sets(const BlockCase& c, const engine::BlockType& type,
                                                       const std::vector<double>& p0) {
  std::vector<std::vector<double>> sets = {p0};
  std::mt19937_64 rng(c.seed + 7919);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int k = 1; k < c.parameter_sets; ++k) {
    std::vector<double> p = p0;
    for (size_t j = 0; j < p.size(); ++j) {
      const engine::ParamSpec& spec = type.parameters[j];
      const double r = unit(rng);
      if (!spec.differentiable) continue;
      double v = p0[j] != 0.0 ? p0[j] * (1 + c.parameter_spread * r) : c.parameter_spread * r;
      if (v < spec.lower) v = 2 * spec.lower - v;
      if (v > spec.upper) v = 2 * spec.upper - v;
      if (v >= spec.lower && v <= spec.upper) p[j] = v;
    }
    sets.push_back(p);
  }
  return sets;
}

/// The directions finite-differenced: all, or a spread keeping each group's first and last.
inline std::vector<int> checked_directions(int nd, const std::vector<int>& group_starts, int limit) {
  std::vector<int> picked;
  const int stride = limit > 0 && nd > limit ? nd / limit + 1 : 1;
  for (int v = 0; v < nd; ++v) {
    bool edge = v == nd - 1;
    for (int start : group_starts) edge = edge || v == start || v == start - 1;
    if (edge || v % stride == 0) picked.push_back(v);
  }
  return picked;
}

/// Evaluates, turning a block's OutOfDomain into a test failure (false) that names the point.
inline bool try_evaluate(const engine::Block& b, const Point& pt, Values& out, const std::string& where) {
  try {
    out = evaluate(b, pt);
    return true;
  } catch (const engine::OutOfDomain& e) {
    ADD_FAILURE() << where << ": out of domain (" << e.reason << "); the case's ranges leave the block's domain";
    return false;
  }
}

/// An objective block's psi and dpsi for every quadrature and every sample of its first input.
inline void check_objective(const BlockCase& c, const engine::Block& b, const engine::Objective& objective,
                            const std::vector<double>& p, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const int nq = b.num_quadratures();
  const int width = b.inputs().empty() ? 0 : b.inputs()[0].width;
  const int ns = c.objective_samples;
  std::vector<double> q, t, u, scale;
  std::vector<std::string> names;
  for (int i = 0; i < nq; ++i) {
    const Range r = i < static_cast<int>(c.quadrature_values.size()) ? c.quadrature_values[i] : Range{1.0, 0.5};
    q.push_back(r.center + r.spread * unit(rng));
    scale.push_back(r.spread);
    names.push_back("quadrature " + std::to_string(i));
  }
  const Range ur = !c.inputs.empty() && !c.inputs[0].empty() ? c.inputs[0][0] : Range{};
  for (int k = 0; k < ns; ++k) {
    t.push_back(ns > 1 ? static_cast<double>(k) / (ns - 1) : 0.0);
    for (int i = 0; i < width; ++i) {
      u.push_back(ur.center + ur.spread * unit(rng));
      scale.push_back(ur.spread);
      names.push_back("sample " + std::to_string(k) + " of the input, element " + std::to_string(i));
    }
  }
  const int nd = static_cast<int>(scale.size());
  const auto psi = [&](const std::vector<double>& qq, const std::vector<double>& uu, int directions,
                       const std::vector<double>& dq, const std::vector<double>& du, std::vector<double>& dpsi) {
    engine::ObjectiveSamples s;
    s.t_start = 0.0;
    s.t_stop = 1.0;
    s.directions = directions;
    s.width = width;
    s.t = &t;
    s.u = &uu;
    s.du = &du;
    dpsi.assign(std::max(directions, 1), std::numeric_limits<double>::quiet_NaN());
    return objective.objective(p.data(), qq.data(), {dq.empty() ? nullptr : dq.data(), nq}, s, dpsi.data());
  };
  // Seeds: direction d < nq on quadrature d, the others on one input sample each.
  std::vector<double> dq(static_cast<size_t>(nq) * nd, 0.0), du(static_cast<size_t>(ns) * nd * width, 0.0);
  for (int d = 0; d < nq; ++d) dq[static_cast<size_t>(d) * nq + d] = 1.0;
  for (int k = 0; k < ns; ++k)
    for (int i = 0; i < width; ++i) {
      const int d = nq + k * width + i;
      du[(static_cast<size_t>(k) * nd + d) * width + i] = 1.0;
    }
  std::vector<double> dpsi, unused;
  const double psi0 = psi(q, u, nd, dq, du, dpsi);
  EXPECT_TRUE(std::isfinite(psi0)) << c.type << ": psi";
  double row_size = 0;
  for (int d = 0; d < nd; ++d) row_size = std::max(row_size, std::fabs(dpsi[d]) * scale[d]);
  for (int d = 0; d < nd; ++d) {
    double best = std::numeric_limits<double>::infinity(), best_fd = 0;
    for (double rel : c.steps) {
      const double h = rel * scale[d];
      std::vector<double> qp = q, qm = q, up = u, um = u;
      if (d < nq) qp[d] += h, qm[d] -= h;
      else up[d - nq] += h, um[d - nq] -= h;
      const double fd = (psi(qp, up, 0, {}, {}, unused) - psi(qm, um, 0, {}, {}, unused)) / (2 * h);
      EXPECT_TRUE(std::isfinite(fd)) << c.type << ": psi not finite by " << names[d] << " at step " << h;
      if (std::fabs(fd - dpsi[d]) < best) best = std::fabs(fd - dpsi[d]), best_fd = fd;
    }
    const double allowed = c.tolerance * (std::fabs(dpsi[d]) + 1e-3 * row_size / scale[d]) + 1e-300;
    EXPECT_LE(best, allowed) << c.type << ": objective psi by " << names[d] << ": tangent " << dpsi[d]
                             << ", finite difference " << best_fd;
    EXPECT_TRUE(std::isfinite(dpsi[d])) << c.type << ": dpsi by " << names[d];
  }
}

}  // namespace detail

/// Runs the check for every parameter set, sample and time; failures name the function, row,
/// variable and parameter set.
inline void check_tangents(const BlockCase& c) {
  std::vector<double> p_case;
  const auto block = make_block(c, &p_case);
  const engine::Block& b = *block;
  const engine::BlockType* type = engine::Registry::global().find(c.type);
  const int nx = b.num_states(), np = static_cast<int>(p_case.size());
  std::mt19937_64 rng(c.seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);

  // Variable names, in direction order, and where states, inputs and parameters start.
  std::vector<std::string> names;
  for (int i = 0; i < nx; ++i) names.push_back("state " + b.state_names()[i]);
  const int first_input = static_cast<int>(names.size());
  for (const auto& port : b.inputs())
    for (int i = 0; i < port.width; ++i) names.push_back("input " + port.name + "[" + std::to_string(i) + "]");
  const int first_parameter = static_cast<int>(names.size());
  for (const auto& spec : type->parameters) names.push_back("parameter " + spec.name);
  const int nd = static_cast<int>(names.size());
  const std::vector<int> checked = detail::checked_directions(nd, {first_input, first_parameter}, c.direction_limit);
  const auto* objective = dynamic_cast<const engine::Objective*>(&b);

  const std::vector<std::vector<double>> sets = detail::parameter_sets(c, *type, p_case);
  for (size_t set = 0; set < sets.size(); ++set) {
    const std::vector<double>& p0 = sets[set];
    std::string at_set = "parameter set " + std::to_string(set);
    if (set > 0) {
      at_set += " (";
      for (int j = 0; j < np; ++j) at_set += (j ? ", " : "") + type->parameters[j].name + " = " + std::to_string(p0[j]);
      at_set += ")";
    }
    SCOPED_TRACE(c.type + ", " + at_set);
    if (objective) detail::check_objective(c, b, *objective, p0, rng);
    for (int sample = 0; sample < c.samples; ++sample)
      for (double t : c.times) {
        detail::Point pt;
        pt.t = t;
        pt.p = p0;
        std::vector<double> scale;
        for (int i = 0; i < nx; ++i) {
          const Range r = i < static_cast<int>(c.states.size()) ? c.states[i] : Range{};
          pt.x.push_back(r.center + r.spread * unit(rng));
          scale.push_back(r.spread);
        }
        for (size_t k = 0; k < b.inputs().size(); ++k) {
          pt.u.emplace_back();
          for (int i = 0; i < b.inputs()[k].width; ++i) {
            const Range r = k < c.inputs.size() && i < static_cast<int>(c.inputs[k].size()) ? c.inputs[k][i] : Range{};
            pt.u.back().push_back(r.center + r.spread * unit(rng));
            scale.push_back(r.spread);
          }
        }
        for (int j = 0; j < np; ++j) scale.push_back(p0[j] != 0.0 ? std::fabs(p0[j]) : c.zero_parameter_scale);

        detail::Values base;
        if (!detail::try_evaluate(b, pt, base, c.type + " at t = " + std::to_string(t))) continue;
        const detail::Values an = detail::tangents(b, pt, nd);
        // A local Jacobian, where the block provides one, is the state columns of the derivative
        // tangents (checked against finite differences below).
        const std::vector<double> local = detail::local_jacobian(b, pt);
        for (size_t k = 0; k < local.size(); ++k) {
          const double expected = an.xdot[k];  // column k / nx is state direction k / nx
          EXPECT_NEAR(local[k], expected, 1e-12 * (std::fabs(expected) + 1e-300))
              << c.type << ": local_jacobian row " << k % nx << " by " << names[k / nx];
        }
        // Perturbs variable v of a copy of the point by h.
        const auto perturbed = [&](int v, double h) {
          detail::Point q = pt;
          if (v < nx) { q.x[v] += h; return q; }
          int k = v - nx;
          for (auto& port : q.u) {
            if (k < static_cast<int>(port.size())) { port[k] += h; return q; }
            k -= static_cast<int>(port.size());
          }
          q.p[k] += h;
          return q;
        };
        struct Fn { const char* name; std::vector<double> detail::Values::*member; };
        const Fn fns[] = {{"outputs", &detail::Values::y}, {"derivatives", &detail::Values::xdot},
                          {"quadratures", &detail::Values::qdot}, {"initial_state", &detail::Values::x0}};
        for (const Fn& fn : fns) {
          const std::vector<double>& f0 = base.*fn.member;
          for (size_t r = 0; r < f0.size(); ++r)
            EXPECT_TRUE(std::isfinite(f0[r])) << c.type << ": " << fn.name << " row " << r << " at t = " << t;
        }
        for (int v : checked) {
          const bool input_or_state = v < first_parameter;
          // Switching times and other non-differentiable parameters: the engine refuses them as
          // sensitivity directions, so their tangents are not part of the contract.
          if (!input_or_state && !type->parameters[v - first_parameter].differentiable) continue;
          std::vector<detail::Values> plus, minus;
          std::vector<double> steps;
          bool evaluated = true;
          for (double rel : c.steps) {
            const double h = rel * scale[v];
            steps.push_back(h);
            plus.emplace_back();
            minus.emplace_back();
            const std::string where = c.type + " at t = " + std::to_string(t) + ", " + names[v] + " moved by ";
            evaluated = detail::try_evaluate(b, perturbed(v, h), plus.back(), where + std::to_string(h)) &&
                        detail::try_evaluate(b, perturbed(v, -h), minus.back(), where + std::to_string(-h));
            if (!evaluated) break;
          }
          if (!evaluated) continue;
          for (const Fn& fn : fns) {
            const std::vector<double>& f0 = base.*fn.member;
            const int rows = static_cast<int>(f0.size());
            for (int r = 0; r < rows; ++r) {
              if (fn.member == &detail::Values::x0 && input_or_state) continue;
              const double analytic = (an.*fn.member)[static_cast<size_t>(v) * rows + r];
              // The row's natural size: its largest tangent times that variable's scale.
              double row_size = 0;
              for (int w = 0; w < nd; ++w)
                row_size = std::max(row_size, std::fabs((an.*fn.member)[static_cast<size_t>(w) * rows + r]) * scale[w]);
              double best = std::numeric_limits<double>::infinity(), best_fd = 0;
              for (size_t k = 0; k < steps.size(); ++k) {
                const double fd = ((plus[k].*fn.member)[r] - (minus[k].*fn.member)[r]) / (2 * steps[k]);
                // A step that leaves the block's domain gives NaN: a failure, not a dropped step
                // (steps are relative to each variable's size, so they should not leave it).
                EXPECT_TRUE(std::isfinite(fd)) << c.type << ": " << fn.name << " row " << r << " by " << names[v]
                                               << " at t = " << t << ": not finite at step " << steps[k];
                if (std::fabs(fd - analytic) < best) best = std::fabs(fd - analytic), best_fd = fd;
              }
              const double allowed = c.tolerance * (std::fabs(analytic) + 1e-3 * row_size / scale[v]) + 1e-300;
              EXPECT_LE(best, allowed) << c.type << ": " << fn.name << " row " << r << " by " << names[v]
                                       << " at t = " << t << ": tangent " << analytic << ", finite difference "
                                       << best_fd;
              EXPECT_TRUE(std::isfinite(analytic)) << fn.name << " row " << r << " by " << names[v];
            }
          }
        }
      }
  }
}

}  // namespace dydp::test
