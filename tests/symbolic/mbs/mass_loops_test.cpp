// The loop form of the composite-inertia mass matrix (MassLoops), forced on branched models
// (the sedan: prismatic chassis joints, arbitrary axes, four corners and the steering under one
// chassis; Andrews' mechanism; chain9), run by the interpreter one lane at a time: the lanes'
// start, then every sweep in order. The M it gives equals the numerical oracle's, and the
// entries it leaves out are the oracle's zeros. chain200's emitted loops are checked against the
// oracle in generated_test.cpp.
#include <gtest/gtest.h>

#include <random>

#include "oracle_compare.hpp"
#include "symbolic/interpret.hpp"
#include "symbolic/mbs/model.hpp"
#include "symbolic/mbs/newton_euler.hpp"
#include "symbolic/mbs/numeric_dynamics.hpp"

namespace dydp::mbs {
namespace {

using symbolic::EquationList;
using testing::Matrix;
using testing::relative_error;
using testing::Vector;
using symbolic::Tape;

// M from the loops, interpreted. `arrays`: the values of every array of the lists' context;
// `lane_in`: an array of six inputs in it, for one lane's values.
Matrix interpreted_mass(const ModelLists& lists, std::vector<const double*> arrays, symbolic::ArrayId lane_in) {
  const MassLoops& loops = *lists.mass_loops;
  symbolic::Context& ctx = *lists.context;
  const int n = static_cast<int>(loops.lane_joint.size());
  std::vector<double> start(loops.start->outputs().size());
  Tape(*loops.start).evaluate<double>(arrays, start.data());

  // One list per sweep: the start's assignments (they define what the sweep reads), the lane's
  // values from a six-element array, the moved values and the entry.
  Matrix M = Matrix::Zero(n, n);
  for (int t = 0; t < n; ++t) M(loops.lane_joint[t], loops.lane_joint[t]) = start[6 * n + t];
  for (const MassLoops::Sweep& sweep : loops.sweeps) {
    EquationList list(ctx);
    for (const auto& a : loops.start->assignments()) list.append(a);
    for (int a = 0; a < 6; ++a) list.append({loops.lane[a], ctx.element(lane_in, a).id()});
    for (int a = 0; a < 6; ++a) list.append({loops.moved_lane[a], sweep.moved[a]});
    for (int a = 0; a < 6; ++a) list.add_output("moved", ctx.expr(loops.moved_lane[a]));
    list.add_output("entry", ctx.expr(sweep.entry));
    const Tape tape(list);
    for (int t = sweep.begin; t < sweep.end; ++t) {
      double lane[6], result[7];
      for (int a = 0; a < 6; ++a) lane[a] = start[a * n + t];
      arrays[lane_in] = lane;
      tape.evaluate<double>(arrays, result);
      for (int a = 0; a < 6; ++a) start[a * n + t] = result[a];
      const int i = loops.lane_joint[t];
      EXPECT_EQ(M(i, sweep.parent), 0.0) << "one entry per joint and ancestor";
      M(i, sweep.parent) = M(sweep.parent, i) = result[6];
    }
  }
  return M;
}

class MassLoopsForced : public ::testing::TestWithParam<std::string> {};

TEST_P(MassLoopsForced, EqualTheOraclesMassMatrix) {
  const Model model = load_model(std::string(DYDP_MODELS_DIR) + "/" + GetParam() + ".mbs.yaml");
  const ModelLists lists = build_model_lists(model, MassForm::Loops);
  ASSERT_NE(lists.mass_loops, nullptr);
  EXPECT_EQ(lists.mass_matrix, nullptr);
  const int n = model.coordinates();
  NumericDynamics oracle(model);
  std::vector<double> p;
  for (const Parameter& par : model.parameters)
    if (par.symbolic) p.push_back(par.value);
  if (p.empty()) p.push_back(0.0);
  oracle.set_symbolic_parameters(p.data());
  const symbolic::ArrayId lane_in = lists.context->add_array("lanes", 6, symbolic::SymbolKind::Input);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  for (int trial = 0; trial < 3; ++trial) {
    Vector q(n);
    for (int j = 0; j < n; ++j) q[j] = u(rng);
    const std::vector<double> unused(64, 0.0);
    std::vector<const double*> arrays(lists.context->array_count(), unused.data());
    arrays[lists.q] = q.data();
    arrays[lists.p] = p.data();
    const Matrix M = oracle.mass(q);
    EXPECT_LT(relative_error(interpreted_mass(lists, arrays, lane_in), M), 1e-12);
  }
  // the sweeps carry every lane to every ancestor: n (n + 1) / 2 entries for a chain, fewer for
  // a tree, whose other entries are zero
  std::size_t entries = lists.mass_loops->lane_joint.size();
  for (const auto& sweep : lists.mass_loops->sweeps) entries += static_cast<std::size_t>(sweep.end - sweep.begin);
  EXPECT_LE(entries, static_cast<std::size_t>(n * (n + 1) / 2));
}

INSTANTIATE_TEST_SUITE_P(Models, MassLoopsForced, ::testing::Values("sedan", "andrews", "chain9", "fourbar"));

}  // namespace
}  // namespace dydp::mbs
