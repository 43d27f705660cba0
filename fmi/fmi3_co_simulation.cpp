// The Co-Simulation functions of the FMU (FMI 3.0, 4.2): fmi3DoStep with CVODES inside
// (cvodes_stepper.hpp); no event mode, no output derivatives; no Scheduled Execution.
#include <algorithm>
#include <cmath>
#include <string>

#include "engine/framework/errors.hpp"
#include "fmi/fmi3_checks.hpp"

using dydp::fmi::enter;
using dydp::fmi::fail;
using dydp::fmi::FmuInstance;
using dydp::fmi::guarded;
using dydp::fmi::live;
using dydp::fmi::Mode;

extern "C" {

fmi3Status fmi3EnterStepMode(fmi3Instance instance) {
  return fail(live(instance), "fmi3EnterStepMode", "this FMU has no event mode in Co-Simulation: it is in Step Mode after initialisation");
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference[], size_t nValueReferences,
                                    const fmi3Int32[], fmi3Float64[], size_t) {
  FmuInstance* i = live(instance);
  if (i && nValueReferences == 0) return fmi3OK;
  return fail(i, "fmi3GetOutputDerivatives", "not provided (maxOutputDerivativeOrder = 0)");
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint, fmi3Float64 communicationStepSize,
                      fmi3Boolean, fmi3Boolean* eventHandlingNeeded, fmi3Boolean* terminateSimulation,
                      fmi3Boolean* earlyReturn, fmi3Float64* lastSuccessfulTime) {
  FmuInstance* i = enter(instance, "fmi3DoStep", {Mode::step});
  if (!i) return fmi3Error;
  if (!i->co_simulation || !i->stepper) return fail(i, "fmi3DoStep", "a Co-Simulation function, called in Model Exchange");
  if (!eventHandlingNeeded || !terminateSimulation || !earlyReturn || !lastSuccessfulTime)
    return fail(i, "fmi3DoStep", "null arguments");
  *eventHandlingNeeded = false;
  *terminateSimulation = false;
  *earlyReturn = false;
  *lastSuccessfulTime = i->model->time();
  if (!(communicationStepSize > 0) || !std::isfinite(communicationStepSize))
    return fail(i, "fmi3DoStep", "communicationStepSize must be positive");
  const double t = i->model->time();
  if (std::fabs(currentCommunicationPoint - t) > 1e-9 * std::max(1.0, std::fabs(t)))
    return fail(i, "fmi3DoStep", "currentCommunicationPoint " + std::to_string(currentCommunicationPoint) +
                                     " is not the FMU's time " + std::to_string(t));
  return guarded(i, "fmi3DoStep", [&] {
    try {
      i->stepper->advance(currentCommunicationPoint + communicationStepSize);
    } catch (const dydp::engine::SolverError& e) {
      *lastSuccessfulTime = i->model->time();
      throw;
    }
    *lastSuccessfulTime = i->model->time();
    return fmi3OK;
  });
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference, fmi3Float64) {
  return fail(live(instance), "fmi3ActivateModelPartition", "this FMU has no Scheduled Execution interface");
}

}  // extern "C"
