// The FMI 3.0 functions the FMU's shared object exports (fmi3_interface.h) that every
// interface type shares, over FmuModel: instantiation, initialisation, getting and setting
// values, dependencies, FMU states, partial derivatives. The Model Exchange and Co-Simulation
// calls are in fmi3_model_exchange.cpp and fmi3_co_simulation.cpp. Every call checks its
// instance, mode and arguments (fmi3_checks.hpp); no exception leaves.
#include <cmath>
#include <cstring>
#include <exception>
#include <filesystem>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/framework/block.hpp"
#include "engine/framework/errors.hpp"
#include "fmi/fmi3_interface.h"
#include "fmi/fmi3_checks.hpp"
#include "fmi/fmu_state_bytes.hpp"

using dydp::fmi::FmuInstance;
using dydp::fmi::Mode;
using dydp::fmi::ModelSnapshot;
using dydp::fmi::Role;
using dydp::fmi::Variable;
using dydp::fmi::enter;
using dydp::fmi::fail;
using dydp::fmi::finite_all;
using dydp::fmi::guarded;
using dydp::fmi::kAfterInstantiation;
using dydp::fmi::kAnyMode;
using dydp::fmi::live;
using dydp::fmi::variables_of;

namespace {

fmi3Instance instantiate(fmi3String name, fmi3String token, fmi3String resources, bool co_simulation,
                         fmi3Boolean logging, fmi3InstanceEnvironment environment, fmi3LogMessageCallback logger) {
  auto i = std::make_unique<FmuInstance>();
  i->name = name ? name : "";
  i->co_simulation = co_simulation;
  i->environment = environment;
  i->logger = logger;
  i->logging = logging;
  const char* function = co_simulation ? "fmi3InstantiateCoSimulation" : "fmi3InstantiateModelExchange";
  try {
    if (!resources || !*resources) throw std::invalid_argument("no resource path");
    const std::filesystem::path description = std::filesystem::path(resources) / "fmu.yaml";
    i->description_file = description.string();
    i->model = std::make_unique<dydp::fmi::FmuModel>(i->description_file);
    if (!token || i->model->table().token != token)
      throw std::invalid_argument(std::string("instantiation token ") + (token ? token : "(null)") +
                                  " is not this FMU's " + i->model->table().token);
    if (!co_simulation && i->model->num_sensitivities() > 0)
      throw std::invalid_argument("this FMU's sensitivity outputs exist in Co-Simulation only (its integrator gives them)");
    const auto& solver = i->model->diagram().solver;
    i->settings.rtol = solver.rtol;
    i->settings.atol = solver.atol;
    i->settings.max_order = solver.max_order;
    i->settings.max_steps = solver.max_steps;
  } catch (const std::exception& e) {
    fail(i.get(), function, e.what());
    return nullptr;
  }
  dydp::fmi::live_instances().add(i.get());
  return i.release();
}

/// The time span and start state set at the start of initialisation.
void start_model(FmuInstance* i, double t0, bool stop_defined, double stop) {
  if (!std::isfinite(t0)) throw std::invalid_argument("start time is not finite");
  const double t_stop = stop_defined ? stop : std::max(i->model->diagram().time.stop, t0);
  if (stop_defined && !(stop >= t0)) throw std::invalid_argument("stop time before the start time");
  i->model->start(t0, t_stop);
}


template <class T>
fmi3Status no_variables_of_type(fmi3Instance instance, const char* function, size_t n) {
  FmuInstance* i = live(instance);
  if (!i) return fmi3Error;
  if (n == 0) return fmi3OK;
  return fail(i, function, "this FMU has no variables of this type (its variables are Float64)");
}

}  // namespace

