// Which states limit the step: after each accepted step, the state whose weighted local error
// estimate |e_i| w_i (w_i = 1 / (rtol |x_i| + atol_i), the terms of CVODES' error norm) is the
// largest is the one the step size was chosen for; counted over the run, the shares say why a
// run takes the steps it takes.
#pragma once

#include <string>
#include <vector>

#include "engine/analysis/run_result.hpp"
#include "engine/framework/diagram.hpp"

namespace dydp::engine {

class StepLimiters {
 public:
  explicit StepLimiters(int states) : count_(states, 0) {}

  /// One accepted step: local error estimates and error weights of the states.
  void add_step(const double* local_errors, const double* weights);

  /// The `most` states that limited the step most often, by share of the counted steps.
  std::vector<LimitingState> ranking(const Diagram& d, int most = 5) const;

 private:
  std::vector<long> count_;
  long steps_ = 0;
};

}  // namespace dydp::engine
