// Hash-consing and construction-time simplification of expressions.
#include "symbolic/expr.hpp"

#include <gtest/gtest.h>

#include "symbolic/emit_cpp.hpp"
#include "symbolic/equation_list.hpp"

namespace dydp::symbolic {
namespace {

class ExprTest : public ::testing::Test {
 protected:
  Context ctx;
  ArrayId q = ctx.add_array("q", 4, SymbolKind::Input);
  ArrayId p = ctx.add_array("p", 2, SymbolKind::Parameter);
  Expr x = ctx.element(q, 0), y = ctx.element(q, 1), z = ctx.element(q, 2);
  Expr k = ctx.element(p, 0);
};

TEST_F(ExprTest, StructurallyEqualExpressionsAreOneNode) {
  const Expr a = (x + y) * sin(z) + k / (x * y);
  const Expr b = k / (y * x) + sin(z) * (y + x);
  EXPECT_EQ(a.id(), b.id());
  EXPECT_EQ((x + (y + z)).id(), ((z + x) + y).id());
  EXPECT_EQ((x * (y * z)).id(), ((z * x) * y).id());
  EXPECT_EQ(min(x, y).id(), min(y, x).id());
  const std::size_t before = ctx.size();
  const Expr again = (x + y) * sin(z) + k / (x * y);
  EXPECT_EQ(again.id(), a.id());
  EXPECT_EQ(ctx.size(), before) << "rebuilding an existing expression must not create nodes";
  EXPECT_NE((x + y).id(), (x * y).id());
  EXPECT_NE((x - y).id(), (y - x).id());
}

TEST_F(ExprTest, ConstantsFold) {
  EXPECT_TRUE((ctx.constant(2.0) * ctx.constant(3.0) + 1.0).is_constant(7.0));
  EXPECT_TRUE(sin(ctx.zero()).is_constant(0.0));
  EXPECT_TRUE(pow(ctx.constant(2.0), 10.0).is_constant(1024.0));
  EXPECT_TRUE(max(ctx.constant(-1.0), ctx.constant(2.0)).is_constant(2.0));
  // not folded to a non-finite number
  EXPECT_FALSE(log(ctx.zero()).is_constant());
  EXPECT_FALSE((ctx.one() / ctx.zero()).is_constant());
}

TEST_F(ExprTest, ZeroAndOneRules) {
  EXPECT_EQ((x + 0.0).id(), x.id());
  EXPECT_EQ((x * 1.0).id(), x.id());
  EXPECT_TRUE((x * 0.0).is_zero());
  EXPECT_EQ((x / 1.0).id(), x.id());
  EXPECT_TRUE((ctx.zero() / x).is_zero());
  EXPECT_TRUE(pow(x, 0.0).is_constant(1.0));
  EXPECT_EQ(pow(x, 1.0).id(), x.id());
  EXPECT_EQ((-(-x)).id(), x.id());
}

TEST_F(ExprTest, CancellationRules) {
  EXPECT_TRUE((x - x).is_zero());
  EXPECT_TRUE((x * y + z - y * x - z).is_zero());
  EXPECT_TRUE((x * pow(x, -1.0)).is_constant(1.0));
  EXPECT_TRUE((x / x).is_constant(1.0));
  EXPECT_EQ((x * y / y).id(), x.id());
  EXPECT_EQ((x + x).id(), (2.0 * x).id());
  EXPECT_EQ((x * x).id(), pow(x, 2.0).id());
  EXPECT_EQ((pow(x, 2.0) * pow(x, -3.0)).id(), pow(x, -1.0).id());
  EXPECT_EQ((3.0 * x - x).id(), (2.0 * x).id());
}

TEST_F(ExprTest, NegationIsCanonical) {
  EXPECT_EQ((-(x + y)).id(), ((-x) - y).id());
  EXPECT_EQ((-x * y).id(), (-(x * y)).id());
  EXPECT_EQ(((-x) * (-y)).id(), (x * y).id());
  EXPECT_EQ((-2.0 * x).op(), Op::Mul);
  EXPECT_EQ((-1.0 * x).op(), Op::Neg);
  EXPECT_EQ(cos(-x).id(), cos(x).id());
  EXPECT_EQ(sin(-x).id(), (-sin(x)).id());
}

TEST_F(ExprTest, TrigonometricAbbreviationsOfInputs) {
  const Expr s = sin(z), c = cos(z);
  ASSERT_TRUE(ctx.is_abbreviation(s.id()));
  ASSERT_TRUE(ctx.is_abbreviation(c.id()));
  EXPECT_EQ(ctx.abbreviation_name(s.id()), "S3");
  EXPECT_EQ(ctx.abbreviation_name(c.id()), "C3");
  EXPECT_EQ(sin(z).id(), s.id()) << "one S3 per joint";
  EXPECT_TRUE(ctx.is_abbreviation(sin(k).id()));
  EXPECT_FALSE(ctx.is_abbreviation(sin(x + y).id()));
  EXPECT_EQ(to_cpp(ctx, (x * c + y * s).id()), "q[0]*C3 + q[1]*S3");
}

TEST_F(ExprTest, EquationListInlinesTrivialValues) {
  EquationList list(ctx);
  EXPECT_EQ(list.assign("A", x).id(), x.id());
  EXPECT_EQ(list.assign("B", -y).id(), (-y).id());
  EXPECT_EQ(list.assign("C", ctx.constant(2.5)).id(), ctx.constant(2.5).id());
  EXPECT_EQ(list.assign("S", sin(z)).id(), sin(z).id());
  EXPECT_EQ(list.size(), 0u);
  const Expr a = list.assign("OM23", x * cos(z) + y * sin(z));
  EXPECT_EQ(list.size(), 1u);
  EXPECT_EQ(a.op(), Op::Symbol);
  EXPECT_EQ(ctx.symbol(a.id()).name, "OM23");
  // names stay unique C++ identifiers
  const Expr b = list.assign("OM23", x * y);
  EXPECT_NE(ctx.symbol(b.id()).name, "OM23");
  const Expr c = list.assign("double", x * z);
  EXPECT_NE(ctx.symbol(c.id()).name, "double");
}

TEST_F(ExprTest, PrinterWritesSubtractionsAndQuotients) {
  EXPECT_EQ(to_cpp(ctx, (x - 2.0 * y).id()), "q[0] - 2.0*q[1]");
  EXPECT_EQ(to_cpp(ctx, (x / (y * y)).id()), "q[0]/(q[1]*q[1])");
  EXPECT_EQ(to_cpp(ctx, ((x + y) * z).id()), "q[2]*(q[0] + q[1])");
}

}  // namespace
}  // namespace dydp::symbolic
