// The sensitivity matrix of the two sedan scenes end to end: every declared scene parameter and
// direction (18 on the comfort scene, 19 on the handling scene) on every objective and every
// logged signal over the output grid, the exact forward sensitivities of one run against
// central differences of whole runs. A step study shows each difference quotient is in its h^2
// regime before it is believed, so the comparison cannot pass on noise; the tolerance is the
// study's own measure of what it resolves. docs/testing.md states the metric and shows the test
// failing for a tangent scaled by 1.001 in the spring, the anti-roll bar, either tyre, the
// damper's state derivatives and the generated car.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <tuple>
#include <vector>

#include "engine/analysis/run.hpp"
#include "engine/framework/diagram.hpp"
#include "tests/apps/dydp_process.hpp"

namespace dydp::test {
namespace {

using engine::Diagram;
using engine::RunOptions;
using engine::RunResult;

// Tolerances of every run: BDF at rtol = atol = 1e-12 (atol per state's nominal magnitude),
// the sensitivities in the error test. At rtol 1e-10 the extrapolated quotients of the comfort
// scene's valve-current columns (1 % steps) differ from the sensitivity by up to 3e-5, the
// runs' noise; at 1e-12 by 6e-7 at most, well below what a tangent wrong by 0.1 % moves
// (docs/testing.md).
constexpr double kRtol = 1e-12, kAtol = 1e-12;

// The first step h moves the most sensitive quantity by about this fraction of its magnitude
// (by the exact sensitivity), at most kLargestStep of |p|; the study halves it until every
// column is in its h^2 regime.
constexpr double kFirstChange = 4e-3;
constexpr double kLargestStep = 2e-2;
constexpr int kMaxHalvings = 8;

// A column is judged against its own largest magnitude, or, when that is below kNegligible of
// the largest normalised column of the same quantity (|p| max |dS/dp| over the directions), on
// that scale times kNegligible.
constexpr double kNegligible = 1e-3;

// The h^2 regime: D2 = q(4h) - q(2h) is 4 times D1 = q(2h) - q(h) (largest over the grid), to
// within kRatioSlack; or both differences are below kResolved (the quotients agree
// at every step: no h^2 term to see above the runs' own error, which the same bound covers).
constexpr double kRatioSlack = 1.0, kResolved = 2e-6;

// The sensitivity must match the finer quotient with its h^2 term removed to within the study's
// misfit (max |D2 - 4 D1|, which bounds the removed term's h^4 remainder 45-fold and the runs'
// noise in it about 4-fold), but never tighter than kResolved; a study whose misfit is above
// kWorst does not resolve what the test is for and fails.
constexpr double kWorst = 1e-4;

/// The quantities of a run: each objective (one sample), then each logged signal over the grid.
struct Quantities {
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;
};

Quantities values_of(const RunResult& r) {
  Quantities q;
  for (const auto& o : r.objectives) q.names.push_back(o.name), q.columns.push_back({o.value});
  for (int i = 0; i < r.num_signals(); ++i) {
    q.names.push_back(r.signal_names[i]);
    std::vector<double> s(r.t.size());
    for (size_t k = 0; k < r.t.size(); ++k) s[k] = r.value(static_cast<int>(k), i);
    q.columns.push_back(s);
  }
  return q;
}

/// d(quantity)/d(direction d), in the order of values_of.
std::vector<std::vector<double>> sensitivities_of(const RunResult& r, int d) {
  std::vector<std::vector<double>> c;
  for (const auto& o : r.objectives) c.push_back({o.sensitivity[d]});
  for (int i = 0; i < r.num_signals(); ++i) {
    std::vector<double> s(r.t.size());
    for (size_t k = 0; k < r.t.size(); ++k) s[k] = r.tangent(static_cast<int>(k), d, i);
    c.push_back(s);
  }
  return c;
}

double largest(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::fabs(x));
  return m;
}

/// max_k |a_k - f b_k|
double largest_difference(const std::vector<double>& a, const std::vector<double>& b, double f = 1.0) {
  double m = 0;
  for (size_t k = 0; k < a.size(); ++k) m = std::max(m, std::fabs(a[k] - f * b[k]));
  return m;
}

/// One column's verdict: figures relative to the column's scale.
struct ColumnCheck {
  std::string parameter, quantity;
  double scale = 0;         ///< what the figures are relative to
  double d1 = 0, d2 = 0;    ///< max |q(2h) - q(h)|, max |q(4h) - q(2h)|
  double misfit = 0;        ///< max |D2 - 4 D1|
  double fine = 0;          ///< max |sens - q(h)|
  double error = 0;         ///< max |sens - (q(h) + (q(h) - q(2h)) / 3)|
  double tolerance = 0;
  bool h2() const { return std::fabs(d2 / d1 - 4) <= kRatioSlack || std::max(d1, d2) <= kResolved; }
  /// The study sees the h^2 term, and resolves kWorst.
  bool resolved() const { return h2() && tolerance <= kWorst; }
  bool agrees() const { return error <= tolerance; }
};

class SensitivityMatrix : public DydpProcessTest {
 protected:
  SensitivityMatrix() : DydpProcessTest("dydp_sensitivity_matrix_") {}

