// Recursive differentiation against complex-step derivatives of the interpreter, which are
// exact to rounding: f'(x) = Im f(x + i h) / h with h = 1e-30, no subtraction involved.
#include "symbolic/differentiate.hpp"

#include <gtest/gtest.h>

#include "eval_helpers.hpp"
#include "random_list.hpp"
#include "symbolic/eliminate.hpp"

namespace dydp::symbolic {
namespace {

using testing::ArrayValues;
using cplx = std::complex<double>;
constexpr double kStep = 1e-30;
constexpr double kTolerance = 1e-12;

ArrayValues<double> random_point(const Context& ctx, unsigned seed) {
  ArrayValues<double> x(ctx);
  for (std::size_t a = 0; a < x.values.size(); ++a) {
    x.values[a] = testing::random_values(x.values[a].size(), seed * 31 + static_cast<unsigned>(a), 1.2);
  }
  return x;
}

// d(outputs)/d(element i of array a) by complex step.
std::vector<double> complex_step(const Tape& tape, const ArrayValues<double>& x, ArrayId a, std::size_t i) {
  ArrayValues<cplx> xc = testing::to_complex(x);
  xc.values[a][i] += cplx(0.0, kStep);
  std::vector<double> d;
  for (const cplx& v : testing::run(tape, xc)) d.push_back(v.imag() / kStep);
  return d;
}

TEST(Differentiate, MatchesComplexStepAlongInputsAndParameters) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    Context ctx;
    EquationList list(ctx);
    const auto model = testing::make_random_list(list, 300, 6, seed);
    const EquationList primal = eliminate(list);
    std::vector<Direction> directions;
    std::vector<std::pair<ArrayId, std::size_t>> along_what;
    for (ArrayId a : {model.q, model.qd, model.p}) {
      for (std::size_t i = 0; i < ctx.array(a).elements.size(); ++i) {
        directions.push_back(along(ctx.element(a, i)));
        along_what.emplace_back(a, i);
      }
    }
    const EquationList derivative = eliminate(differentiate(primal, directions));
    const std::size_t n = primal.outputs().size();
    ASSERT_EQ(derivative.outputs().size(), n * (1 + directions.size()));
    ASSERT_EQ(derivative.primal_outputs(), n);

    const ArrayValues<double> x = random_point(ctx, seed);
    const Tape primal_tape(primal);
    const std::vector<double> values = testing::run(Tape(derivative), x);
    const std::vector<double> reference = testing::run(primal_tape, x);
    for (std::size_t j = 0; j < n; ++j) EXPECT_EQ(values[j], reference[j]);
    int checked = 0;
    for (std::size_t k = 0; k < directions.size(); ++k) {
      const auto cs = complex_step(primal_tape, x, along_what[k].first, along_what[k].second);
      for (std::size_t j = 0; j < n; ++j) {
        const double recursive = values[n + k * n + j];
        EXPECT_TRUE(testing::close(recursive, cs[j], kTolerance))
            << "seed " << seed << " direction " << directions[k].suffix << " output " << j
            << ": recursive " << recursive << " complex step " << cs[j];
        checked += cs[j] != 0.0;
      }
    }
    EXPECT_GT(checked, 0) << "the check must not be vacuous";
  }
}

TEST(Differentiate, ZeroDerivativesVanish) {
  Context ctx;
  const ArrayId q = ctx.add_array("q", 2, SymbolKind::Input);
  const ArrayId p = ctx.add_array("p", 1, SymbolKind::Parameter);
  EquationList list(ctx);
  const Expr q1 = ctx.element(q, 0), q2 = ctx.element(q, 1), k = ctx.element(p, 0);
  const Expr a = list.assign("A", q1 * q2);
  const Expr b = list.assign("B", sin(a) + k);   // only B depends on k
  const Expr c = list.assign("C", a * cos(q1));
  list.add_output("b", b);
  list.add_output("c", c);
  const Direction dk = along(k);
  const EquationList d = eliminate(differentiate(list, std::span<const Direction>(&dk, 1)));
  // dA/dk = 0, dC/dk = 0 vanish; dB/dk = 1 is a constant output: no derivative assignment at all.
  EXPECT_EQ(d.size() - d.primal_assignments(), 0u);
  EXPECT_TRUE(ctx.is_constant(d.outputs()[2].value, 1.0));
  EXPECT_TRUE(ctx.is_constant(d.outputs()[3].value, 0.0));
  // Along q1, dA = q2 is inlined, so only B and C get derivative assignments.
  const Direction dq = along(q1);
  const EquationList e = eliminate(differentiate(list, std::span<const Direction>(&dq, 1)));
  EXPECT_EQ(e.size() - e.primal_assignments(), 2u);
}

TEST(Differentiate, SecondOrderMatchesComplexStepOfFirstOrder) {
  for (unsigned seed = 11; seed <= 14; ++seed) {
    Context ctx;
    EquationList list(ctx);
    const auto model = testing::make_random_list(list, 200, 4, seed);
    const Direction first = along(ctx.element(model.q, 0));
    const EquationList d1 = eliminate(differentiate(eliminate(list), std::span<const Direction>(&first, 1)));
    const Direction second = along(ctx.element(model.p, 1));
    const EquationList d2 = eliminate(differentiate(d1, std::span<const Direction>(&second, 1)));
    const ArrayValues<double> x = random_point(ctx, seed);
    const std::vector<double> values = testing::run(Tape(d2), x);
    const auto cs = complex_step(Tape(d1), x, model.p, 1);
    const std::size_t m = d1.outputs().size();
    ASSERT_EQ(values.size(), 2 * m);
    for (std::size_t j = 0; j < m; ++j) {
      EXPECT_TRUE(testing::close(values[m + j], cs[j], kTolerance))
          << "seed " << seed << " output " << d2.outputs()[m + j].name << ": " << values[m + j]
          << " vs " << cs[j];
    }
  }
}

TEST(Differentiate, TangentListMatchesComplexStepAlongSeeds) {
  for (unsigned seed = 21; seed <= 24; ++seed) {
    Context ctx;
    EquationList list(ctx);
    const auto model = testing::make_random_list(list, 300, 5, seed);
    const ArrayId seeded_arrays[2] = {model.q, model.p};
    const EquationList tangent = tangent_list(list, seeded_arrays);
    const Tape tape(tangent), primal(list);
    ArrayValues<double> x = random_point(ctx, seed);
    const ArrayId dq = ctx.seed_array(model.q), dp = ctx.seed_array(model.p);
    const std::size_t n = list.outputs().size();
    for (int direction = 0; direction < 3; ++direction) {
      x.values[dq] = testing::random_values(4, seed * 7 + direction);
      x.values[dp] = testing::random_values(3, seed * 13 + direction);
      const std::vector<double> values = testing::run(tape, x);
      ArrayValues<cplx> xc = testing::to_complex(x);
      for (std::size_t i = 0; i < 4; ++i) xc.values[model.q][i] += cplx(0.0, kStep * x.values[dq][i]);
      for (std::size_t i = 0; i < 3; ++i) xc.values[model.p][i] += cplx(0.0, kStep * x.values[dp][i]);
      const auto cs = testing::run(primal, xc);
      ASSERT_EQ(values.size(), 2 * n);
      for (std::size_t j = 0; j < n; ++j) {
        EXPECT_TRUE(testing::close(values[j], cs[j].real(), 1e-13));
        EXPECT_TRUE(testing::close(values[n + j], cs[j].imag() / kStep, kTolerance))
            << "seed " << seed << " output " << j;
      }
    }
  }
}

}  // namespace
}  // namespace dydp::symbolic
