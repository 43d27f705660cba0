// A generic tangent checker for registered block types: made through the registry factory with
// given settings and parameters, evaluated at random states and inputs, every tangent function
// (outputs, derivatives, quadratures, initial state) is compared, entry by entry, with central
// differences of the matching value function over a study of steps, keeping the best step.
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

#include "engine/block.hpp"
#include "engine/registry.hpp"

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

/// Tangents of the four functions, one direction per variable (states, inputs, parameters).
inline Values tangents(const engine::Block& b, const Point& pt, int nd) {
  const int nx = b.num_states(), nq = b.num_quadratures(), np = static_cast<int>(pt.p.size());
  int nu = 0;
  for (const auto& v : pt.u) nu += static_cast<int>(v.size());
  std::vector<double> sx(static_cast<size_t>(std::max(nx, 1)) * nd, 0.0);
  for (int i = 0; i < nx; ++i) sx[i * nx + i] = 1.0;
  std::vector<std::vector<double>> su;
  std::vector<engine::ConstDirView> su_view, su_poisoned;
  std::vector<std::vector<double>> su_nan;
  int off = nx;
  for (const auto& v : pt.u) {
    const int w = static_cast<int>(v.size());
    su.emplace_back(static_cast<size_t>(w) * nd, 0.0);
    for (int i = 0; i < w; ++i) su.back()[(off + i) * w + i] = 1.0;
    su_nan.emplace_back(static_cast<size_t>(w) * nd, std::numeric_limits<double>::quiet_NaN());
    off += w;
  }
  for (size_t k = 0; k < su.size(); ++k) {
    su_view.push_back({su[k].data(), static_cast<int>(pt.u[k].size())});
    su_poisoned.push_back({su_nan[k].data(), static_cast<int>(pt.u[k].size())});
  }
  std::vector<double> sp(static_cast<size_t>(std::max(np, 1)) * nd, 0.0);
  for (int j = 0; j < np; ++j) sp[(nx + nu + j) * np + j] = 1.0;
  engine::Seeds s;
  s.directions = nd;
  s.x = nx ? engine::ConstDirView{sx.data(), nx} : engine::ConstDirView{};
  s.p = np ? engine::ConstDirView{sp.data(), np} : engine::ConstDirView{};

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
  off = 0;
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

}  // namespace detail

/// Runs the check for every sample and time; failures name the function, row and variable.
inline void check_tangents(const BlockCase& c) {
  std::vector<double> p0;
  const auto block = make_block(c, &p0);
  const engine::Block& b = *block;
  const engine::BlockType* type = engine::Registry::global().find(c.type);
  const int nx = b.num_states(), np = static_cast<int>(p0.size());
  std::mt19937_64 rng(c.seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);

  // Variable names and scales, in direction order.
  std::vector<std::string> names;
  for (int i = 0; i < nx; ++i) names.push_back("state " + b.state_names()[i]);
  for (const auto& port : b.inputs())
    for (int i = 0; i < port.width; ++i) names.push_back("input " + port.name + "[" + std::to_string(i) + "]");
  for (const auto& spec : type->parameters) names.push_back("parameter " + spec.name);
  const int nd = static_cast<int>(names.size());

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
      for (int j = 0; j < np; ++j) scale.push_back(std::max(std::fabs(p0[j]), 1e-3));

      const detail::Values base = detail::evaluate(b, pt);
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
      for (int v = 0; v < nd; ++v) {
        const bool input_or_state = v < static_cast<int>(scale.size()) - np;
        // Switching times and other non-differentiable parameters: the engine refuses them as
        // sensitivity directions, so their tangents are not part of the contract.
        if (!input_or_state && !type->parameters[v - (nd - np)].differentiable) continue;
        std::vector<detail::Values> plus, minus;
        std::vector<double> steps;
        for (double rel : {1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7}) {
          const double h = rel * scale[v];
          steps.push_back(h);
          plus.push_back(detail::evaluate(b, perturbed(v, h)));
          minus.push_back(detail::evaluate(b, perturbed(v, -h)));
        }
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

}  // namespace dydp::test
