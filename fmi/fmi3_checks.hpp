// The checks every FMI 3.0 function of the FMU makes before it acts (fmi3_functions.cpp,
// fmi3_model_exchange.cpp, fmi3_co_simulation.cpp): the handle is a live instance, the call is
// allowed in the instance's mode, value references exist, numbers are finite; and the one way
// a failure comes back: fmi3Error (fmi3Discard for a block refusing a point in Model Exchange)
// with a message to the importer's logger.
#pragma once

#include <cmath>
#include <exception>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/framework/block.hpp"
#include "fmi/fmi3_interface.h"
#include "fmi/fmu_instance.hpp"

namespace dydp::fmi {

/// The live instance behind a handle, or null (a freed or foreign handle).
inline FmuInstance* live(fmi3Instance instance) {
  return instance && live_instances().contains(instance) ? static_cast<FmuInstance*>(instance) : nullptr;
}

inline fmi3Status fail(const FmuInstance* i, const char* function, const std::string& message) {
  if (i) i->log(fmi3Error, "logStatusError", std::string(function) + ": " + message);
  return fmi3Error;
}

/// The instance when it is live and in one of `modes`, else null (after logging why).
inline FmuInstance* enter(fmi3Instance instance, const char* function, std::initializer_list<Mode> modes) {
  FmuInstance* i = live(instance);
  if (!i) return nullptr;
  for (Mode m : modes)
    if (i->mode == m) return i;
  fail(i, function, std::string("not allowed in ") + mode_name(i->mode));
  return nullptr;
}

inline constexpr std::initializer_list<Mode> kAfterInstantiation = {Mode::initialization, Mode::event, Mode::continuous_time,
                                                             Mode::step, Mode::terminated};
inline constexpr std::initializer_list<Mode> kAnyMode = {Mode::instantiated, Mode::initialization, Mode::event,
                                                  Mode::continuous_time, Mode::step, Mode::terminated};

/// Runs f, turning an exception into a logged status: a block refusing a point (OutOfDomain,
/// its message naming the block) is fmi3Discard in Model Exchange, every other failure fmi3Error.
template <class F>
fmi3Status guarded(FmuInstance* i, const char* function, F&& f) {
  try {
    return f();
  } catch (const engine::OutOfDomain& e) {
    const fmi3Status s = i->co_simulation ? fmi3Error : fmi3Discard;
    i->log(s, s == fmi3Error ? "logStatusError" : "logStatusDiscard",
           std::string(function) + ": block " + e.reason);
    return s;
  } catch (const std::exception& e) {
    return fail(i, function, e.what());
  }
}

inline std::vector<const Variable*> variables_of(FmuInstance* i, const char* function, const fmi3ValueReference vrs[], size_t n) {
  std::vector<const Variable*> out;
  if (n > 0 && !vrs) throw std::invalid_argument("null value references");
  for (size_t k = 0; k < n; ++k) {
    const Variable* v = i->model->table().find(vrs[k]);
    if (!v) throw std::invalid_argument("unknown value reference " + std::to_string(vrs[k]));
    out.push_back(v);
  }
  return out;
}

inline bool finite_all(const double* v, size_t n) {
  for (size_t k = 0; k < n; ++k)
    if (!std::isfinite(v[k])) return false;
  return true;
}

}  // namespace dydp::fmi
