// libFuzzer target: any bytes as a CSV table (recorded test-bench input, source.table). Reading
// must either give the columns or throw InputError; anything else is a finding.
#include <cstdint>

#include "engine/framework/errors.hpp"
#include "io/csv.hpp"
#include "tests/fuzz/fuzz_input_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static dydp::fuzz::InputFile file(".csv");
  const std::string& path = file.write(data, size);
  try {
    const dydp::io::CsvFile csv = dydp::io::read_csv(path);
    for (const auto& column : csv.columns)
      if (column.size() != csv.columns.front().size()) __builtin_trap();  // ragged table accepted
  } catch (const dydp::engine::InputError&) {
  }
  return 0;
}
