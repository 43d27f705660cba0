// The recorded-signal interpolation of the replay's pads (blocks/time_series): a cubic spline
// through the samples, checked against what a spline must be. A cubic polynomial sampled on an
// uneven grid is reproduced exactly, with its rate (the not-a-knot ends included); the samples
// are met; and on random data the second derivative is continuous at every sample, which the
// central-difference Hermite cubic it replaced was not.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "blocks/time_series.hpp"

namespace dydp::blocks {
namespace {

std::vector<double> uneven_grid(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> step(0.5e-3, 3e-3);
  std::vector<double> t{0.0};
  for (int k = 1; k < n; ++k) t.push_back(t.back() + step(rng));
  return t;
}

TEST(TimeSeries, CubicPolynomialReproducedExactlyWithItsRate) {
  std::mt19937 rng(7);
  const std::vector<double> t = uneven_grid(40, rng);
  const auto f = [](double x) { return 0.3 - 2.0 * x + 40.0 * x * x - 900.0 * x * x * x; };
  const auto fdot = [](double x) { return -2.0 + 80.0 * x - 2700.0 * x * x; };
  std::vector<double> y;
  for (double x : t) y.push_back(f(x));
  const TimeSeries series(t, y);
  double worst_y = 0, worst_ydot = 0;
  for (size_t k = 0; k + 1 < t.size(); ++k)
    for (double s : {0.0, 0.1, 0.37, 0.5, 0.81}) {
      if (k == 0 && s == 0.0) continue;  // the first sample: the series is held before it, rate 0
      const double x = t[k] + s * (t[k + 1] - t[k]);
      double v, vdot;
      series.cubic(x, v, vdot);
      worst_y = std::max(worst_y, std::fabs(v - f(x)));
      worst_ydot = std::max(worst_ydot, std::fabs(vdot - fdot(x)));
    }
  EXPECT_LT(worst_y, 1e-13);
  EXPECT_LT(worst_ydot, 1e-10);
}

TEST(TimeSeries, RandomSamplesMetWithAContinuousSecondDerivative) {
  std::mt19937 rng(11);
  const std::vector<double> t = uneven_grid(60, rng);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<double> y;
  for (size_t k = 0; k < t.size(); ++k) y.push_back(noise(rng));
  const TimeSeries series(t, y);
  const double delta = 1e-8;
  double largest = 0, jump = 0;
  for (size_t k = 1; k + 1 < t.size(); ++k) {
    double v, before, after, at;
    series.cubic(t[k], v, at);
    EXPECT_NEAR(v, y[k], 1e-12) << "sample " << k;
    series.cubic(t[k] - delta, v, before);
    series.cubic(t[k] + delta, v, after);
    const double left = (at - before) / delta, right = (after - at) / delta;
    largest = std::max({largest, std::fabs(left), std::fabs(right)});
    jump = std::max(jump, std::fabs(left - right));
  }
  ASSERT_GT(largest, 1e3);  // the data are rough: curvatures of the order of 1 / h^2
  EXPECT_LT(jump, 1e-4 * largest);
}

}  // namespace
}  // namespace dydp::blocks
