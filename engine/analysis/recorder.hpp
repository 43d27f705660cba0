// Logging on the output grid: the requested signals and their sensitivities, samples for the
// objectives that need them, and, at the end, each objective's psi and d(psi)/dp.
#pragma once

#include <vector>

#include "engine/analysis/run_result.hpp"
#include "engine/evaluation/evaluator.hpp"

namespace dydp::engine {

class Recorder {
 public:
  Recorder(const Diagram& d, int directions, RunResult& result, const RunOptions& options);

  /// Records time t; the evaluator holds the value pass and, with directions, the tangent pass
  /// at (t, x, dx/dp). Throws SolverError when a state or output is not finite. Then calls the
  /// options' on_sample and progress callbacks.
  void record(double t, const double* x, Evaluator& ev);

  /// Objectives from the quadratures q and their sensitivities dq (ld = num_quadratures).
  void finish(const double* q, ConstDirView dq);

 private:
  const Diagram& d_;
  int ns_;
  RunResult& result_;
  const RunOptions& options_;
  struct Sampled {
    std::vector<double> t, u, du;
  };
  std::vector<Sampled> samples_;  ///< per objective
};

}  // namespace dydp::engine
