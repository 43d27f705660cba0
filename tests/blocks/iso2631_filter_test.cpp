// filter.iso2631: the state-space filter's gain |C (jw - A)^-1 B + D|, with A, B, C, D read from
// the block's own tangents, against the product of the standard's four transfer functions and
// against the standard's tabulated weighting factors; a simulated sine through the engine.
#include <gtest/gtest.h>

#include <complex>
#include <numbers>

#include "tests/blocks/scene_helpers.hpp"
#include "tests/blocks/tangent_check.hpp"

namespace dydp::test {
namespace {

using cd = std::complex<double>;

/// |H(j 2 pi f)| from the block's linearisation.
double state_space_gain(const engine::Block& b, double f) {
  const int n = b.num_states();
  // Columns of A and B from derivative tangents, of C and D from output tangents.
  std::vector<double> x(n, 0.0), seeds_x(n * (n + 1), 0.0), seeds_u(n + 1, 0.0);
  for (int i = 0; i < n; ++i) seeds_x[i * n + i] = 1.0;
  seeds_u[n] = 1.0;
  const double a = 0.0;
  const double* u[1] = {&a};
  engine::Eval e;
  e.x = x.data();
  e.u = u;
  engine::ConstDirView du{seeds_u.data(), 1};
  engine::Seeds s;
  s.directions = n + 1;
  s.x = {seeds_x.data(), n};
  s.u = &du;
  std::vector<double> dxdot(n * (n + 1)), dy(n + 1);
  b.derivatives_tangent(e, s, {dxdot.data(), n});
  engine::DirView dyv{dy.data(), 1};
  b.outputs_tangent(e, s, &dyv);
  // Solve (j w I - A) z = B, gain = C z + D.
  const double w = 2 * std::numbers::pi * f;
  std::vector<std::vector<cd>> m(n, std::vector<cd>(n + 1));
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) m[i][j] = (i == j ? cd(0, w) : cd(0)) - dxdot[j * n + i];
    m[i][n] = dxdot[n * n + i];
  }
  for (int c = 0; c < n; ++c) {
    int piv = c;
    for (int i = c + 1; i < n; ++i) if (std::abs(m[i][c]) > std::abs(m[piv][c])) piv = i;
    std::swap(m[c], m[piv]);
    for (int i = c + 1; i < n; ++i) {
      const cd factor = m[i][c] / m[c][c];
      for (int k = c; k <= n; ++k) m[i][k] -= factor * m[c][k];
    }
  }
  std::vector<cd> z(n);
  for (int i = n - 1; i >= 0; --i) {
    cd acc = m[i][n];
    for (int k = i + 1; k < n; ++k) acc -= m[i][k] * z[k];
    z[i] = acc / m[i][i];
  }
  cd h = dy[n];
  for (int i = 0; i < n; ++i) h += dy[i] * z[i];
  return std::abs(h);
}

/// |Hh Hl Ht Hs| at f, from ISO 2631-1 Annex A. Hs is normalised to unit gain at high frequency,
/// (s^2 + w5 s / Q5 + w5^2) / (s^2 + w6 s / Q6 + w6^2); with the extra factor w6^2 / w5^2 (unit gain
/// at DC) every weighting factor would be twice the standard's tables.
double standard_gain(bool wk, double f) {
  const double tau = 2 * std::numbers::pi;
  const cd s(0, tau * f);
  const double w1 = tau * 0.4, w2 = tau * 100, q = 1 / std::sqrt(2.0);
  const double w3 = tau * (wk ? 12.5 : 2.0), w4 = w3, q4 = 0.63;
  cd h = s * s / (s * s + w1 * s / q + w1 * w1);
  h *= w2 * w2 / (s * s + w2 * s / q + w2 * w2);
  h *= (1.0 + s / w3) / (1.0 + s / (q4 * w4) + s * s / (w4 * w4));
  if (wk) {
    const double w5 = tau * 2.37, q5 = 0.91, w6 = tau * 3.35, q6 = 0.91;
    h *= (s * s + w5 * s / q5 + w5 * w5) / (s * s + w6 * s / q6 + w6 * w6);
  }
  return std::abs(h);
}

BlockCase filter_case(const char* w) {
  BlockCase c;
  c.type = "filter.iso2631";
  c.settings = {{"weighting", {w}}};
  return c;
}

TEST(Iso2631Filter, TangentsMatchFiniteDifferences) {
  check_tangents(filter_case("Wk"));
  check_tangents(filter_case("Wd"));
}

TEST(Iso2631Filter, StateSpaceGainIsTheProductOfTheFourTransferFunctions) {
  for (const char* w : {"Wk", "Wd"}) {
    const auto b = make_block(filter_case(w));
    for (double f = 0.1; f < 400; f *= 1.25)
      EXPECT_NEAR(state_space_gain(*b, f), standard_gain(w[1] == 'k', f), 1e-9 * standard_gain(w[1] == 'k', f))
          << w << " at " << f << " Hz";
  }
}

TEST(Iso2631Filter, GainMatchesTheStandardsTable) {
  // Weighting factors (x 1000) of ISO 2631-1:1997, Table 3 (Wk) and Table 4 (Wd).
  const std::vector<std::pair<double, double>> wk = {
      {0.5, 418}, {1.0, 482}, {2.0, 531}, {4.0, 967}, {5.0, 1039}, {6.3, 1054}, {8.0, 1036}, {16.0, 768}, {31.5, 405}};
  const std::vector<std::pair<double, double>> wd = {{0.5, 853}, {1.0, 1011}, {2.0, 890}, {4.0, 512}, {8.0, 253}};
  const auto b_wk = make_block(filter_case("Wk"));
  const auto b_wd = make_block(filter_case("Wd"));
  for (const auto& [f, g] : wk) EXPECT_NEAR(state_space_gain(*b_wk, f), g / 1000, 0.02 * g / 1000) << "Wk " << f;
  for (const auto& [f, g] : wd) EXPECT_NEAR(state_space_gain(*b_wd, f), g / 1000, 0.02 * g / 1000) << "Wd " << f;
}

TEST(Iso2631Filter, WeightedRmsOfASineThroughTheEngine) {
  const std::string scene = R"(scene: wk_sine
time: {start: 0.0, stop: 12.0, output_step: 0.01}
solver: {method: bdf, rtol: 1.0e-9, atol: 1.0e-10}
blocks:
  a: {type: source.sine, amplitude: 1.0, frequency: 1.0}
  wk: {type: filter.iso2631, weighting: Wk}
  a_w: {type: objective.rms, window: [8.0, 12.0]}
connections:
  - a.y -> wk.a
  - wk.a_weighted -> a_w.in
outputs: [a_w]
)";
  const auto r = run_scene(write_scene("wk_sine.yaml", scene), {}, false);
  const double expected = standard_gain(true, 1.0) / std::sqrt(2.0);
  EXPECT_NEAR(objective(r, "a_w").value, expected, 1e-3 * expected);
}

}  // namespace
}  // namespace dydp::test
