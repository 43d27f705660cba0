// Reverse mode against forward mode and closed forms: the dot-product identity <w, J v> = <J^T w, v>
// between tangent_list and adjoint_list on random lists, J^T w entry by entry against complex
// steps, every node kind's adjoint against its closed-form gradient (both branches of the
// non-smooth ones), zero adjoints never assigned, nodes shared between right-hand sides propagated
// once, and the operation counts against the primal's and the tangent's.
#include "symbolic/reverse.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "eval_helpers.hpp"
#include "random_list.hpp"
#include "symbolic/differentiate.hpp"
#include "symbolic/eliminate.hpp"
#include "symbolic/op_count.hpp"

namespace dydp::symbolic {
namespace {

using testing::ArrayValues;
using cplx = std::complex<double>;
constexpr double kStep = 1e-30;

ArrayValues<double> random_point(const Context& ctx, unsigned seed) {
  ArrayValues<double> x(ctx);
  for (std::size_t a = 0; a < x.values.size(); ++a) {
    x.values[a] = testing::random_values(x.values[a].size(), seed * 31 + static_cast<unsigned>(a), 1.2);
  }
  return x;
}

double dot(const double* a, const double* b, std::size_t n, double* magnitude) {
  double s = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    s += a[i] * b[i];
    *magnitude += std::fabs(a[i] * b[i]);
  }
  return s;
}

TEST(Reverse, DotProductWithTheTangentOnRandomLists) {
  double worst = 0.0;
  for (unsigned seed = 1; seed <= 8; ++seed) {
    Context ctx;
    EquationList list(ctx);
    const auto model = testing::make_random_list(list, 300, 6, seed);
    const std::vector<ArrayId> arrays = seed % 2 ? std::vector<ArrayId>{model.q, model.qd, model.p}
                                                 : std::vector<ArrayId>{model.p, model.q};
    const EquationList tangent = tangent_list(list, arrays);
    const EquationList adjoint = adjoint_list(list, arrays);
    const std::size_t n = list.outputs().size();
    ASSERT_EQ(adjoint.primal_outputs(), n);
    std::size_t inputs = 0;
    for (ArrayId a : arrays) inputs += ctx.array(a).elements.size();
    ASSERT_EQ(adjoint.outputs().size(), n + inputs);
    const ArrayId w = ctx.weight_array(n);
    const Tape tangent_tape(tangent), adjoint_tape(adjoint), primal(list);
    for (int trial = 0; trial < 3; ++trial) {
      const ArrayValues<double> x = random_point(ctx, seed * 10 + trial);
      const std::vector<double> jv = testing::run(tangent_tape, x);
      const std::vector<double> jtw = testing::run(adjoint_tape, x);
      const std::vector<double> y = testing::run(primal, x);
      for (std::size_t j = 0; j < n; ++j) EXPECT_EQ(jtw[j], y[j]) << "the primal outputs come first";
      double magnitude = 0.0;
      const double lhs = dot(x.values[w].data(), jv.data() + n, n, &magnitude);
      double rhs = 0.0;
      std::size_t k = n;
      for (ArrayId a : arrays) {
        const std::size_t size = ctx.array(a).elements.size();
        rhs += dot(jtw.data() + k, x.values[ctx.seed_array(a)].data(), size, &magnitude);
        k += size;
      }
      ASSERT_GT(magnitude, 0.0) << "the check must not be vacuous";
      const double error = std::fabs(lhs - rhs) / magnitude;
      worst = std::max(worst, error);
      EXPECT_LE(error, 1e-12) << "seed " << seed << ": <w, J v> = " << lhs << ", <J^T w, v> = " << rhs;
    }
  }
  std::printf("random lists: largest dot-product error %.3g\n", worst);
}

TEST(Reverse, EntriesMatchComplexStep) {
  for (unsigned seed = 31; seed <= 34; ++seed) {
    Context ctx;
    EquationList list(ctx);
    const auto model = testing::make_random_list(list, 250, 5, seed);
    const ArrayId arrays[3] = {model.q, model.qd, model.p};
    const EquationList adjoint = adjoint_list(list, arrays);
    const std::size_t n = list.outputs().size();
    const ArrayId w = ctx.weight_array(n);
    const ArrayValues<double> x = random_point(ctx, seed);
    const std::vector<double> jtw = testing::run(Tape(adjoint), x);
    const Tape primal(list);
    std::size_t k = n;
    int checked = 0;
    for (ArrayId a : arrays) {
      for (std::size_t i = 0; i < ctx.array(a).elements.size(); ++i, ++k) {
        ArrayValues<cplx> xc = testing::to_complex(x);
        xc.values[a][i] += cplx(0.0, kStep);
        double reference = 0.0;
        const std::vector<cplx> y = testing::run(primal, xc);
        for (std::size_t j = 0; j < n; ++j) reference += x.values[w][j] * y[j].imag() / kStep;
        EXPECT_TRUE(testing::close(jtw[k], reference, 1e-12))
            << "seed " << seed << " " << adjoint.outputs()[k].name << ": " << jtw[k] << " vs " << reference;
        checked += reference != 0.0;
      }
    }
    EXPECT_GT(checked, 0);
  }
}

// One output f(q1, q2, q3) with weight 1: its gradient over q.
struct Case {
  std::string name;
  std::function<Expr(Expr, Expr, Expr)> f;
  std::function<std::vector<double>(double, double, double)> gradient;
  std::vector<double> at;
};

TEST(Reverse, EveryNodeKindMatchesItsClosedForm) {
  const std::vector<Case> cases = {
      {"add", [](Expr a, Expr b, Expr c) { return a + 2.0 * b - c + a * 0.5; },
       [](double, double, double) { return std::vector<double>{1.5, 2.0, -1.0}; }, {0.3, 0.4, 0.5}},
      {"mul", [](Expr a, Expr b, Expr c) { return 3.0 * a * b * c; },
       [](double a, double b, double c) { return std::vector<double>{3 * b * c, 3 * a * c, 3 * a * b}; },
       {0.3, -0.4, 0.5}},
      {"neg", [](Expr a, Expr b, Expr) { return -(a * b); },
       [](double a, double b, double) { return std::vector<double>{-b, -a, 0.0}; }, {0.3, -0.4, 0.5}},
      {"div", [](Expr a, Expr b, Expr c) { return (a + c) / b; },
       [](double a, double b, double c) { return std::vector<double>{1 / b, -(a + c) / (b * b), 1 / b}; },
       {0.3, -0.4, 0.5}},
      {"pow constant", [](Expr a, Expr, Expr) { return pow(a, 2.5); },
       [](double a, double, double) { return std::vector<double>{2.5 * std::pow(a, 1.5), 0.0, 0.0}; },
       {0.7, 0.4, 0.5}},
      {"pow", [](Expr a, Expr b, Expr) { return pow(a, b); },
       [](double a, double b, double) {
         return std::vector<double>{b * std::pow(a, b - 1), std::pow(a, b) * std::log(a), 0.0};
       },
       {0.7, 1.3, 0.5}},
      {"sin cos of inputs", [](Expr a, Expr b, Expr) { return sin(a) * cos(b); },
       [](double a, double b, double) {
         return std::vector<double>{std::cos(a) * std::cos(b), -std::sin(a) * std::sin(b), 0.0};
       },
       {0.7, 1.3, 0.5}},
      {"sin cos of expressions", [](Expr a, Expr b, Expr c) { return sin(a * c) + cos(b + c); },
       [](double a, double b, double c) {
         return std::vector<double>{c * std::cos(a * c), -std::sin(b + c),
                                    a * std::cos(a * c) - std::sin(b + c)};
       },
       {0.7, 1.3, 0.5}},
      {"tan", [](Expr a, Expr b, Expr) { return tan(a * b); },
       [](double a, double b, double) {
         const double s = 1 + std::tan(a * b) * std::tan(a * b);
         return std::vector<double>{s * b, s * a, 0.0};
       },
       {0.7, 0.6, 0.5}},
      {"atan2", [](Expr a, Expr b, Expr) { return atan2(a, b); },
       [](double y, double x, double) {
         const double r = x * x + y * y;
         return std::vector<double>{x / r, -y / r, 0.0};
       },
       {0.7, -1.3, 0.5}},
      {"sqrt", [](Expr a, Expr b, Expr) { return sqrt(a * a + b); },
       [](double a, double b, double) {
         const double s = std::sqrt(a * a + b);
         return std::vector<double>{a / s, 0.5 / s, 0.0};
       },
       {0.7, 1.3, 0.5}},
      {"exp", [](Expr a, Expr b, Expr) { return exp(a * b); },
       [](double a, double b, double) { return std::vector<double>{b * std::exp(a * b), a * std::exp(a * b), 0.0}; },
       {0.7, 1.3, 0.5}},
      {"log", [](Expr a, Expr b, Expr) { return log(a + b); },
       [](double a, double b, double) { return std::vector<double>{1 / (a + b), 1 / (a + b), 0.0}; },
       {0.7, 1.3, 0.5}},
      {"abs", [](Expr a, Expr b, Expr) { return abs(a - b); },
       [](double, double, double) { return std::vector<double>{-1.0, 1.0, 0.0}; }, {0.7, 1.3, 0.5}},
      {"sign", [](Expr a, Expr b, Expr c) { return sign(a - b) * c; },
       [](double, double, double) { return std::vector<double>{0.0, 0.0, -1.0}; }, {0.7, 1.3, 0.5}},
      {"min first", [](Expr a, Expr b, Expr c) { return min(a * c, b); },
       [](double a, double, double c) { return std::vector<double>{c, 0.0, a}; }, {0.7, 1.3, 0.5}},
      {"min second", [](Expr a, Expr b, Expr c) { return min(a * c, b); },
       [](double, double, double) { return std::vector<double>{0.0, 1.0, 0.0}; }, {0.7, 0.2, 0.5}},
      {"max first", [](Expr a, Expr b, Expr c) { return max(a * c, b); },
       [](double a, double, double c) { return std::vector<double>{c, 0.0, a}; }, {0.7, 0.2, 0.5}},
      {"max second", [](Expr a, Expr b, Expr c) { return max(a * c, b); },
       [](double, double, double) { return std::vector<double>{0.0, 1.0, 0.0}; }, {0.7, 1.3, 0.5}},
      {"select positive", [](Expr a, Expr b, Expr c) { return select(a - c, b * b, c); },
       [](double, double b, double) { return std::vector<double>{0.0, 2 * b, 0.0}; }, {0.7, 1.3, 0.5}},
      {"select otherwise", [](Expr a, Expr b, Expr c) { return select(a - c, b * b, c); },
       [](double, double, double) { return std::vector<double>{0.0, 0.0, 1.0}; }, {0.2, 1.3, 0.5}},
      {"shared node", [](Expr a, Expr b, Expr c) { const Expr s = a * b + c; return s * sin(s) + s; },
       [](double a, double b, double c) {
         const double s = a * b + c, d = std::sin(s) + s * std::cos(s) + 1;
         return std::vector<double>{d * b, d * a, d};
       },
       {0.7, 1.3, 0.5}},
  };
  for (const Case& c : cases) {
    Context ctx;
    const ArrayId q = ctx.add_array("q", 3, SymbolKind::Input);
    EquationList list(ctx);
    const Expr a = list.assign("A", c.f(ctx.element(q, 0), ctx.element(q, 1), ctx.element(q, 2)));
    list.add_output("y", a);
    const EquationList adjoint = adjoint_list(list, std::span<const ArrayId>(&q, 1));
    ArrayValues<double> x(ctx);
    x.values[q] = c.at;
    x.values[ctx.weight_array(1)] = {1.0};
    const std::vector<double> g = testing::run(Tape(adjoint), x);
    const std::vector<double> expected = c.gradient(c.at[0], c.at[1], c.at[2]);
    ASSERT_EQ(g.size(), 4u);
    for (int i = 0; i < 3; ++i) {
      EXPECT_TRUE(testing::close(g[1 + i], expected[i], 1e-14))
          << c.name << ": d/dq" << i + 1 << " = " << g[1 + i] << ", expected " << expected[i];
    }
  }
}

TEST(Reverse, ZeroAdjointsVanish) {
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
  // Along k: bar(k) = w1, the weight itself; no adjoint assignment at all.
  const EquationList d = adjoint_list(list, std::span<const ArrayId>(&p, 1));
  const ArrayId w = ctx.weight_array(2);
  EXPECT_EQ(d.size() - d.primal_assignments(), 0u);
  ASSERT_EQ(d.outputs().size(), 3u);
  EXPECT_EQ(d.outputs()[2].name, "bar(p1)");
  EXPECT_EQ(d.outputs()[2].value, ctx.array(w).elements[0]);
  // Along q: B_b = w1 and C_b = w2 are inlined; A_b = w1 cos(A) + w2 C1 is the one adjoint assigned.
  const EquationList e = adjoint_list(list, std::span<const ArrayId>(&q, 1));
  EXPECT_EQ(e.size() - e.primal_assignments(), 1u);
  EXPECT_EQ(ctx.symbol(e.assignments().back().target).name, "A_b");
}

TEST(Reverse, ANodeSharedByTwoRightHandSidesIsPropagatedOnce) {
  Context ctx;
  const ArrayId q = ctx.add_array("q", 3, SymbolKind::Input);
  EquationList list(ctx);
  const Expr q1 = ctx.element(q, 0), q2 = ctx.element(q, 1), q3 = ctx.element(q, 2);
  const Expr n = q1 * q2 * q3;  // one node, read by both
  list.add_output("a", list.assign("A", sin(n)));
  list.add_output("b", list.assign("B", exp(n) + q1));
  const EquationList adjoint = adjoint_list(list, std::span<const ArrayId>(&q, 1));
  // A_b = w1 and B_b = w2 are inlined: the one adjoint assigned is n's, w1 cos(n) + w2 exp(n).
  EXPECT_EQ(adjoint.size() - adjoint.primal_assignments(), 1u);
  ArrayValues<double> x(ctx);
  x.values[q] = {0.7, -1.3, 0.5};
  x.values[ctx.weight_array(2)] = {0.3, -0.8};
  const std::vector<double> g = testing::run(Tape(adjoint), x);
  const double v = 0.7 * -1.3 * 0.5, dn = 0.3 * std::cos(v) - 0.8 * std::exp(v);
  const double expected[3] = {dn * -1.3 * 0.5 - 0.8, dn * 0.7 * 0.5, dn * 0.7 * -1.3};
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(testing::close(g[2 + i], expected[i], 1e-14)) << g[2 + i];
}

TEST(Reverse, CostsAFewPrimals) {
  for (unsigned seed = 41; seed <= 44; ++seed) {
    Context ctx;
    EquationList list(ctx);
    const auto model = testing::make_random_list(list, 400, 6, seed);
    const ArrayId arrays[3] = {model.q, model.qd, model.p};
    const std::uint64_t primal = count_ops(eliminate(list)).total();
    const std::uint64_t tangent = count_ops(tangent_list(list, arrays)).total();
    const std::uint64_t adjoint = count_ops(adjoint_list(list, arrays)).total();
    std::printf("random list %u: operations primal %llu, tangent %llu, adjoint %llu\n", seed,
                static_cast<unsigned long long>(primal), static_cast<unsigned long long>(tangent),
                static_cast<unsigned long long>(adjoint));
    EXPECT_LE(adjoint, 5 * primal);
  }
}

}  // namespace
}  // namespace dydp::symbolic
