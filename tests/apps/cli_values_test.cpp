// The numbers the dydp program writes, checked by value against independent references: the
// shipped scenarios/msd_sensitivity.yaml through `dydp run` against the closed form of the
// mass-spring-damper (x(t), its sensitivities by complex step, the rms objective by
// Gauss-Legendre), the `sweep --delta` column against the closed form's derivative times the
// step, and `accuracy`'s named setting against the cheapest qualifying row of accuracy.csv.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <vector>

#include "io/csv.hpp"
#include "tests/apps/dydp_process.hpp"
#include "tests/engine/msd_closed_form.hpp"
#include "tests/grid_error.hpp"

namespace dydp::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using Complex = std::complex<double>;

// scenarios/msd_sensitivity.yaml: m = 1.5 kg, k = 40 N/m, c = 1.2 N s/m, a 2 N sine at 0.8 Hz,
// x(0) = 0.05 m, v(0) = 0; x_rms over [2, 10] s; sensitivities to mass, stiffness, damping.
MsdParams<double> shipped(double damping = 1.2) {
  return {1.5, 40.0, damping, 2.0, 2 * std::numbers::pi * 0.8, 0.05, 0.0};
}
constexpr double kWindowFrom = 2.0, kWindowTo = 10.0;
const char* const kParams[3] = {"mass", "stiffness", "damping"};

/// x_rms = sqrt(1/T integral x^2 dt) over the window, from the closed form.
Complex rms_of(const MsdParams<Complex>& p) {
  const Complex integral = gauss_legendre<Complex>(
      [&](double t) { const Complex x = msd_position(p, t); return x * x; }, kWindowFrom, kWindowTo, 4000);
  return std::sqrt(integral / (kWindowTo - kWindowFrom));
}
double rms_value(const MsdParams<double>& p) {
  return rms_of({p.m, p.k, p.c, p.amplitude, p.omega, p.x0, p.v0}).real();
}

class CliValues : public DydpProcessTest {
 protected:
  CliValues() : DydpProcessTest("dydp_cli_values_") {}
  static std::string msd_scene() { return source_path("scenarios/msd_sensitivity.yaml").string(); }
};

