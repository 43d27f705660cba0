#include "fmi/fmu_instance.hpp"

namespace dydp::fmi {

const char* mode_name(Mode m) {
  switch (m) {
    case Mode::instantiated: return "Instantiated";
    case Mode::initialization: return "Initialization Mode";
    case Mode::event: return "Event Mode";
    case Mode::continuous_time: return "Continuous-Time Mode";
    case Mode::step: return "Step Mode";
    case Mode::terminated: return "Terminated";
  }
  return "?";
}

void FmuInstance::log(fmi3Status status, const std::string& category, const std::string& message) const {
  if (!logger) return;
  if (!logging && status < fmi3Warning) return;
  const std::string text = name + ": " + message;
  logger(environment, status, category.c_str(), text.c_str());
}

void InstanceList::add(FmuInstance* i) {
  std::lock_guard<std::mutex> lock(mutex_);
  live_.insert(i);
}

bool InstanceList::remove(FmuInstance* i) {
  std::lock_guard<std::mutex> lock(mutex_);
  return live_.erase(i) > 0;
}

bool InstanceList::contains(const void* i) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return live_.count(i) > 0;
}

InstanceList& live_instances() {
  static InstanceList list;
  return list;
}

}  // namespace dydp::fmi
