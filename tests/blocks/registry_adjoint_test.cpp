// Every block type in the registry passes the dot-product test of its adjoints: for random
// weights w and random directions v, <w, J v> from the block's tangent equals <J^T w, v> from its
// adjoint, to 1e-12 of the sum of the products' magnitudes, for every pair of a function's port
// (each output port, derivatives, quadratures, initial state) and a variable group (states, each
// input port, parameters), at the points of the registry's tangent cases (registry_cases.hpp).
// Outputs are also checked as the engine calls them: the state-only outputs with the inputs not
// ready (poisoned with NaN), whose adjoint must leave every input's product untouched.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "tests/blocks/registry_cases.hpp"

namespace dydp::test {
namespace {

/// A function's rows: (name, first row, rows) per port of the flattened Values member.
struct Part {
  std::string name;
  std::vector<double> detail::Values::*member;
  int first = 0, rows = 0;
  int port = -1;  ///< output port, or -1 for derivatives, quadratures and initial state
};

std::vector<Part> parts(const engine::Block& b) {
  std::vector<Part> out;
  int offset = 0;
  for (size_t k = 0; k < b.outputs().size(); ++k) {
    out.push_back({"output " + b.outputs()[k].name, &detail::Values::y, offset, b.outputs()[k].width, static_cast<int>(k)});
    offset += b.outputs()[k].width;
  }
  if (b.num_states()) out.push_back({"derivatives", &detail::Values::xdot, 0, b.num_states(), -1});
  if (b.num_quadratures()) out.push_back({"quadratures", &detail::Values::qdot, 0, b.num_quadratures(), -1});
  if (b.num_states()) out.push_back({"initial_state", &detail::Values::x0, 0, b.num_states(), -1});
  return out;
}

/// The adjoint products of one part for weights w (rows x 1): states, per input port, parameters
/// (identity parameter columns), with the inputs ready or not.
struct Products {
  std::vector<double> x, p;
  std::vector<std::vector<double>> u;
};

Products adjoint(const engine::Block& b, const detail::Point& pt, const Part& part, const std::vector<double>& w,
                 bool inputs_ready) {
  const int nx = b.num_states(), np = static_cast<int>(pt.p.size());
  Products r;
  r.x.assign(std::max(nx, 1), 0.0);
  r.p.assign(std::max(np, 1), 0.0);
  std::vector<engine::DirView> u_view;
  for (const auto& port : b.inputs()) r.u.emplace_back(port.width, 0.0);
  for (auto& v : r.u) u_view.push_back({v.data(), static_cast<int>(v.size())});
  std::vector<double> identity(static_cast<size_t>(std::max(np, 1)) * std::max(np, 1), 0.0);
  for (int j = 0; j < np; ++j) identity[static_cast<size_t>(j) * np + j] = 1.0;
  engine::Adjoint a;
  a.directions = 1;
  a.x = nx ? engine::DirView{r.x.data(), nx} : engine::DirView{};
  a.u = u_view.data();
  a.p_columns = np;
  a.p_seeds = np ? engine::ConstDirView{identity.data(), np} : engine::ConstDirView{};
  a.p = np ? engine::DirView{r.p.data(), np} : engine::DirView{};

  std::vector<const double*> u, u_nan;
  std::vector<std::vector<double>> nan;
  for (const auto& v : pt.u) {
    u.push_back(v.data());
    nan.emplace_back(v.size(), std::numeric_limits<double>::quiet_NaN());
  }
  for (const auto& v : nan) u_nan.push_back(v.data());
  engine::Eval e;
  e.t = pt.t;
  e.segment_start = pt.t;
  e.x = pt.x.data();
  e.p = pt.p.data();
  e.u = inputs_ready ? u.data() : u_nan.data();
  e.inputs_ready = inputs_ready;
  const engine::ConstDirView wv{w.data(), part.rows};
  if (part.port >= 0) {
    std::vector<engine::ConstDirView> wy(b.outputs().size());
    wy[part.port] = wv;
    b.outputs_adjoint(e, wy.data(), a);
  } else if (part.member == &detail::Values::xdot) {
    b.derivatives_adjoint(e, wv, a);
  } else if (part.member == &detail::Values::qdot) {
    b.quadratures_adjoint(e, wv, a);
  } else {
    e.u = u_nan.data();  // the initial state reads parameters only
    b.initial_state_adjoint(e, wv, a);
  }
  return r;
}

void check_adjoints(const BlockCase& c) {
  std::vector<double> p_case;
  const auto block = make_block(c, &p_case);
  const engine::Block& b = *block;
  const engine::BlockType* type = engine::Registry::global().find(c.type);
  const int nx = b.num_states(), np = static_cast<int>(p_case.size());
  int nu = 0;
  for (const auto& port : b.inputs()) nu += port.width;
  const int nd = nx + nu + np;
  std::mt19937_64 rng(c.seed + 104729);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const std::vector<Part> all_parts = parts(b);
  const std::vector<std::vector<double>> sets = detail::parameter_sets(c, *type, p_case);
  const int samples = std::min(c.samples, 3);
  int checked = 0;
  for (size_t set = 0; set < sets.size(); ++set)
    for (int sample = 0; sample < samples; ++sample)
      for (double t : c.times) {
        SCOPED_TRACE(c.type + ", parameter set " + std::to_string(set) + ", t = " + std::to_string(t));
        detail::Point pt;
        pt.t = t;
        pt.p = sets[set];
        for (int i = 0; i < nx; ++i) {
          const Range r = i < static_cast<int>(c.states.size()) ? c.states[i] : Range{};
          pt.x.push_back(r.center + r.spread * unit(rng));
        }
        for (size_t k = 0; k < b.inputs().size(); ++k) {
          pt.u.emplace_back();
          for (int i = 0; i < b.inputs()[k].width; ++i) {
            const Range r = k < c.inputs.size() && i < static_cast<int>(c.inputs[k].size()) ? c.inputs[k][i] : Range{};
            pt.u.back().push_back(r.center + r.spread * unit(rng));
          }
        }
        detail::Values jac;  // column v of each function: the tangent along variable v
        try {
          jac = detail::tangents(b, pt, nd);
        } catch (const engine::OutOfDomain& e) {
          ADD_FAILURE() << "out of domain: " << e.reason;
          continue;
        }
        // v: random on differentiable variables (a switching time has no tangent contract)
        std::vector<double> v(nd);
        for (int i = 0; i < nd; ++i)
          v[i] = i >= nx + nu && !type->parameters[i - nx - nu].differentiable ? 0.0 : unit(rng);
        for (const Part& part : all_parts) {
          const int rows_total = static_cast<int>((jac.*part.member).size()) / std::max(nd, 1);
          std::vector<double> w(part.rows);
          for (double& wi : w) wi = unit(rng);
          for (bool ready : {true, false}) {
            if (!ready && (part.port < 0 || b.outputs()[part.port].feedthrough)) continue;
            const Products r = adjoint(b, pt, part, w, ready);
            // groups: states, each input port, parameters; (first variable, count, product)
            struct Group { std::string name; int first, count; const double* product; };
            std::vector<Group> groups = {{"states", 0, nx, r.x.data()}};
            int first = nx;
            for (size_t k = 0; k < b.inputs().size(); ++k) {
              groups.push_back({"input " + b.inputs()[k].name, first, b.inputs()[k].width, r.u[k].data()});
              first += b.inputs()[k].width;
            }
            groups.push_back({"parameters", nx + nu, np, r.p.data()});
            for (const Group& g : groups) {
              if (g.count == 0) continue;
              const bool input_group = g.first >= nx && g.first < nx + nu;
              double forward = 0.0, magnitude = 0.0, reverse = 0.0;
              for (int j = 0; j < g.count; ++j) {
                const int var = g.first + j;
                for (int row = 0; row < part.rows; ++row) {
                  const double term = w[row] * (jac.*part.member)[static_cast<size_t>(var) * rows_total + part.first + row] * v[var];
                  forward += term;
                  magnitude += std::fabs(term);
                }
                if (!ready && input_group) {
                  EXPECT_EQ(g.product[j], 0.0) << part.name << " with the inputs not ready wrote a product into " << g.name;
                  continue;
                }
                reverse += g.product[j] * v[var];
                magnitude += std::fabs(g.product[j] * v[var]);
              }
              if (!ready && input_group) continue;
              EXPECT_TRUE(std::isfinite(reverse)) << part.name << " by " << g.name;
              EXPECT_NEAR(reverse, forward, 1e-12 * magnitude + 1e-300)
                  << part.name << " by " << g.name << (ready ? "" : " (inputs not ready)") << ": <J^T w, v> = " << reverse
                  << ", <w, J v> = " << forward;
              ++checked;
            }
          }
        }
      }
  if (nd > 0 && !all_parts.empty()) {
    EXPECT_GT(checked, 0) << c.type << ": nothing was checked";
  }
}

class RegisteredType : public ::testing::TestWithParam<std::string> {};

TEST_P(RegisteredType, PassesTheDotProductTest) {
  const auto it = registry_cases().find(GetParam());
  ASSERT_NE(it, registry_cases().end()) << "block type " << GetParam()
                                        << " has no case: add one to tests/blocks/registry_cases.hpp";
  for (const BlockCase& c : it->second) check_adjoints(c);
}

INSTANTIATE_TEST_SUITE_P(Registry, RegisteredType, ::testing::ValuesIn(registered_types()), [](const auto& info) {
  std::string name = info.param;
  std::replace_if(name.begin(), name.end(), [](char ch) { return !std::isalnum(static_cast<unsigned char>(ch)); }, '_');
  return name;
});

}  // namespace
}  // namespace dydp::test
