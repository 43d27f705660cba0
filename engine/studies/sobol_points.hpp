// Quasi-random points for screening studies: the Sobol' low-discrepancy sequence (Boost.Random's
// sobol engine, direction numbers of Joe and Kuo) mapped onto the parameters' ranges.
#pragma once

#include <vector>

namespace dydp::engine {

/// The first n points of the d-dimensional Sobol' sequence in (0, 1)^d (the sequence's leading
/// zero point left out, as Boost.Random does), points[k][i]. Throws std::invalid_argument for
/// d outside [1, largest dimension of the tables] or n < 1.
std::vector<std::vector<double>> sobol_points(int d, int n);

/// The largest dimension the Sobol' tables hold.
int sobol_max_dimension();

}  // namespace dydp::engine
