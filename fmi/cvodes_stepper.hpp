// The integrator inside a Co-Simulation FMU: SUNDIALS CVODES (BDF) on the FMU's state vector,
// its Newton matrix the exact d(xdot)/dx from the blocks' tangents, the absolute tolerance
// scaled by each state's nominal magnitude (as dydp's own runs do, docs/engine.md). It stops
// at every breakpoint of the blocks (a new segment there) and restarts when the importer
// changed the inputs, the states or the parameters between two communication points. With the
// description's sensitivity directions, CVODES' forward sensitivities along them (simultaneous
// corrector, right-hand side from the blocks' tangents, tolerances and error test as dydp's own
// runs), carried over breakpoints and restarts.
#pragma once

#include <string>
#include <vector>

#include "fmi/fmu_model.hpp"

namespace dydp::fmi {

struct StepperSettings {
  double rtol = 1e-6;
  double atol = 1e-8;  ///< times each state's nominal magnitude
  int max_order = 0;   ///< 0: BDF's own limit (5)
  long max_steps = 500000;
};

class CvodesStepper {
 public:
  CvodesStepper(FmuModel& model, const StepperSettings& settings);
  ~CvodesStepper();
  CvodesStepper(const CvodesStepper&) = delete;
  CvodesStepper& operator=(const CvodesStepper&) = delete;

  /// From the model's time to t_end; the model is left at t_end. Throws engine::SolverError
  /// naming time and block.
  void advance(double t_end);
  long steps() const;

  // The CVODES callbacks' context (public for them; not for callers).
  FmuModel& model;
  std::string failure;  ///< the last callback's failure
  double failure_time = 0.0;

 private:
  void restart();
  void take_sensitivities();  ///< CVODES' sensitivities at its last step's end into the model
  StepperSettings settings_;
  void* context_ = nullptr;
  void* cvode_ = nullptr;
  void* y_ = nullptr;
  void* atol_ = nullptr;
  void* matrix_ = nullptr;
  void* solver_ = nullptr;
  void* sens_ = nullptr;      ///< the sensitivities' N_Vector array (ns_ vectors), or null
  void* sens_atol_ = nullptr;  ///< their absolute tolerances
  int ns_ = 0;

 public:
  // The sensitivity callback's buffers: the sensitivities and their derivatives, direction d
  // at [d * num_states].
  std::vector<double> s_buffer, sdot_buffer;
  long seen_changes_ = -1;
  long steps_before_ = 0;
};

}  // namespace dydp::fmi
