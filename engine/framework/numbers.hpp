// Numbers written as text (scene values, CSV cells, RPC III header values, GUI fields).
#pragma once

#include <string>

namespace dydp::engine {

/// Parses a whole string as a finite double; false when malformed.
bool parse_number(const std::string& text, double& value);

}  // namespace dydp::engine
