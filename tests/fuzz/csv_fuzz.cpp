// libFuzzer target: any bytes as a CSV table (recorded test-bench input, source.table). Reading
// must either give the columns or throw InputError; anything else is a finding.
#include <cstdint>

#include "engine/csv.hpp"
#include "engine/errors.hpp"
#include "tests/fuzz/fuzz_input_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static dydp::fuzz::InputFile file(".csv");
  const std::string& path = file.write(data, size);
  try {
    const dydp::engine::CsvFile csv = dydp::engine::read_csv(path);
    for (const auto& column : csv.columns)
      if (column.size() != csv.columns.front().size()) __builtin_trap();  // ragged table accepted
  } catch (const dydp::engine::InputError&) {
  }
  return 0;
}