extern "C" {

const char* fmi3GetVersion(void) { return "3.0"; }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t, const fmi3String[]) {
  FmuInstance* i = live(instance);
  if (!i) return fmi3Error;
  i->logging = loggingOn;
  return fmi3OK;
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage) {
  return instantiate(instanceName, instantiationToken, resourcePath, false, loggingOn, instanceEnvironment, logMessage);
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean, const fmi3ValueReference[], size_t,
                                         fmi3InstanceEnvironment instanceEnvironment,
                                         fmi3LogMessageCallback logMessage, fmi3IntermediateUpdateCallback) {
  if (eventModeUsed) {
    if (logMessage)
      logMessage(instanceEnvironment, fmi3Error, "logStatusError",
                 "fmi3InstantiateCoSimulation: this FMU has no event mode in Co-Simulation (hasEventMode=false)");
    return nullptr;
  }
  return instantiate(instanceName, instantiationToken, resourcePath, true, loggingOn, instanceEnvironment, logMessage);
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String, fmi3String, fmi3String, fmi3Boolean, fmi3Boolean,
                                               fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback,
                                               fmi3LockPreemptionCallback, fmi3UnlockPreemptionCallback) {
  if (logMessage)
    logMessage(instanceEnvironment, fmi3Error, "logStatusError",
               "fmi3InstantiateScheduledExecution: this FMU has no Scheduled Execution interface");
  return nullptr;
}

void fmi3FreeInstance(fmi3Instance instance) {
  FmuInstance* i = live(instance);
  if (!i || !dydp::fmi::live_instances().remove(i)) return;  // freed before, or never ours
  for (const ModelSnapshot* s : i->snapshots) delete s;
  delete i;
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime) {
  FmuInstance* i = enter(instance, "fmi3EnterInitializationMode", {Mode::instantiated});
  if (!i) return fmi3Error;
  return guarded(i, "fmi3EnterInitializationMode", [&] {
    if (toleranceDefined) {
      if (!(tolerance > 0) || !std::isfinite(tolerance)) throw std::invalid_argument("tolerance must be positive");
      i->settings.rtol = tolerance;
    }
    start_model(i, startTime, stopTimeDefined, stopTime);
    i->mode = Mode::initialization;
    return fmi3OK;
  });
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance) {
  FmuInstance* i = enter(instance, "fmi3ExitInitializationMode", {Mode::initialization});
  if (!i) return fmi3Error;
  return guarded(i, "fmi3ExitInitializationMode", [&] {
    // The start state with the parameters as the importer left them.
    i->model->start(i->model->time(), i->model->stop_time());
    if (i->co_simulation) {
      i->stepper = std::make_unique<dydp::fmi::CvodesStepper>(*i->model, i->settings);
      i->mode = Mode::step;
    } else {
      i->mode = Mode::event;
    }
    return fmi3OK;
  });
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance) {
  FmuInstance* i = enter(instance, "fmi3EnterEventMode", {Mode::continuous_time});
  if (!i) return fmi3Error;
  i->mode = Mode::event;
  return fmi3OK;
}

fmi3Status fmi3Terminate(fmi3Instance instance) {
  FmuInstance* i = enter(instance, "fmi3Terminate", {Mode::event, Mode::continuous_time, Mode::step});
  if (!i) return fmi3Error;
  i->mode = Mode::terminated;
  return fmi3OK;
}

fmi3Status fmi3Reset(fmi3Instance instance) {
  FmuInstance* i = live(instance);
  if (!i) return fmi3Error;
  return guarded(i, "fmi3Reset", [&] {
    i->stepper.reset();
    auto fresh = std::make_unique<dydp::fmi::FmuModel>(i->description_file);
    i->model = std::move(fresh);
    i->mode = Mode::instantiated;
    return fmi3OK;
  });
}

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          fmi3Float64 values[], size_t nValues) {
  FmuInstance* i = enter(instance, "fmi3GetFloat64", kAfterInstantiation);
  if (!i) return fmi3Error;
  return guarded(i, "fmi3GetFloat64", [&] {
    if (nValues != nValueReferences) throw std::invalid_argument("nValues differs from nValueReferences (every variable is a scalar)");
    const auto vars = variables_of(i, "fmi3GetFloat64", valueReferences, nValueReferences);
    if (nValues > 0 && !values) throw std::invalid_argument("null values");
    for (size_t k = 0; k < vars.size(); ++k) values[k] = i->model->value(*vars[k]);
    return fmi3OK;
  });
}

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          const fmi3Float64 values[], size_t nValues) {
  FmuInstance* i = enter(instance, "fmi3SetFloat64",
                         {Mode::instantiated, Mode::initialization, Mode::event, Mode::continuous_time, Mode::step});
  if (!i) return fmi3Error;
  return guarded(i, "fmi3SetFloat64", [&] {
    if (nValues != nValueReferences) throw std::invalid_argument("nValues differs from nValueReferences (every variable is a scalar)");
    const auto vars = variables_of(i, "fmi3SetFloat64", valueReferences, nValueReferences);
    if (nValues > 0 && !values) throw std::invalid_argument("null values");
    for (size_t k = 0; k < vars.size(); ++k) {
      const Variable& v = *vars[k];
      if (v.role != Role::input && v.role != Role::parameter)
        throw std::invalid_argument(v.name + " cannot be set (only inputs and parameters can)");
      if (v.role == Role::input && i->mode == Mode::continuous_time && i->co_simulation)
        throw std::invalid_argument(v.name + ": not in this mode");
      if (v.role == Role::parameter && i->mode == Mode::continuous_time)
        throw std::invalid_argument(v.name + " is a tunable parameter: set it in Event Mode");
      if (!std::isfinite(values[k]))
        throw std::invalid_argument(v.name + " = " + std::to_string(values[k]) + ": not a finite number");
    }
    for (size_t k = 0; k < vars.size(); ++k) {
      try {
        i->model->set_value(*vars[k], values[k]);
      } catch (const dydp::engine::InputError& e) {
        throw std::invalid_argument(vars[k]->name + ": " + e.what());
      }
    }
    return fmi3OK;
  });
}

