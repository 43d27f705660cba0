// Every generated model's tangent functions, entry by entry, against central differences with a
// step study: sensors_tangent against the numerical oracle's sensors (parameters through
// set_symbolic_parameters), velocity_constraints_tangent and residual_tangent against the
// generated primal functions constraints and residual; and each tangent's primal `out` against
// its primal function. One direction per element of q, qd, qdd, inp, p, at three random states.
#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "generated_models/registry.hpp"
#include "model_cases.hpp"
#include "oracle_compare.hpp"
#include "symbolic/mbs/numeric_dynamics.hpp"

namespace dydp::mbs {
namespace {

using namespace dydp::mbs::testing;

// The seeded arrays of a GeneratedTangent, in its argument order.
enum SeedArray { kQ, kQd, kQdd, kInp, kP, kArrays };
const char* const kArrayNames[kArrays] = {"q", "qd", "qdd", "inp", "p"};

struct Direction {
  int array;
  int index;
};

int array_size(const GeneratedModel& g, int array) {
  switch (array) {
    case kQ: case kQd: case kQdd: return g.n;
    case kInp: return g.inputs;
    default: return g.parameters;
  }
}

Vector& element_array(Args& a, int array) {
  switch (array) {
    case kQ: return a.q;
    case kQd: return a.qd;
    case kQdd: return a.qdd;
    case kInp: return a.inp;
    default: return a.p;
  }
}
const Vector& element_array(const Args& a, int array) { return element_array(const_cast<Args&>(a), array); }

// One direction per element of every seeded array.
std::vector<Direction> directions(const GeneratedModel& g) {
  std::vector<Direction> all;
  for (int a = 0; a < kArrays; ++a)
    for (int i = 0; i < array_size(g, a); ++i) all.push_back({a, i});
  return all;
}

// The values a tangent function returns: out (k) and dout (k x nd, column d: direction d).
struct Tangent {
  Vector out;
  Matrix dout;
};

// Seeds for `dirs` (one unit seed each) handed to call(nd, seeds, out, dout).
template <class Call>
Tangent call_seeded(int k, const GeneratedModel& g, const std::vector<Direction>& dirs, Call call) {
  const int nd = static_cast<int>(dirs.size());
  std::vector<std::vector<double>> seeds(kArrays);
  for (int s = 0; s < kArrays; ++s) seeds[s].assign(static_cast<size_t>(std::max(array_size(g, s), 1)) * nd, 0.0);
  for (int d = 0; d < nd; ++d) {
    const int stride = std::max(array_size(g, dirs[d].array), 1);
    seeds[dirs[d].array][static_cast<size_t>(d) * stride + dirs[d].index] = 1.0;
  }
  std::vector<double> out(std::max(k, 1)), dout(static_cast<size_t>(std::max(k, 1)) * nd);
  call(nd, seeds, out.data(), dout.data());
  Tangent t;
  t.out = Eigen::Map<Vector>(out.data(), k);
  t.dout = Eigen::Map<Matrix>(dout.data(), k, nd);
  return t;
}

Tangent call_tangent(GeneratedTangent f, int k, const GeneratedModel& g, const Args& a,
                     const std::vector<Direction>& dirs) {
  return call_seeded(k, g, dirs, [&](int nd, const std::vector<std::vector<double>>& seeds, double* out, double* dout) {
    f(a.q.data(), a.qd.data(), a.qdd.data(), a.lam.data(), a.inp.data(), a.p.data(), nd, seeds[kQ].data(),
      seeds[kQd].data(), seeds[kQdd].data(), seeds[kInp].data(), seeds[kP].data(), out, dout);
  });
}

// A velocity tangent (no q seeds) on `dirs`, none of which may seed q.
Tangent call_velocity_tangent(GeneratedVelocityTangent f, int k, const GeneratedModel& g, const Args& a,
                              const std::vector<Direction>& dirs) {
  return call_seeded(k, g, dirs, [&](int nd, const std::vector<std::vector<double>>& seeds, double* out, double* dout) {
    f(a.q.data(), a.qd.data(), a.qdd.data(), a.lam.data(), a.inp.data(), a.p.data(), nd, seeds[kQd].data(),
      seeds[kQdd].data(), seeds[kInp].data(), seeds[kP].data(), out, dout);
  });
}

Args random_args(std::mt19937& rng, const GeneratedModel& g, const Vector& p) {
  Args a;
  a.q = random_vector(rng, g.n, 1.2);
  a.qd = random_vector(rng, g.n, 2.0);
  a.qdd = random_vector(rng, g.n, 3.0);
  a.lam = random_vector(rng, g.m, 5.0);
  a.inp = random_vector(rng, g.inputs, 10.0);
  a.p = p;
  for (int i = 0; i < g.parameters; ++i) a.p[i] *= 1.0 + 0.1 * random_vector(rng, 1, 1.0)[0];
  return a;
}

// The step scale of a variable: its magnitude (at least 0.1 for q, qd, qdd, inp, which are
// of order one; a parameter's own size, 1 when it is zero).
double step_scale(const Args& a, Direction d) {
  const double x = std::fabs(element_array(a, d.array)[d.index]);
  if (d.array == kP) return x > 0 ? x : 1.0;
  return std::max(x, 0.1);
}

constexpr double kTolerance = 1e-7;
constexpr double kSteps[] = {1e-3, 1e-4, 1e-5};

struct Worst {
  double ratio = 0.0;  // largest error / allowed over the entries checked
  int entries = 0;
};

// Compares every entry of t.dout with central differences of `reference` (the primal whose
// tangent dout is) over the steps, keeping each entry's best. An entry passes when its
// best error is within kTolerance of the entry's scale: |analytic| plus 1e-3 of the row's
// natural size (its largest derivative times that variable's scale) per unit of this variable,
// plus an absolute floor of roundoff size (1e-12 of the value per unit of the variable).
Worst check_entries(const char* what, const GeneratedModel& g, const Args& a, const std::vector<Direction>& dirs,
                    const Tangent& t, const std::function<Vector(const Args&)>& reference) {
  const int k = static_cast<int>(t.out.size()), nd = static_cast<int>(dirs.size());
  Worst worst;
  if (k == 0) return worst;
  std::vector<double> scale(nd);
  for (int d = 0; d < nd; ++d) scale[d] = step_scale(a, dirs[d]);
  Vector row_size = Vector::Zero(k);
  for (int d = 0; d < nd; ++d) row_size = row_size.cwiseMax(t.dout.col(d).cwiseAbs() * scale[d]);
  for (int d = 0; d < nd; ++d) {
    const Direction dir = dirs[d];
    // Per step h, the second-order central difference and the fourth-order one (Richardson on
    // h and 2h), which on large models (the 200-body chain) stays truncation-free at steps
    // large enough for roundoff not to matter.
    std::vector<Vector> fd;
    std::vector<double> fd_step;
    for (double rel : kSteps) {
      const double h = rel * scale[d];
      const auto at = [&](double step) {
        Args x = a;
        element_array(x, dir.array)[dir.index] += step;
        return reference(x);
      };
      const Vector d1 = at(h) - at(-h), d2 = at(2 * h) - at(-2 * h);
      fd.push_back(d1 / (2 * h));
      fd.push_back((8 * d1 - d2) / (12 * h));
      fd_step.insert(fd_step.end(), {rel, rel});
    }
    for (int j = 0; j < k; ++j) {
      const double analytic = t.dout(j, d);
      double best = std::numeric_limits<double>::infinity(), best_fd = 0.0, best_step = 0.0;
      for (size_t s = 0; s < fd.size(); ++s) {
        const double e = std::fabs(fd[s][j] - analytic);
        if (!std::isfinite(fd[s][j])) {
          ADD_FAILURE() << g.name << ": " << what << " output " << j << ": central difference not finite";
          return worst;
        }
        if (e < best) best = e, best_fd = fd[s][j], best_step = fd_step[s];
      }
      const double allowed = kTolerance * (std::fabs(analytic) + 1e-3 * row_size[j] / scale[d]) +
                             1e-12 * std::max(std::fabs(t.out[j]), 1.0) / scale[d];
      EXPECT_TRUE(std::isfinite(analytic)) << g.name << ": " << what << " output " << j << " by "
                                           << kArrayNames[dir.array] << "[" << dir.index << "]: tangent not finite";
      EXPECT_LE(best, allowed) << g.name << ": " << what << " output " << j << " by " << kArrayNames[dir.array] << "["
                               << dir.index << "]: tangent " << analytic << ", central difference " << best_fd
                               << " (best relative step " << best_step << ")";
      worst.ratio = std::max(worst.ratio, best / allowed);
      ++worst.entries;
    }
  }
  return worst;
}

struct Fixture {
  const GeneratedModel* g;
  Model model;
  Vector p;  // symbolic parameters (padded)
  explicit Fixture(const std::string& name)
      : g(generated::find_model(name)), model(load_model(std::string(DYDP_MODELS_DIR) + "/" + name + ".mbs.yaml")) {
    p = Vector::Zero(std::max(g->parameters, 1));
    for (int i = 0; i < g->parameters; ++i) p[i] = g->parameter_values[i];
  }
};

constexpr int kStates = 3;  // random states per model

using Reference = std::function<Vector(const Args&)>;

// The oracle's sensors read q, qd, qdd and the parameters, not the inputs: a driven joint's
// motion reaches them through q, so their derivative by inp is zero (the multibody block seeds
// the driven rows of dq; a sensor that read inp as well would count the motion twice).
Reference oracle_sensors(NumericDynamics& oracle, const GeneratedModel& g) {
  return [&oracle, &g](const Args& x) {
    oracle.set_symbolic_parameters(x.p.data());
    return Vector(oracle.sensors(x.q.head(g.n), x.qd.head(g.n), x.qdd.head(g.n)));
  };
}

// (h, J qd) from the generated primal `constraints`: h (m), J (m x n row-major).
Reference velocity_constraints(const GeneratedModel& g) {
  return [&g](const Args& x) {
    const int m = g.m, n = g.n;
    const Vector all = generated_outputs(g.constraints, m + m * n, x);
    const Matrix J = Eigen::Map<const Eigen::Matrix<double, -1, -1, Eigen::RowMajor>>(all.data() + m, m, n);
    Vector v(2 * m);
    v << all.head(m), J * x.qd.head(n);
    return v;
  };
}

// h alone from the generated primal `constraints`.
Reference position_constraints(const GeneratedModel& g) {
  return [&g](const Args& x) { return Vector(generated_outputs(g.constraints, g.m + g.m * g.n, x).head(g.m)); };
}

// M qdd + c - J^T lam, J qdd + Jdot qd with the cut forces applied at the cut points, as the
// residual's tangent writes it (its primal outputs, checked against the oracle in
// generated_test.cpp; the residual function itself reads no multipliers). Off the constraint
// manifold (random states) the two forces of a ball cut are a couple d x f, which J^T lam has
// not: the reference must be this form, not residual - J^T lam.
Reference residual(const GeneratedModel& g) {
  return [&g](const Args& x) { return tangent_primal(g.residual_tangent, g.n + g.m, x); };
}

// At kStates random states: the tangent's `out` against the primal reference (to `same`,
// relative), and every entry of dout against central differences of `reference`.
void check_function(const char* what, const Fixture& f, GeneratedTangent tangent, int outputs,
                    const Reference& primal, const Reference& reference, double same, unsigned seed) {
  const GeneratedModel& g = *f.g;
  const std::vector<Direction> dirs = directions(g);
  std::mt19937 rng(seed);
  Worst worst;
  for (int state = 0; state < kStates; ++state) {
    const Args a = random_args(rng, g, f.p);
    const Tangent t = call_tangent(tangent, outputs, g, a, dirs);
    const Vector value = primal(a);
    EXPECT_LE((t.out - value).cwiseAbs().maxCoeff(), same * std::max(value.cwiseAbs().maxCoeff(), 1.0))
        << g.name << ": " << what << " tangent's out is not its primal function's";
    const Worst w = check_entries(what, g, a, dirs, t, reference);
    worst.ratio = std::max(worst.ratio, w.ratio);
    worst.entries += w.entries;
  }
  ::testing::Test::RecordProperty("entries", worst.entries);
  ::testing::Test::RecordProperty("worst_error_over_allowed", std::to_string(worst.ratio));
}

class Tangents : public ::testing::TestWithParam<std::string> {};
// The same tests on the models they apply to only (instantiated below from models_where).
class TangentsWithSensors : public Tangents {};
class TangentsWithConstraints : public Tangents {};
class TangentsWithCoordinateGroups : public Tangents {};

TEST_P(TangentsWithSensors, SensorsMatchCentralDifferencesOfTheOracle) {
  Fixture f(GetParam());
  ASSERT_NE(f.g, nullptr);
  const GeneratedModel& g = *f.g;
  ASSERT_GT(g.sensor_outputs, 0) << g.name << " has no sensors";
  NumericDynamics oracle(f.model);
  const Reference generated = [&g](const Args& x) { return generated_outputs(g.sensors, g.sensor_outputs, x); };
  check_function("sensors", f, g.sensors_tangent, g.sensor_outputs, generated, oracle_sensors(oracle, g), 1e-13, 21);
}

TEST_P(TangentsWithConstraints, VelocityConstraintsMatchCentralDifferencesOfConstraints) {
  Fixture f(GetParam());
  ASSERT_NE(f.g, nullptr);
  const GeneratedModel& g = *f.g;
  ASSERT_GT(g.m, 0) << g.name << " has no constraints";
  check_function("velocity constraints", f, g.velocity_constraints_tangent, 2 * g.m, velocity_constraints(g),
                 velocity_constraints(g), 1e-13, 22);
}

TEST_P(TangentsWithConstraints, PositionConstraintsMatchCentralDifferencesOfConstraints) {
  Fixture f(GetParam());
  ASSERT_NE(f.g, nullptr);
  const GeneratedModel& g = *f.g;
  ASSERT_GT(g.m, 0) << g.name << " has no constraints";
  check_function("position constraints", f, g.constraints_tangent, g.m, position_constraints(g),
                 position_constraints(g), 1e-13, 25);
}

TEST_P(Tangents, ResidualMatchesCentralDifferencesOfResidual) {
  Fixture f(GetParam());
  ASSERT_NE(f.g, nullptr);
  const GeneratedModel& g = *f.g;
  check_function("residual", f, g.residual_tangent, g.n + g.m, residual(g), residual(g), 1e-12, 23);
}

// The residual's velocity tangent (not seeded on q) on every direction but q's: against central
// differences of the residual, and equal to the full tangent's columns for the same seeds.
TEST_P(Tangents, ResidualVelocityTangentMatchesCentralDifferencesAndTheFullTangent) {
  Fixture f(GetParam());
  ASSERT_NE(f.g, nullptr);
  const GeneratedModel& g = *f.g;
  ASSERT_NE(g.residual_velocity_tangent, nullptr);
  std::vector<Direction> dirs;
  for (const Direction& d : directions(g))
    if (d.array != kQ) dirs.push_back(d);
  std::mt19937 rng(26);
  Worst worst;
  for (int state = 0; state < kStates; ++state) {
    const Args a = random_args(rng, g, f.p);
    const Tangent t = call_velocity_tangent(g.residual_velocity_tangent, g.n + g.m, g, a, dirs);
    const Tangent full = call_tangent(g.residual_tangent, g.n + g.m, g, a, dirs);
    EXPECT_LE((t.out - full.out).cwiseAbs().maxCoeff(), 1e-13 * std::max(full.out.cwiseAbs().maxCoeff(), 1.0))
        << g.name << ": the velocity tangent's out is not the residual";
    EXPECT_LE((t.dout - full.dout).cwiseAbs().maxCoeff(), 1e-12 * std::max(full.dout.cwiseAbs().maxCoeff(), 1.0))
        << g.name << ": the velocity tangent differs from the full tangent at dq = 0";
    const Worst w = check_entries("residual velocity", g, a, dirs, t, residual(g));
    worst.ratio = std::max(worst.ratio, w.ratio);
    worst.entries += w.entries;
  }
  RecordProperty("entries", worst.entries);
  RecordProperty("worst_error_over_allowed", std::to_string(worst.ratio));
}

// The residual's tangent in blocks, every block in one call with the directions each block may
// take (one unit seed each: the full block every array's elements, the velocity block all but
// q's, a group's position block the group's q, qd and qdd, its velocity block the group's qd
// and qdd): its out is the residual, and each column equals the full tangent's for that seed.
// The sedan must have groups (its corners, wheels and the chassis' coordinates).
TEST_P(TangentsWithCoordinateGroups, ResidualTangentInBlocksIsTheFullTangentOnEachBlocksSeeds) {
  Fixture f(GetParam());
  ASSERT_NE(f.g, nullptr);
  const GeneratedModel& g = *f.g;
  if (std::string(g.name) == "sedan") {
    ASSERT_GE(g.tangent_groups, 8);
  }
  ASSERT_TRUE(g.residual_tangent_groups) << g.name << " has no coordinate groups";
  std::vector<Direction> dirs;
  std::vector<int> per_block;
  auto add_block = [&](auto keep) {
    int count = 0;
    for (const Direction& d : directions(g))
      if (keep(d)) dirs.push_back(d), ++count;
    per_block.push_back(count);
  };
  add_block([](const Direction&) { return true; });
  add_block([](const Direction& d) { return d.array != kQ; });
  for (int group = 0; group < g.tangent_groups; ++group) {
    const auto in_group = [&](const Direction& d) { return d.array <= kQdd && g.tangent_group[d.index] == group; };
    add_block(in_group);
    add_block([&](const Direction& d) { return d.array != kQ && in_group(d); });
    EXPECT_GT(per_block.back(), 0) << g.name << ": group " << group << " has no coordinate";
  }
  std::mt19937 rng(27);
  for (int state = 0; state < kStates; ++state) {
    const Args a = random_args(rng, g, f.p);
    const int k = g.n + g.m;
    const Tangent blocks = call_seeded(k, g, dirs, [&](int, const std::vector<std::vector<double>>& seeds, double* out,
                                                       double* dout) {
      g.residual_tangent_groups(a.q.data(), a.qd.data(), a.qdd.data(), a.lam.data(), a.inp.data(), a.p.data(),
                                per_block.data(), seeds[kQ].data(), seeds[kQd].data(), seeds[kQdd].data(),
                                seeds[kInp].data(), seeds[kP].data(), out, dout);
    });
    const Tangent full = call_tangent(g.residual_tangent, k, g, a, dirs);
    EXPECT_LE((blocks.out - full.out).cwiseAbs().maxCoeff(), 1e-13 * std::max(full.out.cwiseAbs().maxCoeff(), 1.0))
        << g.name << ": the blocks' out is not the residual";
    for (int d = 0; d < static_cast<int>(dirs.size()); ++d)
      EXPECT_LE((blocks.dout.col(d) - full.dout.col(d)).cwiseAbs().maxCoeff(),
                1e-12 * std::max(full.dout.cwiseAbs().maxCoeff(), 1.0))
          << g.name << ": direction " << d << " (" << kArrayNames[dirs[d].array] << "[" << dirs[d].index << "])";
  }
}

INSTANTIATE_TEST_SUITE_P(Models, Tangents, ::testing::Values(DYDP_TEST_MODELS),
                         [](const auto& info) { return info.param; });
INSTANTIATE_TEST_SUITE_P(Models, TangentsWithSensors, ::testing::ValuesIn(models_where({DYDP_TEST_MODELS}, has_sensors)),
                         [](const auto& info) { return info.param; });
INSTANTIATE_TEST_SUITE_P(Models, TangentsWithConstraints,
                         ::testing::ValuesIn(models_where({DYDP_TEST_MODELS}, has_constraints)),
                         [](const auto& info) { return info.param; });
INSTANTIATE_TEST_SUITE_P(Models, TangentsWithCoordinateGroups,
                         ::testing::ValuesIn(models_where({DYDP_TEST_MODELS}, has_coordinate_groups)),
                         [](const auto& info) { return info.param; });

// The filtered lists are not empty, and the sedan (whose corners, wheels and chassis make
// coordinate groups) is among the grouped models: a filter cannot drop the cases it is for.
TEST(TangentCases, EachFilteredListHasItsModels) {
  EXPECT_FALSE(models_where({DYDP_TEST_MODELS}, has_sensors).empty());
  EXPECT_FALSE(models_where({DYDP_TEST_MODELS}, has_constraints).empty());
  const std::vector<std::string> grouped = models_where({DYDP_TEST_MODELS}, has_coordinate_groups);
  EXPECT_NE(std::find(grouped.begin(), grouped.end(), "sedan"), grouped.end());
}

// The check fails on a wrong tangent: on the sedan, the largest entry of each tangent off by a
// relative 1e-5, and a sensor given a derivative by an input (which it must not read).
TEST(TangentCheck, FailsOnOneWrongEntry) {
  Fixture f("sedan");
  const GeneratedModel& g = *f.g;
  NumericDynamics oracle(f.model);
  std::mt19937 rng(24);
  const Args a = random_args(rng, g, f.p);
  const std::vector<Direction> dirs = directions(g);
  const auto off = [](Tangent t, Eigen::Index j, Eigen::Index d, double value) {
    t.dout(j, d) = value;
    return t;
  };
  Eigen::Index j, d;
  const Tangent s = call_tangent(g.sensors_tangent, g.sensor_outputs, g, a, dirs);
  s.dout.cwiseAbs().maxCoeff(&j, &d);
  EXPECT_NONFATAL_FAILURE(check_entries("sensors", g, a, dirs, off(s, j, d, s.dout(j, d) * (1 + 1e-5)),
                                        oracle_sensors(oracle, g)),
                          "central difference");
  const Eigen::Index first_input = 3 * g.n;
  ASSERT_EQ(dirs[first_input].array, kInp);
  s.dout.col(0).cwiseAbs().maxCoeff(&j);  // a sensor that moves with q[0]: as if it read inp[0] too
  EXPECT_NONFATAL_FAILURE(check_entries("sensors", g, a, dirs, off(s, j, first_input, s.dout(j, 0)),
                                        oracle_sensors(oracle, g)),
                          "central difference");
  const Tangent v = call_tangent(g.velocity_constraints_tangent, 2 * g.m, g, a, dirs);
  v.dout.cwiseAbs().maxCoeff(&j, &d);
  EXPECT_NONFATAL_FAILURE(check_entries("velocity constraints", g, a, dirs, off(v, j, d, v.dout(j, d) * (1 + 1e-5)),
                                        velocity_constraints(g)),
                          "central difference");
  const Tangent h = call_tangent(g.constraints_tangent, g.m, g, a, dirs);
  h.dout.cwiseAbs().maxCoeff(&j, &d);
  EXPECT_NONFATAL_FAILURE(check_entries("position constraints", g, a, dirs, off(h, j, d, h.dout(j, d) * (1 + 1e-5)),
                                        position_constraints(g)),
                          "central difference");
  const Tangent r = call_tangent(g.residual_tangent, g.n + g.m, g, a, dirs);
  r.dout.cwiseAbs().maxCoeff(&j, &d);
  EXPECT_NONFATAL_FAILURE(check_entries("residual", g, a, dirs, off(r, j, d, r.dout(j, d) * (1 + 1e-5)), residual(g)),
                          "central difference");
}

}  // namespace
}  // namespace dydp::mbs
