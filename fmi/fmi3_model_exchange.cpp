// The Model Exchange functions of the FMU (FMI 3.0, 3.2): time, continuous states and their
// derivatives, nominals, event indicators at the blocks' breakpoints, and the event iteration
// (fmi3UpdateDiscreteStates gives the next breakpoint as the next time event).
#include <algorithm>
#include <cmath>
#include <string>

#include "fmi/fmi3_checks.hpp"

using dydp::fmi::enter;
using dydp::fmi::fail;
using dydp::fmi::FmuInstance;
using dydp::fmi::guarded;
using dydp::fmi::live;
using dydp::fmi::kAfterInstantiation;
using dydp::fmi::kAnyMode;
using dydp::fmi::Mode;
using dydp::fmi::finite_all;

extern "C" {

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance) {
  FmuInstance* i = enter(instance, "fmi3EvaluateDiscreteStates", {Mode::event, Mode::step});
  return i ? fmi3OK : fmi3Error;
}

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean* discreteStatesNeedUpdate,
                                    fmi3Boolean* terminateSimulation, fmi3Boolean* nominalsOfContinuousStatesChanged,
                                    fmi3Boolean* valuesOfContinuousStatesChanged, fmi3Boolean* nextEventTimeDefined,
                                    fmi3Float64* nextEventTime) {
  FmuInstance* i = enter(instance, "fmi3UpdateDiscreteStates", {Mode::event});
  if (!i) return fmi3Error;
  if (!discreteStatesNeedUpdate || !terminateSimulation || !nominalsOfContinuousStatesChanged ||
      !valuesOfContinuousStatesChanged || !nextEventTimeDefined || !nextEventTime)
    return fail(i, "fmi3UpdateDiscreteStates", "null arguments");
  // An event at a breakpoint begins a new segment: the blocks take their law after it.
  i->model->set_segment_start(i->model->time());
  const double next = i->model->next_breakpoint(i->model->time());
  *discreteStatesNeedUpdate = false;
  *terminateSimulation = false;
  *nominalsOfContinuousStatesChanged = false;
  *valuesOfContinuousStatesChanged = false;
  *nextEventTimeDefined = std::isfinite(next);
  *nextEventTime = std::isfinite(next) ? next : 0.0;
  i->log(fmi3OK, "logEvents", "event at t = " + std::to_string(i->model->time()));
  return fmi3OK;
}

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) {
  FmuInstance* i = enter(instance, "fmi3EnterContinuousTimeMode", {Mode::event});
  if (!i) return fmi3Error;
  if (i->co_simulation) return fail(i, "fmi3EnterContinuousTimeMode", "a Model Exchange function, called in Co-Simulation");
  i->mode = Mode::continuous_time;
  return fmi3OK;
}

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean, fmi3Boolean* enterEventMode,
                                       fmi3Boolean* terminateSimulation) {
  FmuInstance* i = enter(instance, "fmi3CompletedIntegratorStep", {Mode::continuous_time});
  if (!i) return fmi3Error;
  if (!enterEventMode || !terminateSimulation) return fail(i, "fmi3CompletedIntegratorStep", "null arguments");
  *enterEventMode = false;
  *terminateSimulation = false;
  return fmi3OK;
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time) {
  FmuInstance* i = enter(instance, "fmi3SetTime", {Mode::event, Mode::continuous_time});
  if (!i) return fmi3Error;
  if (i->co_simulation) return fail(i, "fmi3SetTime", "a Model Exchange function, called in Co-Simulation");
  if (!std::isfinite(time)) return fail(i, "fmi3SetTime", "time is not a finite number");
  i->model->set_time(time);
  return fmi3OK;
}

fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 continuousStates[], size_t nContinuousStates) {
  FmuInstance* i = enter(instance, "fmi3SetContinuousStates", {Mode::event, Mode::continuous_time});
  if (!i) return fmi3Error;
  if (i->co_simulation) return fail(i, "fmi3SetContinuousStates", "a Model Exchange function, called in Co-Simulation");
  if (nContinuousStates != static_cast<size_t>(i->model->num_states()))
    return fail(i, "fmi3SetContinuousStates", "nContinuousStates is " + std::to_string(nContinuousStates) + ", the FMU has " +
                                                  std::to_string(i->model->num_states()));
  if (nContinuousStates && !continuousStates) return fail(i, "fmi3SetContinuousStates", "null states");
  if (!finite_all(continuousStates, nContinuousStates)) return fail(i, "fmi3SetContinuousStates", "a state is not a finite number");
  i->model->set_states(continuousStates);
  return fmi3OK;
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 derivatives[], size_t nContinuousStates) {
  FmuInstance* i = enter(instance, "fmi3GetContinuousStateDerivatives",
                         {Mode::initialization, Mode::event, Mode::continuous_time, Mode::terminated});
  if (!i) return fmi3Error;
  if (nContinuousStates != static_cast<size_t>(i->model->num_states()))
    return fail(i, "fmi3GetContinuousStateDerivatives", "nContinuousStates is not the FMU's number of states");
  if (nContinuousStates && !derivatives) return fail(i, "fmi3GetContinuousStateDerivatives", "null derivatives");
  return guarded(i, "fmi3GetContinuousStateDerivatives", [&] {
    i->model->derivatives(derivatives);
    return fmi3OK;
  });
}

fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 eventIndicators[], size_t nEventIndicators) {
  FmuInstance* i = enter(instance, "fmi3GetEventIndicators",
                         {Mode::initialization, Mode::event, Mode::continuous_time, Mode::terminated});
  if (!i) return fmi3Error;
  if (nEventIndicators != i->model->table().breakpoints.size())
    return fail(i, "fmi3GetEventIndicators", "nEventIndicators is not the FMU's number of event indicators");
  if (nEventIndicators && !eventIndicators) return fail(i, "fmi3GetEventIndicators", "null event indicators");
  i->model->event_indicators(eventIndicators);
  return fmi3OK;
}

fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 continuousStates[], size_t nContinuousStates) {
  FmuInstance* i = enter(instance, "fmi3GetContinuousStates", kAfterInstantiation);
  if (!i) return fmi3Error;
  if (nContinuousStates != static_cast<size_t>(i->model->num_states()))
    return fail(i, "fmi3GetContinuousStates", "nContinuousStates is not the FMU's number of states");
  if (nContinuousStates && !continuousStates) return fail(i, "fmi3GetContinuousStates", "null states");
  std::copy(i->model->states().begin(), i->model->states().end(), continuousStates);
  return fmi3OK;
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[], size_t nContinuousStates) {
  FmuInstance* i = enter(instance, "fmi3GetNominalsOfContinuousStates", kAnyMode);
  if (!i) return fmi3Error;
  if (nContinuousStates != static_cast<size_t>(i->model->num_states()))
    return fail(i, "fmi3GetNominalsOfContinuousStates", "nContinuousStates is not the FMU's number of states");
  if (nContinuousStates && !nominals) return fail(i, "fmi3GetNominalsOfContinuousStates", "null nominals");
  std::copy(i->model->table().nominals.begin(), i->model->table().nominals.end(), nominals);
  return fmi3OK;
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t* nEventIndicators) {
  FmuInstance* i = enter(instance, "fmi3GetNumberOfEventIndicators", kAnyMode);
  if (!i) return fmi3Error;
  if (!nEventIndicators) return fail(i, "fmi3GetNumberOfEventIndicators", "null argument");
  *nEventIndicators = i->model->table().breakpoints.size();
  return fmi3OK;
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t* nContinuousStates) {
  FmuInstance* i = enter(instance, "fmi3GetNumberOfContinuousStates", kAnyMode);
  if (!i) return fmi3Error;
  if (!nContinuousStates) return fail(i, "fmi3GetNumberOfContinuousStates", "null argument");
  *nContinuousStates = static_cast<size_t>(i->model->num_states());
  return fmi3OK;
}

}  // extern "C"