  /// The shipped scene with each `from` replaced by `to` exactly `count` times.
  std::string short_copy(const std::string& scene, const std::vector<std::tuple<std::string, std::string, int>>& edits) {
    std::string text = scene_copy_text(source_path("scenarios/" + scene));
    for (const auto& [from, to, count] : edits) text = replaced_all(text, from, to, count);
    return write(scene, text);
  }

  static Diagram tight(const std::string& scene) {
    Diagram d = engine::load_scene(scene);
    d.solver.method = "bdf";
    d.solver.rtol = kRtol;
    d.solver.atol = kAtol;
    d.solver.sens_error_test = true;
    return d;
  }

  /// (q(p + h) - q(p - h)) / 2h for every quantity: two runs without sensitivities.
  static std::vector<std::vector<double>> central_difference(const std::string& scene, int parameter, double h) {
    RunOptions options;
    options.sensitivities = false;
    Diagram up = tight(scene), down = tight(scene);
    const double p = up.parameters[parameter].value;
    up.set_parameter(parameter, p + h, false);
    down.set_parameter(parameter, p - h, false);
    const Quantities a = values_of(engine::run(up, options)), b = values_of(engine::run(down, options));
    std::vector<std::vector<double>> q(a.columns.size());
    for (size_t i = 0; i < q.size(); ++i)
      for (size_t k = 0; k < a.columns[i].size(); ++k) q[i].push_back((a.columns[i][k] - b.columns[i][k]) / (2 * h));
    return q;
  }

  /// The columns of direction p against the quotients q[0], q[1], q[2] at h, 2h, 4h.
  static std::vector<ColumnCheck> judge(const std::string& parameter, const Quantities& base,
                                        const std::vector<std::vector<double>>& sens,
                                        const std::vector<std::vector<std::vector<double>>>& q,
                                        const std::vector<double>& quantity_scale, double magnitude) {
    std::vector<ColumnCheck> columns;
    for (size_t i = 0; i < base.names.size(); ++i) {
      ColumnCheck c{parameter, base.names[i]};
      c.scale = std::max(largest(q[0][i]), kNegligible * quantity_scale[i] / magnitude);
      if (c.scale == 0) c.scale = 1;  // a quantity no direction moves: judged absolutely
      std::vector<double> d1(q[0][i].size()), d2(d1.size()), extrapolated(d1.size());
      for (size_t k = 0; k < d1.size(); ++k) {
        d1[k] = q[1][i][k] - q[0][i][k];
        d2[k] = q[2][i][k] - q[1][i][k];
        extrapolated[k] = q[0][i][k] - d1[k] / 3;
      }
      c.d1 = largest(d1) / c.scale;
      c.d2 = largest(d2) / c.scale;
      c.misfit = largest_difference(d2, d1, 4.0) / c.scale;
      c.fine = largest_difference(sens[i], q[0][i]) / c.scale;
      c.error = largest_difference(sens[i], extrapolated) / c.scale;
      c.tolerance = std::max(c.misfit, kResolved);
      columns.push_back(c);
    }
    return columns;
  }

