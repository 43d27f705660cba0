// An FMU instance as the FMI 3.0 C functions see it: the model, its interface type (Model
// Exchange or Co-Simulation), its place in the standard's state machine, the importer's logger,
// and the FMU states it handed out. Live instances are kept in a list, so that a handle that was
// freed or never made is refused with fmi3Error instead of being read (a C interface cannot
// otherwise tell a stale pointer from a live one).
#pragma once

#include <memory>
#include <mutex>
#include <set>
#include <string>

#include "fmi/cvodes_stepper.hpp"
#include "fmi/fmi3_interface.h"
#include "fmi/fmu_model.hpp"

namespace dydp::fmi {

/// The modes of the FMI 3.0 state machines (2.3, 3.2, 4.2) that this FMU has.
enum class Mode { instantiated, initialization, event, continuous_time, step, terminated };

const char* mode_name(Mode m);

struct FmuInstance {
  std::string name;
  std::string description_file;  ///< resources/fmu.yaml, read again by fmi3Reset
  bool co_simulation = false;
  Mode mode = Mode::instantiated;
  fmi3InstanceEnvironment environment = nullptr;
  fmi3LogMessageCallback logger = nullptr;
  bool logging = false;
  std::unique_ptr<FmuModel> model;
  std::unique_ptr<CvodesStepper> stepper;  ///< Co-Simulation, made when initialisation ends
  StepperSettings settings;
  std::set<const ModelSnapshot*> snapshots;  ///< FMU states handed out and not yet freed

  /// Sends a message to the importer's logger ("instance: message"): errors always, the
  /// others when logging is on.
  void log(fmi3Status status, const std::string& category, const std::string& message) const;
};

/// The list of live instances (made by the instantiate functions, removed by fmi3FreeInstance).
class InstanceList {
 public:
  void add(FmuInstance* i);
  bool remove(FmuInstance* i);
  bool contains(const void* i) const;

 private:
  mutable std::mutex mutex_;
  std::set<const void*> live_;
};

/// The FMU's one list (the C interface has no other place to keep it).
InstanceList& live_instances();

}  // namespace dydp::fmi