#define DYDP_NO_VARIABLES(NAME, TYPE)                                                                            \
  fmi3Status fmi3Get##NAME(fmi3Instance instance, const fmi3ValueReference[], size_t nValueReferences, TYPE[],  \
                           size_t) {                                                                             \
    return no_variables_of_type<TYPE>(instance, "fmi3Get" #NAME, nValueReferences);                            \
  }                                                                                                              \
  fmi3Status fmi3Set##NAME(fmi3Instance instance, const fmi3ValueReference[], size_t nValueReferences,          \
                           const TYPE[], size_t) {                                                               \
    return no_variables_of_type<TYPE>(instance, "fmi3Set" #NAME, nValueReferences);                            \
  }
DYDP_NO_VARIABLES(Float32, fmi3Float32)
DYDP_NO_VARIABLES(Int8, fmi3Int8)
DYDP_NO_VARIABLES(UInt8, fmi3UInt8)
DYDP_NO_VARIABLES(Int16, fmi3Int16)
DYDP_NO_VARIABLES(UInt16, fmi3UInt16)
DYDP_NO_VARIABLES(Int32, fmi3Int32)
DYDP_NO_VARIABLES(UInt32, fmi3UInt32)
DYDP_NO_VARIABLES(Int64, fmi3Int64)
DYDP_NO_VARIABLES(UInt64, fmi3UInt64)
DYDP_NO_VARIABLES(Boolean, fmi3Boolean)
DYDP_NO_VARIABLES(String, fmi3String)
#undef DYDP_NO_VARIABLES

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference[], size_t nValueReferences, size_t[],
                         fmi3Binary[], size_t) {
  return no_variables_of_type<fmi3Binary>(instance, "fmi3GetBinary", nValueReferences);
}
fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference[], size_t nValueReferences, const size_t[],
                         const fmi3Binary[], size_t) {
  return no_variables_of_type<fmi3Binary>(instance, "fmi3SetBinary", nValueReferences);
}
fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference[], size_t nValueReferences, fmi3Clock[]) {
  return no_variables_of_type<fmi3Clock>(instance, "fmi3GetClock", nValueReferences);
}
fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference[], size_t nValueReferences, const fmi3Clock[]) {
  return no_variables_of_type<fmi3Clock>(instance, "fmi3SetClock", nValueReferences);
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference valueReference,
                                               size_t* nDependencies) {
  FmuInstance* i = enter(instance, "fmi3GetNumberOfVariableDependencies", kAnyMode);
  if (!i) return fmi3Error;
  const Variable* v = i->model->table().find(valueReference);
  if (!v) return fail(i, "fmi3GetNumberOfVariableDependencies", "unknown value reference " + std::to_string(valueReference));
  if (!nDependencies) return fail(i, "fmi3GetNumberOfVariableDependencies", "null nDependencies");
  *nDependencies = v->dependencies.size();
  return fmi3OK;
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies) {
  FmuInstance* i = enter(instance, "fmi3GetVariableDependencies", kAnyMode);
  if (!i) return fmi3Error;
  const Variable* v = i->model->table().find(dependent);
  if (!v) return fail(i, "fmi3GetVariableDependencies", "unknown value reference " + std::to_string(dependent));
  if (nDependencies != v->dependencies.size())
    return fail(i, "fmi3GetVariableDependencies", "nDependencies is not the number of dependencies");
  if (nDependencies > 0 && (!elementIndicesOfDependent || !independents || !elementIndicesOfIndependents || !dependencyKinds))
    return fail(i, "fmi3GetVariableDependencies", "null arrays");
  for (size_t k = 0; k < nDependencies; ++k) {
    elementIndicesOfDependent[k] = 0;
    independents[k] = v->dependencies[k];
    elementIndicesOfIndependents[k] = 0;
    dependencyKinds[k] = fmi3Dependent;
  }
  return fmi3OK;
}

fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState* FMUState) {
  FmuInstance* i = enter(instance, "fmi3GetFMUState", kAnyMode);
  if (!i) return fmi3Error;
  if (!FMUState) return fail(i, "fmi3GetFMUState", "null FMUState");
  return guarded(i, "fmi3GetFMUState", [&] {
    ModelSnapshot* kept = static_cast<ModelSnapshot*>(*FMUState);
    if (kept && i->snapshots.count(kept)) {  // overwrite a state handed out before (2.2.11)
      *kept = i->model->snapshot();
      return fmi3OK;
    }
    auto s = std::make_unique<ModelSnapshot>(i->model->snapshot());
    i->snapshots.insert(s.get());
    *FMUState = s.release();
    return fmi3OK;
  });
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState) {
  FmuInstance* i = enter(instance, "fmi3SetFMUState", kAnyMode);
  if (!i) return fmi3Error;
  const auto* s = static_cast<const ModelSnapshot*>(FMUState);
  if (!s || !i->snapshots.count(s)) return fail(i, "fmi3SetFMUState", "not an FMU state of this instance (freed, or never made)");
  return guarded(i, "fmi3SetFMUState", [&] {
    i->model->restore(*s);
    return fmi3OK;
  });
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState* FMUState) {
  FmuInstance* i = enter(instance, "fmi3FreeFMUState", kAnyMode);
  if (!i) return fmi3Error;
  if (!FMUState || !*FMUState) return fmi3OK;  // nothing to free (2.2.11)
  auto* s = static_cast<ModelSnapshot*>(*FMUState);
  if (!i->snapshots.erase(s)) return fail(i, "fmi3FreeFMUState", "not an FMU state of this instance (freed before?)");
  delete s;
  *FMUState = nullptr;
  return fmi3OK;
}

