// Objective blocks: a block that also reduces its input over a run to one figure psi, with
// d(psi)/dp for every sensitivity direction, from its quadratures and, where needed, samples.
#pragma once

#include <string>
#include <vector>

#include "engine/framework/block.hpp"

namespace dydp::engine {

/// The objective's first input port sampled on the output grid.
struct ObjectiveSamples {
  double t_start = 0.0;  ///< the run's time span (a window left open extends to it)
  double t_stop = 0.0;
  int directions = 0;
  int width = 0;
  const std::vector<double>* t = nullptr;   ///< sample times
  const std::vector<double>* u = nullptr;   ///< u[k * width + i]
  const std::vector<double>* du = nullptr;  ///< du[(k * directions + d) * width + i]
};

class Objective {
 public:
  virtual ~Objective() = default;
  /// Unit of psi given the unit of the first input ("" when unknown).
  virtual std::string unit(const std::string& input_unit) const { return input_unit; }
  /// Whether the objective needs its input sampled on the output grid (max, final value).
  virtual bool needs_samples() const { return false; }
  /// psi from the quadratures q at the end of the run; dpsi[d] from their seeds dq(., d).
  virtual double objective(const double* p, const double* q, ConstDirView dq,
                           const ObjectiveSamples& samples, double* dpsi) const = 0;
};

}  // namespace dydp::engine
