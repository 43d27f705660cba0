// Writing a file so that no reader ever sees half of it: every output file of dydp goes
// through here.
#pragma once

#include <string>

namespace dydp::io {

/// Writes `text` to path atomically (temporary file in the same folder, then rename).
void write_file_atomically(const std::string& path, const std::string& text);

}  // namespace dydp::io
