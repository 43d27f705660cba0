// libFuzzer target: any bytes as a scene file. Loading must either give a diagram or throw
// InputError (file:line: field: message, exit 2 in dydp); any other exception, a crash, a leak
// or undefined behaviour is a finding. Seeds: scenarios/ (scripts/fuzz.sh).
#include <cstdint>

#include "engine/diagram.hpp"
#include "engine/errors.hpp"
#include "tests/fuzz/fuzz_input_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static dydp::fuzz::InputFile file(".yaml");
  const std::string& path = file.write(data, size);
  try {
    const dydp::engine::Diagram d = dydp::engine::load_scene(path);
  } catch (const dydp::engine::InputError&) {
    // refused, as bad input must be
  }
  return 0;
}
