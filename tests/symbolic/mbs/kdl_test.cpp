// The KDL chain built from a serial model (bench/mbs/kdl_chain.hpp) against the generated
// functions at random states: the mass matrix (ChainDynParam::JntToMass against the inertial
// tangent seeded with identity columns), inverse dynamics (ChainIdSolver_RNE against the residual
// with lam = 0 and no inputs: M qdd + c) and forward dynamics (ChainFdSolver_RNE against
// ReducedDynamics::solve). Agreement here is what makes bench_kdl compare like with like.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <string>

#include "bench/mbs/kdl_chain.hpp"
#include "generated_models/registry.hpp"
#include "symbolic/mbs/reduced_dynamics.hpp"
#include "tests/symbolic/mbs/oracle_compare.hpp"

namespace {

using namespace dydp::mbs;
using namespace dydp::mbs::testing;

KDL::JntArray jnt(const Vector& v, int n) {
  KDL::JntArray a(n);
  a.data = v.head(n);
  return a;
}

Model load(const std::string& name) { return load_model(std::string(DYDP_MODELS_DIR) + "/" + name + ".mbs.yaml"); }

class KdlChain : public ::testing::TestWithParam<const char*> {};

TEST_P(KdlChain, MatchesModelSizes) {
  const Model model = load(GetParam());
  const GeneratedModel& g = *dydp::generated::find_model(GetParam());
  const KDL::Chain chain = dydp::bench::kdl_chain(model);
  EXPECT_EQ(static_cast<int>(chain.getNrOfJoints()), g.n);
  EXPECT_EQ(static_cast<int>(chain.getNrOfSegments()), g.n);
  EXPECT_EQ(g.m, 0);
  EXPECT_EQ(g.inputs, 0);
}

TEST_P(KdlChain, AgreesWithGeneratedDynamics) {
  const std::string name = GetParam();
  const GeneratedModel& g = *dydp::generated::find_model(name);
  const int n = g.n;
  dydp::bench::KdlDynamics kdl(load(name));
  ReducedDynamics reduced(g);
  ASSERT_EQ(reduced.nu(), n);
  std::mt19937 rng(11);
  double worst_mass = 0.0, worst_id = 0.0, worst_fd = 0.0;
  for (int trial = 0; trial < 10; ++trial) {
    Args a;
    a.q = random_vector(rng, n, 1.5);
    a.qd = random_vector(rng, n, 1.0);
    a.qdd = random_vector(rng, n, 1.0);
    a.lam = Vector::Zero(1);
    a.inp = Vector::Zero(std::max(1, g.inputs));
    a.p = g.parameters ? Vector(Eigen::Map<const Vector>(g.parameter_values, g.parameters)) : Vector::Zero(1);
    const KDL::JntArray q = jnt(a.q, n), qd = jnt(a.qd, n), qdd = jnt(a.qdd, n);

    // Mass matrix.
    const Matrix M = generated_mass(g, a);
    ASSERT_EQ(kdl.mass(q), 0);
    const double e_mass = relative_error(kdl.H.data, M);
    EXPECT_LT(e_mass, 1e-12) << name << " trial " << trial;
    worst_mass = std::max(worst_mass, e_mass);

    // Inverse dynamics: r = M qdd + c (gravity included).
    const Vector r = generated_outputs(g.residual, n + g.m, a).head(n);
    ASSERT_EQ(kdl.inverse(q, qd, qdd), 0);
    const double e_id = relative_error(kdl.torques.data, r);
    EXPECT_LT(e_id, 1e-12) << name << " trial " << trial;
    worst_id = std::max(worst_id, e_id);

    // Forward dynamics with no joint forces.
    ReducedDynamics::Result res;
    Vector u(n), ud(n);
    for (int i = 0; i < n; ++i) {
      u[i] = a.q[reduced.independent()[i]];
      ud[i] = a.qd[reduced.independent()[i]];
    }
    reduced.solve(u.data(), ud.data(), a.inp.data(), nullptr, a.q, res);
    KDL::JntArray no_torques(n);
    KDL::SetToZero(no_torques);
    ASSERT_EQ(kdl.forward(q, qd, no_torques), 0);
    // chain200's M has a condition number near 1e7 at these states: the two solutions differ by
    // up to ~3e-10 (relative) while each satisfies M qdd + c = 0 to ~1e-14 of |c|, so the
    // residual at KDL's accelerations is checked as well.
    const double e_fd = relative_error(kdl.qdd.data, res.qdd);
    EXPECT_LT(e_fd, 1e-9) << name << " trial " << trial;
    worst_fd = std::max(worst_fd, e_fd);
    const Vector c = generated_outputs(g.residual, n, Args{a.q, a.qd, Vector::Zero(n), a.lam, a.inp, a.p});
    const Vector at_kdl = generated_outputs(g.residual, n, Args{a.q, a.qd, kdl.qdd.data, a.lam, a.inp, a.p});
    EXPECT_LT(at_kdl.cwiseAbs().maxCoeff() / c.cwiseAbs().maxCoeff(), 1e-12) << name << " trial " << trial;
  }
  std::printf("%s: worst relative difference, M %.2e, inverse dynamics %.2e, forward dynamics %.2e\n", name.c_str(),
              worst_mass, worst_id, worst_fd);
}

INSTANTIATE_TEST_SUITE_P(SerialChains, KdlChain, ::testing::Values("chain9", "chain200"),
                         [](const ::testing::TestParamInfo<const char*>& info) { return std::string(info.param); });

TEST(KdlChainBuilder, RejectsClosedLoops) {
  EXPECT_THROW(dydp::bench::kdl_chain(load("fourbar")), std::invalid_argument);
}

}  // namespace
