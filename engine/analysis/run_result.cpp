#include "engine/analysis/run_result.hpp"

namespace dydp::engine {

std::string unit_per(const std::string& a, const std::string& b) {
  if (b.empty()) return a;
  const auto wrap = [](const std::string& u) { return u.find(' ') != std::string::npos ? "(" + u + ")" : u; };
  return (a.empty() ? "1" : wrap(a)) + " / " + wrap(b);
}

int RunResult::signal_index(const std::string& name) const {
  for (size_t i = 0; i < signal_names.size(); ++i)
    if (signal_names[i] == name) return static_cast<int>(i);
  return -1;
}

}  // namespace dydp::engine
