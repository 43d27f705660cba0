#include "engine/framework/numbers.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace dydp::engine {

bool parse_number(const std::string& text, double& value) {
  if (text.empty()) return false;
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  value = std::strtod(begin, &end);
  return end == begin + text.size() && errno == 0 && std::isfinite(value);
}

}  // namespace dydp::engine