namespace {

const ModelSnapshot* snapshot_of(FmuInstance* i, fmi3FMUState state) {
  const auto* s = static_cast<const ModelSnapshot*>(state);
  if (!s || !i->snapshots.count(s)) throw std::invalid_argument("not an FMU state of this instance (freed, or never made)");
  return s;
}

}  // namespace

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState FMUState, size_t* size) {
  FmuInstance* i = enter(instance, "fmi3SerializedFMUStateSize", kAnyMode);
  if (!i) return fmi3Error;
  return guarded(i, "fmi3SerializedFMUStateSize", [&] {
    if (!size) throw std::invalid_argument("null size");
    *size = dydp::fmi::serialise(i->model->table().token, *snapshot_of(i, FMUState)).size();
    return fmi3OK;
  });
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState, fmi3Byte serializedState[], size_t size) {
  FmuInstance* i = enter(instance, "fmi3SerializeFMUState", kAnyMode);
  if (!i) return fmi3Error;
  return guarded(i, "fmi3SerializeFMUState", [&] {
    const std::vector<fmi3Byte> bytes = dydp::fmi::serialise(i->model->table().token, *snapshot_of(i, FMUState));
    if (!serializedState || size != bytes.size())
      throw std::invalid_argument("size is not fmi3SerializedFMUStateSize's " + std::to_string(bytes.size()));
    std::memcpy(serializedState, bytes.data(), bytes.size());
    return fmi3OK;
  });
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[], size_t size,
                                   fmi3FMUState* FMUState) {
  FmuInstance* i = enter(instance, "fmi3DeserializeFMUState", kAnyMode);
  if (!i) return fmi3Error;
  return guarded(i, "fmi3DeserializeFMUState", [&] {
    if (!serializedState || !FMUState) throw std::invalid_argument("null arguments");
    auto s = std::make_unique<ModelSnapshot>(dydp::fmi::deserialise(i->model->table().token, i->model->snapshot(), serializedState, size));
    ModelSnapshot* kept = static_cast<ModelSnapshot*>(*FMUState);
    if (kept && i->snapshots.count(kept)) {
      *kept = *s;
      return fmi3OK;
    }
    i->snapshots.insert(s.get());
    *FMUState = s.release();
    return fmi3OK;
  });
}

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                        const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                        size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
  FmuInstance* i = enter(instance, "fmi3GetDirectionalDerivative", kAfterInstantiation);
  if (!i) return fmi3Error;
  return guarded(i, "fmi3GetDirectionalDerivative", [&] {
    if (nSeed != nKnowns || nSensitivity != nUnknowns)
      throw std::invalid_argument("nSeed must be nKnowns and nSensitivity nUnknowns (every variable is a scalar)");
    const auto u = variables_of(i, "fmi3GetDirectionalDerivative", unknowns, nUnknowns);
    const auto k = variables_of(i, "fmi3GetDirectionalDerivative", knowns, nKnowns);
    if ((nSeed && !seed) || (nSensitivity && !sensitivity)) throw std::invalid_argument("null seed or sensitivity");
    if (!finite_all(seed, nSeed)) throw std::invalid_argument("a seed is not a finite number");
    i->model->directional_derivative(u, k, seed, sensitivity);
    return fmi3OK;
  });
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                    size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity) {
  FmuInstance* i = enter(instance, "fmi3GetAdjointDerivative", kAfterInstantiation);
  if (!i) return fmi3Error;
  return guarded(i, "fmi3GetAdjointDerivative", [&] {
    if (nSeed != nUnknowns || nSensitivity != nKnowns)
      throw std::invalid_argument("nSeed must be nUnknowns and nSensitivity nKnowns (every variable is a scalar)");
    const auto u = variables_of(i, "fmi3GetAdjointDerivative", unknowns, nUnknowns);
    const auto k = variables_of(i, "fmi3GetAdjointDerivative", knowns, nKnowns);
    if ((nSeed && !seed) || (nSensitivity && !sensitivity)) throw std::invalid_argument("null seed or sensitivity");
    if (!finite_all(seed, nSeed)) throw std::invalid_argument("a seed is not a finite number");
    i->model->adjoint_derivative(u, k, seed, sensitivity);
    return fmi3OK;
  });
}

fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance) {
  return fail(live(instance), "fmi3EnterConfigurationMode", "this FMU has no structural parameters");
}
fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance) {
  return fail(live(instance), "fmi3ExitConfigurationMode", "this FMU has no structural parameters");
}

#define DYDP_NO_CLOCKS(NAME, ...)                                                                          \
  fmi3Status NAME(fmi3Instance instance, const fmi3ValueReference[], size_t nValueReferences, __VA_ARGS__) { \
    if (nValueReferences == 0 && live(instance)) return fmi3OK;                                             \
    return fail(live(instance), #NAME, "this FMU has no clocks");                                           \
  }
DYDP_NO_CLOCKS(fmi3GetIntervalDecimal, fmi3Float64[], fmi3IntervalQualifier[])
DYDP_NO_CLOCKS(fmi3GetIntervalFraction, fmi3UInt64[], fmi3UInt64[], fmi3IntervalQualifier[])
DYDP_NO_CLOCKS(fmi3GetShiftDecimal, fmi3Float64[])
DYDP_NO_CLOCKS(fmi3GetShiftFraction, fmi3UInt64[], fmi3UInt64[])
DYDP_NO_CLOCKS(fmi3SetIntervalDecimal, const fmi3Float64[])
DYDP_NO_CLOCKS(fmi3SetIntervalFraction, const fmi3UInt64[], const fmi3UInt64[])
DYDP_NO_CLOCKS(fmi3SetShiftDecimal, const fmi3Float64[])
DYDP_NO_CLOCKS(fmi3SetShiftFraction, const fmi3UInt64[], const fmi3UInt64[])
#undef DYDP_NO_CLOCKS
}  // extern "C"
