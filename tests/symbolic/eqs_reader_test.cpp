// The .eqs reader: a model read from text computes the closed-form quantities it describes, and
// malformed input is reported as `file:line: message`.
#include "symbolic/eqs_reader.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "eval_helpers.hpp"

namespace dydp::symbolic {
namespace {

TEST(EqsReader, ThreeJointChainMatchesItsClosedForm) {
  const EqsModel model = read_eqs(DYDP_TEST_DATA_DIR "/chain3.eqs");
  EXPECT_EQ(model.name, "chain3");
  ASSERT_EQ(model.list->outputs().size(), 3u);
  ASSERT_EQ(model.tangent_arrays.size(), 2u);
  const Context& ctx = *model.context;
  testing::ArrayValues<double> x(ctx);
  x.values[0] = {0.3, -0.7, 1.1};
  x.values[1] = {0.5, 2.0, -1.5};
  const auto out = testing::run(Tape(*model.list), x);
  // Joint 1 about z, joints 2 and 3 about x: omega_3 = R_x(q3)^T (R_x(q2)^T (0, 0, qd1) + (qd2, 0, 0)) + (qd3, 0, 0)
  const double q2 = -0.7, q3 = 1.1, qd1 = 0.5, qd2 = 2.0, qd3 = -1.5;
  const double w2y = qd1 * std::sin(q2), w2z = qd1 * std::cos(q2);
  EXPECT_DOUBLE_EQ(out[0], qd2 + qd3);
  EXPECT_NEAR(out[1], w2y * std::cos(q3) + w2z * std::sin(q3), 1e-15);
  EXPECT_NEAR(out[2], w2z * std::cos(q3) - w2y * std::sin(q3), 1e-15);
}

TEST(EqsReader, OperatorPrecedenceAndFunctions) {
  const EqsModel m = parse_eqs(
      "input x 2\n"
      "A = 1 + 2*x[0]^2 - -x[1]/4   # comment\n"
      "B = select(x[0], min(x[0], x[1]), max(x[0], x[1])) + atan2(x[1], x[0]) + pow(x[0]*x[0]+1, 0.5)\n"
      "output a = A\noutput b = B\n",
      "inline.eqs");
  testing::ArrayValues<double> v(*m.context);
  v.values[0] = {0.6, -1.2};
  const auto out = testing::run(Tape(*m.list), v);
  EXPECT_NEAR(out[0], 1 + 2 * 0.36 + (-1.2) / 4, 1e-15);
  EXPECT_NEAR(out[1], -1.2 + std::atan2(-1.2, 0.6) + std::sqrt(1.36), 1e-15);
}

struct BadInput {
  const char* text;
  int line;
  const char* message_part;
};

TEST(EqsReader, ReportsFileLineAndMessage) {
  const BadInput cases[] = {
      {"input q 2\nA = q[0] *\noutput A\n", 2, "ends too early"},
      {"input q 2\nA = q[2]\noutput A\n", 2, "outside 'q'"},
      {"input q 2\n\nA = q[0]*r\noutput A\n", 3, "'r' is not defined"},
      {"input q 2\nA = q[0]*q[1]\nA = q[1]\noutput A\n", 3, "already defined"},
      {"input q 2\nA = foo(q[0])\noutput A\n", 2, "unknown function"},
      {"input q 2\nA = atan2(q[0])\noutput A\n", 2, "takes 2"},
      {"input q 2\nA = q*2\noutput A\n", 2, "is an array"},
      {"input q 2\nA = q[0]*q[1]\noutput B\n", 3, "not defined"},
      {"input q 2\nA = (q[0]\noutput A\n", 2, "expected ')'"},
      {"input q 2\nA = q[0]*q[1]\n", 3, "no output"},  // reported at the end of the file
      {"inputs q 2\n", 1, "unknown statement"},
      {"input q x\n", 1, "array size"},
      {"input q 2\nA = q[0]*q[1] )\noutput A\n", 2, "unexpected ')'"},
      {"input q 2\nA = q[0]*q[1]\noutput A\ntangent r\n", 4, "not an input"},
      // found by eqs_fuzz: a size of 1.3e19 ran out of memory, 2.9e6 took a minute
      {"input q 12936409836691885623\nA = q[0]\noutput A\n", 1, "at most 100000 elements in all"},
      {"input q 60000\nparam k 40001\nA = q[0]\noutput A\n", 2, "at most 100000 elements in all"},
  };
  for (const BadInput& c : cases) {
    try {
      parse_eqs(c.text, "bad.eqs");
      ADD_FAILURE() << "accepted: " << c.text;
    } catch (const ParseError& e) {
      EXPECT_EQ(e.line(), c.line) << e.what();
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("bad.eqs:" + std::to_string(c.line) + ": ", 0), 0u) << what;
      EXPECT_NE(what.find(c.message_part), std::string::npos) << what;
    }
  }
  EXPECT_THROW(read_eqs("/nonexistent/model.eqs"), ParseError);
}

}  // namespace
}  // namespace dydp::symbolic