// The shipped scene at its own tolerances (rtol 1e-8, atol 1e-10): every row of signals.csv
// against the closed form, each sensitivity column by its header's name, so a column written
// under another parameter's name or with its sign flipped fails.
TEST_F(CliValues, RunOfTheShippedMsdSceneMatchesTheClosedForm) {
  const fs::path out = dir_ / "run";
  const ProcessResult r = dydp("run " + quote(msd_scene()) + " --out " + quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const io::CsvFile csv = io::read_csv((out / "signals.csv").string());
  const std::vector<double>& t = column(csv, "t");
  ASSERT_EQ(t.size(), 1001u);

  std::vector<double> x_ref, v_ref;
  for (double tk : t) {
    x_ref.push_back(msd_position(shipped(), tk));
    // v = dx/dt by a central difference of the closed form (h^2 x''' / 6 ~ 1e-11 m/s).
    const double h = 1e-5;
    v_ref.push_back((msd_position(shipped(), tk + h) - msd_position(shipped(), tk - h)) / (2 * h));
  }
  EXPECT_LT(grid_error(column(csv, "body.x"), x_ref), 1e-5);
  EXPECT_LT(grid_error(column(csv, "body.v"), v_ref), 1e-5);
  for (int j = 0; j < 3; ++j) {
    std::vector<double> dx_ref;
    for (double tk : t)
      dx_ref.push_back(complex_step([tk](const MsdParams<Complex>& p) { return msd_position(p, tk); }, shipped(), j));
    EXPECT_LT(grid_error(column(csv, std::string("d(body.x)/d(") + kParams[j] + ")"), dx_ref), 1e-5)
        << "d(body.x)/d(" << kParams[j] << ")";
  }

  // objectives.json: x_rms and its gradient.
  const json o = json::parse(read_text(out / "objectives.json"))["objectives"]["x_rms"];
  const double psi = rms_value(shipped());
  EXPECT_NEAR(o["value"].get<double>(), psi, 1e-6 * psi);
  for (int j = 0; j < 3; ++j) {
    const double g = complex_step(rms_of, shipped(), j);
    EXPECT_NEAR(o["sensitivity"][kParams[j]].get<double>(), g, 1e-5 * std::fabs(g)) << kParams[j];
  }
}

// `sweep --delta 0.1`: the column change(x_rms)for_step_0.1 is d(x_rms)/dc times the step, at
// each point of the sweep, and agrees to first order with the closed form's actual change.
TEST_F(CliValues, SweepDeltaColumnIsTheDerivativeTimesTheStep) {
  const fs::path out = dir_ / "sweep";
  const double delta = 0.1;
  const ProcessResult r = dydp("sweep " + quote(msd_scene()) + " --param damping --range 0.5:2.5:3 --delta 0.1 --out " +
                               quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const io::CsvFile csv = io::read_csv((out / "sweep.csv").string());
  const std::vector<double>& c = column(csv, "damping");
  ASSERT_EQ(c.size(), 3u);
  const std::vector<double>& psi = column(csv, "x_rms");
  const std::vector<double>& dpsi = column(csv, "d(x_rms)/d(damping)");
  const std::vector<double>& change = column(csv, "change(x_rms)for_step_0.1");
  for (size_t k = 0; k < c.size(); ++k) {
    SCOPED_TRACE("damping " + std::to_string(c[k]));
    EXPECT_DOUBLE_EQ(c[k], 0.5 + 1.0 * static_cast<double>(k));
    const double psi_ref = rms_value(shipped(c[k]));
    const double dpsi_ref = complex_step(rms_of, shipped(c[k]), 2);
    EXPECT_NEAR(psi[k], psi_ref, 1e-6 * psi_ref);
    EXPECT_NEAR(dpsi[k], dpsi_ref, 1e-5 * std::fabs(dpsi_ref));
    EXPECT_NEAR(change[k], dpsi_ref * delta, 1e-5 * std::fabs(dpsi_ref * delta));
    // First order: the actual change differs from the linear estimate by O(delta^2), here
    // below a tenth of it (the second derivative term, checked by the closed form).
    const double actual = rms_value(shipped(c[k] + delta)) - psi_ref;
    EXPECT_LT(std::fabs(change[k] - actual), 0.1 * std::fabs(actual)) << change[k] << " vs " << actual;
  }
}

// `sweep --fd`: central differences of whole runs converge on the exact derivative as h^2.
// At h = 0.2 and 0.1 N s/m the truncation error psi''' h^2 / 6 dwarfs the solver's noise
// (rtol 1e-8 over h), so halving the step divides the error by 4; the exact derivative is the
// closed form's.
TEST_F(CliValues, SweepFiniteDifferencesConvergeAsTheStepSquared) {
  const fs::path out = dir_ / "sweep";
  const ProcessResult r = dydp("sweep " + quote(msd_scene()) + " --param damping --range 0.5:2.5:3 --fd 0.2,0.1 --out " +
                               quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const json j = json::parse(read_text(out / "sweep.json"));
  ASSERT_EQ(j["points"].size(), 3u);
  for (const auto& pt : j["points"]) {
    const double c = pt["p"].get<double>();
    SCOPED_TRACE("damping " + std::to_string(c));
    const json& o = pt["objectives"]["x_rms"];
    const double exact = complex_step(rms_of, shipped(c), 2);
    EXPECT_NEAR(o["sensitivity"].get<double>(), exact, 1e-5 * std::fabs(exact));
    const double coarse = std::fabs(o["fd"][0]["value"].get<double>() - exact);
    const double fine = std::fabs(o["fd"][1]["value"].get<double>() - exact);
    EXPECT_NEAR(coarse / fine, 4.0, 0.4) << "errors " << coarse << " at h = 0.2, " << fine << " at h = 0.1";
  }
}

struct AccuracyCsvRow {
  std::string method, setting;
  bool ok = false;
  double cpu = 0, signal_error = 0, objective_error = 0, sensitivity_error = 0;
};

std::vector<AccuracyCsvRow> read_accuracy_csv(const std::string& text) {
  std::vector<AccuracyCsvRow> rows;
  std::istringstream in(text);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("method,setting,ok,cpu_seconds,steps,rhs_evaluations,sensitivity_rhs_evaluations,"
                       "jacobian_evaluations,signal_error,objective_error,sensitivity_error,",
                       0),
            0u)
      << line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::vector<std::string> cells;
    std::istringstream fields(line);
    std::string cell;
    while (cells.size() < 11 && std::getline(fields, cell, ',')) cells.push_back(cell);
    if (cells.size() < 11) throw std::runtime_error("short row: " + line);
    AccuracyCsvRow row{cells[0], cells[1], cells[2] == "1", std::stod(cells[3]), std::stod(cells[8]),
                       std::stod(cells[9]), std::stod(cells[10])};
    rows.push_back(row);
  }
  return rows;
}

// `accuracy --target 1e-5` names the cheapest setting of its ladder whose signal, objective and
// sensitivity errors are all within the target: read back from accuracy.csv.
TEST_F(CliValues, AccuracyNamesTheCheapestSettingThatMeetsTheTarget) {
  const fs::path out = dir_ / "acc";
  const double target = 1e-5;
  const ProcessResult r = dydp("accuracy " + quote(msd_scene()) + " --target 1e-5 --out " + quote(out.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  const std::vector<AccuracyCsvRow> rows = read_accuracy_csv(read_text(out / "accuracy.csv"));
  ASSERT_EQ(rows.size(), 7u + 7 + 6 + 6);
  double cheapest = std::numeric_limits<double>::infinity();
  int qualifying = 0, too_coarse = 0;
  for (const auto& row : rows) {
    if (!row.ok) continue;
    const bool meets = std::max({row.signal_error, row.objective_error, row.sensitivity_error}) <= target;
    if (meets) cheapest = std::min(cheapest, row.cpu), ++qualifying;
    else ++too_coarse;
  }
  // The study is informative: some settings meet the target and some do not.
  ASSERT_GT(qualifying, 0);
  ASSERT_GT(too_coarse, 0);

  const std::string verdict = "Cheapest setting for errors below 1e-05: ";
  const size_t at = r.out.find(verdict);
  ASSERT_NE(at, std::string::npos) << r.out;
  std::istringstream named(r.out.substr(at + verdict.size()));
  std::string method, at_word, kind, setting;
  named >> method >> at_word >> kind >> setting;
  const AccuracyCsvRow* chosen = nullptr;
  for (const auto& row : rows)
    if (row.method == method && row.setting == setting) chosen = &row;
  ASSERT_NE(chosen, nullptr) << "named '" << method << " " << setting << "' is no row of accuracy.csv\n" << r.out;
  EXPECT_TRUE(chosen->ok);
  EXPECT_LE(std::max({chosen->signal_error, chosen->objective_error, chosen->sensitivity_error}), target)
      << method << " " << setting << " does not meet the target";
  EXPECT_EQ(chosen->cpu, cheapest) << method << " " << setting << " is not the cheapest qualifying row";
}

}  // namespace
}  // namespace dydp::test
