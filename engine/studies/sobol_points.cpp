#include "engine/studies/sobol_points.hpp"

#include <boost/random/sobol.hpp>
#include <cmath>
#include <stdexcept>
#include <string>

namespace dydp::engine {

int sobol_max_dimension() {
  return static_cast<int>(boost::random::detail::qrng_tables::sobol::max_dimension);
}

std::vector<std::vector<double>> sobol_points(int d, int n) {
  if (d < 1 || d > sobol_max_dimension())
    throw std::invalid_argument("Sobol' points need 1 to " + std::to_string(sobol_max_dimension()) +
                                " dimensions, not " + std::to_string(d));
  if (n < 1) throw std::invalid_argument("Sobol' points: at least one point");
  boost::random::sobol engine(static_cast<std::size_t>(d));
  // The engine returns the point's coordinates one after the other as 64-bit fractions.
  std::vector<std::vector<double>> points(n, std::vector<double>(d));
  for (auto& point : points)
    for (double& u : point) u = std::ldexp(static_cast<double>(engine()), -64);
  return points;
}

}  // namespace dydp::engine
