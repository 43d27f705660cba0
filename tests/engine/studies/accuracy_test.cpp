// The accuracy study on the mass-spring-damper scene: its reference is converged, and errors
// fall as tolerances tighten and steps shrink, for states, objectives and sensitivities.
#include <gtest/gtest.h>

#include <algorithm>

#include "engine/framework/diagram.hpp"
#include "engine/studies/accuracy.hpp"

namespace dydp::engine {
namespace {

TEST(Accuracy, ErrorsFallAsTolerancesTighten) {
  Diagram d = load_scene(std::string(DYDP_SOURCE_DIR) + "/scenarios/msd_sensitivity.yaml");
  AccuracySpec spec;
  spec.rtols = {1e-3, 1e-5, 1e-7};
  spec.step_fractions = {1.0, 0.25};
  const AccuracyReport r = accuracy_study(d, spec);
  ASSERT_EQ(r.rows.size(), 2 * 3 + 2 * 2u);
  EXPECT_LT(r.reference_check, 1e-8);
  for (size_t i = 0; i < r.rows.size(); ++i) {
    const AccuracyRow& row = r.rows[i];
    ASSERT_TRUE(row.ok) << row.method << " " << row.setting << ": " << row.failure;
    EXPECT_GT(row.sensitivity_error, r.reference_check) << "errors are resolved above the reference";
    const bool same_method_next = i + 1 < r.rows.size() && r.rows[i + 1].method == row.method;
    if (!same_method_next) continue;
    const AccuracyRow& tighter = r.rows[i + 1];
    EXPECT_LT(tighter.signal_error, row.signal_error) << row.method << " " << row.setting;
    EXPECT_LT(tighter.objective_error, row.objective_error) << row.method << " " << row.setting;
    EXPECT_LT(tighter.sensitivity_error, row.sensitivity_error) << row.method << " " << row.setting;
  }
  // The scene's own solver settings are restored.
  EXPECT_EQ(d.solver.method, "bdf");
  EXPECT_EQ(d.solver.rtol, 1e-8);
  const AccuracyRow* best = cheapest_for(r, 1e-3);
  ASSERT_NE(best, nullptr);
  EXPECT_LE(std::max({best->signal_error, best->objective_error, best->sensitivity_error}), 1e-3);
}

}  // namespace
}  // namespace dydp::engine