  /// Every parameter's columns against central differences; `every` > 1 checks every
  /// `every`-th parameter only (the sanitizer build). Prints one line per parameter and a
  /// summary, and fails for each parameter with a column whose study is not in its h^2 regime
  /// or whose sensitivity is outside the study's tolerance.
  void check_matrix(const std::string& scene, size_t declared, int every = 1) {
    Diagram d = tight(scene);
    ASSERT_EQ(d.parameters.size(), declared) << "the scene's parameters and directions";
    std::vector<int> all(d.parameters.size());
    for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
    d.set_sensitivities(all);
    const RunResult exact = engine::run(d);
    const Quantities base = values_of(exact);
    std::printf("%s: %zu directions x %zu quantities, %ld steps, %.2f CPU s with the sensitivities\n", scene.c_str(),
                all.size(), base.names.size(), exact.stats.steps, exact.stats.cpu_seconds);

    // The exact columns, normalised by |p| (the change for a relative change of p): the scale
    // of each quantity is the largest over the directions.
    std::vector<std::vector<std::vector<double>>> sens(all.size());
    std::vector<double> magnitude(all.size()), quantity_scale(base.names.size(), 0.0);
    for (int p : all) {
      sens[p] = sensitivities_of(exact, p);
      const double v = d.parameters[p].value;
      magnitude[p] = v != 0 ? std::fabs(v) : d.parameters[p].upper - d.parameters[p].lower;
      for (size_t i = 0; i < base.names.size(); ++i)
        quantity_scale[i] = std::max(quantity_scale[i], magnitude[p] * largest(sens[p][i]));
    }

    std::vector<ColumnCheck> checked;
    for (size_t p = 0; p < all.size(); p += every) {
      const engine::SceneParameter& parameter = d.parameters[p];
      // First step: the most sensitive quantity moves by kFirstChange of its magnitude, at most
      // kLargestStep of |p|, and p +- 4h inside the scene's range where it declares one.
      double relative_change = 0;
      for (size_t i = 0; i < base.names.size(); ++i)
        if (largest(base.columns[i]) > 0)
          relative_change = std::max(relative_change, magnitude[p] * largest(sens[p][i]) / largest(base.columns[i]));
      ASSERT_GT(relative_change, 0) << parameter.name << " moves nothing";
      double h = std::min(kFirstChange / relative_change, kLargestStep) * magnitude[p];
      h = std::min({h, (parameter.value - parameter.lower) / 4, (parameter.upper - parameter.value) / 4});
      // q[0], q[1], q[2]: the quotients at h, 2h, 4h; each halving reuses two of them.
      std::vector<std::vector<std::vector<double>>> q = {central_difference(scene, p, h),
                                                         central_difference(scene, p, 2 * h),
                                                         central_difference(scene, p, 4 * h)};
      std::vector<ColumnCheck> columns = judge(parameter.name, base, sens[p], q, quantity_scale, magnitude[p]);
      int halvings = 0;
      while (!std::all_of(columns.begin(), columns.end(), [](const auto& c) { return c.resolved(); }) &&
             halvings < kMaxHalvings) {
        h /= 2;
        ++halvings;
        q = {central_difference(scene, p, h), std::move(q[0]), std::move(q[1])};
        columns = judge(parameter.name, base, sens[p], q, quantity_scale, magnitude[p]);
      }
      const ColumnCheck& worst = *std::max_element(columns.begin(), columns.end(), [](const auto& a, const auto& b) {
        return a.error / a.tolerance < b.error / b.tolerance;
      });
      std::printf("  %-26s h = %-10.3g (%.2g of |p|, %d halvings)  worst %-28s error %.2e (q(h) alone %.2e) tolerance %.2e"
                  "  d1 %.2e ratio %.2f\n",
                  parameter.name.c_str(), h, h / magnitude[p], halvings, worst.quantity.c_str(), worst.error, worst.fine,
                  worst.tolerance, worst.d1, worst.d2 / worst.d1);
      report_failures(columns);
      checked.insert(checked.end(), columns.begin(), columns.end());
    }
    print_summary(checked);
  }

