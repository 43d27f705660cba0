// libFuzzer target: any bytes as an RPC III time-history file (replay input). Reading must
// either give channels of FRAMES x PTS_PER_FRAME finite samples or throw InputError; anything
// else (a read past the data, an allocation the file's size does not justify) is a finding.
#include <cmath>
#include <cstdint>

#include "engine/framework/errors.hpp"
#include "io/rpc3.hpp"
#include "tests/fuzz/fuzz_input_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static dydp::fuzz::InputFile file(".rsp");
  const std::string& path = file.write(data, size);
  try {
    const dydp::io::Rpc3File f = dydp::io::read_rpc3(path);
    const size_t points = static_cast<size_t>(f.frames) * f.points_per_frame;
    if (f.channels.empty() || points * 2 > size) __builtin_trap();  // more samples than bytes
    for (const auto& c : f.channels) {
      if (c.values.size() != points) __builtin_trap();
      for (double v : c.values)
        if (!std::isfinite(v)) __builtin_trap();
    }
  } catch (const dydp::engine::InputError&) {
  }
  return 0;
}
