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
  /// For the adjoint method: psi's gradient with respect to its nq quadratures at their end
  /// values q, dpsi_dq[j] = dpsi/dq_j; false when psi is not a function of its quadratures
  /// alone (it reads output samples) and so has no adjoint. The default applies objective() to
  /// unit seeds, one per quadrature: exact, since objective()'s dpsi is linear in dq (and psi
  /// depends on the parameters only through the quadratures).
  virtual bool quadrature_gradient(const double* p, const double* q, int nq, const ObjectiveSamples& samples,
                                   double* dpsi_dq) const {
    if (needs_samples()) return false;
    std::vector<double> unit(static_cast<size_t>(nq) * nq, 0.0);
    for (int j = 0; j < nq; ++j) unit[static_cast<size_t>(j) * nq + j] = 1.0;
    ObjectiveSamples s = samples;
    s.directions = nq;
    objective(p, q, {unit.data(), nq}, s, dpsi_dq);
    return true;
  }
};

}  // namespace dydp::engine