  /// How the columns were resolved: by the ratio (its range) or below kResolved; the largest
  /// error, tolerance and error over tolerance.
  static void print_summary(const std::vector<ColumnCheck>& columns) {
    int by_ratio = 0, below = 0;
    double low = INFINITY, high = 0, error = 0, tolerance = 0, share = 0;
    for (const ColumnCheck& c : columns) {
      if (std::max(c.d1, c.d2) <= kResolved) {
        ++below;
      } else {
        ++by_ratio;
        low = std::min(low, c.d2 / c.d1);
        high = std::max(high, c.d2 / c.d1);
      }
      error = std::max(error, c.error);
      tolerance = std::max(tolerance, c.tolerance);
      share = std::max(share, c.error / c.tolerance);
    }
    std::printf("  %zu columns: %d in the h^2 regime (ratio %.2f to %.2f), %d with differences below %.0e; largest error"
                " %.2e, largest tolerance %.2e, largest error / tolerance %.3f\n",
                columns.size(), by_ratio, low, high, below, kResolved, error, tolerance, share);
  }

  /// One failure per parameter with any column outside its h^2 regime or its tolerance: how
  /// many, the worst (by error over tolerance) with its figures, and the others by name.
  static void report_failures(const std::vector<ColumnCheck>& columns) {
    std::vector<ColumnCheck> failed;
    for (const ColumnCheck& c : columns)
      if (!c.resolved() || !c.agrees()) failed.push_back(c);
    if (failed.empty()) return;
    std::sort(failed.begin(), failed.end(),
              [](const auto& a, const auto& b) { return a.error / a.tolerance > b.error / b.tolerance; });
    const ColumnCheck& c = failed.front();
    std::string others;
    for (size_t k = 1; k < failed.size(); ++k) others += " " + failed[k].quantity;
    ADD_FAILURE() << c.parameter << ": " << failed.size() << " of " << columns.size() << " columns fail. Worst "
                  << c.quantity << ": |sens - fd| " << c.error << " against a tolerance of " << c.tolerance << " ("
                  << c.error / c.tolerance << "x; against the finer quotient alone " << c.fine
                  << "); step study: differences " << c.d1 << ", " << c.d2 << " (ratio " << c.d2 / c.d1
                  << ", h^2 gives 4), misfit " << c.misfit << ", all relative to " << c.scale
                  << (others.empty() ? "" : ". Also:" + others);
  }
};

// Under the sanitizers (13 times slower) every sixth parameter only, on the same scenes: 3 of
// 18 and 4 of 19, 2.3 and 1.6 minutes instead of 6.6 and 3.1 for the whole matrix (docs/testing.md).
constexpr int kEvery = DYDP_SANITIZED ? 6 : 1;

// The comfort scene over its first 2 s (objective windows [1, 2] s).
TEST_F(SensitivityMatrix, ComfortSceneEveryParameterOnEveryObjectiveAndSignal) {
  const std::string scene = short_copy("fourposter_comfort.yaml", {{"stop: 20.0", "stop: 2.0", 1},
                                                                   {"window: [2.0, 20.0]", "window: [1.0, 2.0]", 2}});
  check_matrix(scene, 18, kEvery);
}

// The handling scene over its first 2 s: the steering ramp (0.5 to 1.5 s) and the first half
// second of the hold (objective windows [1.5, 2] s).
TEST_F(SensitivityMatrix, HandlingSceneEveryParameterOnEveryObjectiveAndSignal) {
  const std::string scene = short_copy("cornering_arb.yaml", {{"stop: 6.0", "stop: 2.0", 1},
                                                              {"window: [4.0, 6.0]", "window: [1.5, 2.0]", 4}});
  check_matrix(scene, 19, kEvery);
}

}  // namespace
}  // namespace dydp::test
