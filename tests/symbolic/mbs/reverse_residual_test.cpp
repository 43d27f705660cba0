// The adjoint of a multibody residual list (ModelLists::residual, over q, qd, qdd, inp and p)
// against its tangent by the dot-product identity <w, J v> = <J^T w, v> at random states, both
// interpreted, and the operation counts of the primal, the tangent (one direction) and the
// adjoint (one weight vector), as built and compacted.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "symbolic/compact.hpp"
#include "symbolic/differentiate.hpp"
#include "symbolic/interpret.hpp"
#include "symbolic/mbs/model.hpp"
#include "symbolic/mbs/newton_euler.hpp"
#include "symbolic/op_count.hpp"
#include "symbolic/reverse.hpp"

namespace dydp::mbs {
namespace {

using symbolic::ArrayId;
using symbolic::EquationList;

std::vector<double> run(const EquationList& list, const std::vector<std::vector<double>>& values) {
  std::vector<const double*> arrays;
  for (const auto& v : values) arrays.push_back(v.data());
  std::vector<double> out(list.outputs().size());
  symbolic::Tape(list).evaluate<double>(arrays, out.data());
  return out;
}

unsigned long long ops(const EquationList& list) { return symbolic::count_ops(list).total(); }

class ReverseResidual : public ::testing::TestWithParam<std::string> {};

TEST_P(ReverseResidual, DotProductWithTheTangent) {
  const Model model = load_model(std::string(DYDP_MODELS_DIR) + "/" + GetParam() + ".mbs.yaml");
  const ModelLists lists = build_model_lists(model);
  symbolic::Context& ctx = *lists.context;
  const EquationList& residual = *lists.residual;
  const std::vector<ArrayId> arrays = tangent_arrays(lists);
  const EquationList tangent = symbolic::tangent_list(residual, arrays);
  const EquationList adjoint = symbolic::adjoint_list(residual, arrays);
  const std::size_t n = residual.outputs().size();
  const ArrayId w = ctx.weight_array(n);

  std::printf("%s residual (%zu outputs): operations primal %llu, tangent %llu, adjoint %llu; compacted %llu, %llu, "
              "%llu\n",
              GetParam().c_str(), n, ops(residual), ops(tangent), ops(adjoint), ops(symbolic::compact(residual)),
              ops(symbolic::compact(tangent)), ops(symbolic::compact(adjoint)));
  // a few primals: the reverse sweep costs about what the tangent's one direction does
  EXPECT_LE(ops(adjoint), 4 * ops(residual));

  std::vector<double> p;
  for (const Parameter& par : model.parameters)
    if (par.symbolic) p.push_back(par.value);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0.0;
  for (int trial = 0; trial < 3; ++trial) {
    std::vector<std::vector<double>> values(ctx.array_count());
    for (ArrayId a = 0; a < ctx.array_count(); ++a) {
      values[a].resize(ctx.array(a).elements.size());
      for (double& x : values[a]) x = u(rng);
    }
    // the model's own parameter values (masses, lengths), so that the state is a physical one
    if (!p.empty()) values[lists.p] = p;
    const std::vector<double> jv = run(tangent, values);
    const std::vector<double> jtw = run(adjoint, values);
    double lhs = 0.0, rhs = 0.0, magnitude = 0.0;
    for (std::size_t j = 0; j < n; ++j) {
      EXPECT_EQ(jv[j], jtw[j]) << "the primal outputs come first in both";
      lhs += values[w][j] * jv[n + j];
      magnitude += std::fabs(values[w][j] * jv[n + j]);
    }
    std::size_t k = n;
    for (ArrayId a : arrays) {
      const std::vector<double>& seed = values[ctx.seed_array(a)];
      for (std::size_t i = 0; i < seed.size(); ++i, ++k) {
        rhs += jtw[k] * seed[i];
        magnitude += std::fabs(jtw[k] * seed[i]);
      }
    }
    ASSERT_EQ(k, adjoint.outputs().size());
    ASSERT_GT(magnitude, 0.0);
    const double error = std::fabs(lhs - rhs) / magnitude;
    worst = std::max(worst, error);
    EXPECT_LE(error, 1e-12) << "<w, J v> = " << lhs << ", <J^T w, v> = " << rhs;
  }
  std::printf("%s residual: largest dot-product error %.3g\n", GetParam().c_str(), worst);
}

INSTANTIATE_TEST_SUITE_P(Models, ReverseResidual, ::testing::Values("quarter_car", "sedan", "slider_crank"),
                         [](const auto& info) { return info.param; });

}  // namespace
}  // namespace dydp::mbs
