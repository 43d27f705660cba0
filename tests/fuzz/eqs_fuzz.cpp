// libFuzzer target: any bytes as an equation list (`*.eqs`, docs/symbolic.md), read with
// symbolic::parse_eqs, the reader dydp-gen uses. Reading must either give a list or throw
// symbolic::ParseError (`file:line: message`); any other exception, a crash, a leak or undefined
// behaviour is a finding. A list that is read is also evaluated by the interpreter at one point
// (every input and parameter 0.3): whatever the reader accepted must be a list the passes can
// walk. Seeds: tests/symbolic/data/*.eqs and the examples of docs/symbolic.md (scripts/fuzz_run.sh).
#include <cstdint>
#include <string_view>
#include <vector>

#include "symbolic/eqs_reader.hpp"
#include "symbolic/interpret.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const dydp::symbolic::EqsModel m = dydp::symbolic::parse_eqs(text, "fuzz.eqs");
    if (!m.context || !m.list) __builtin_trap();
    const dydp::symbolic::Context& c = *m.context;
    for (dydp::symbolic::ArrayId a : m.tangent_arrays)
      if (a >= c.array_count()) __builtin_trap();
    std::vector<std::vector<double>> values(c.array_count());
    std::vector<const double*> arrays;
    for (dydp::symbolic::ArrayId a = 0; a < c.array_count(); ++a) {
      values[a].assign(c.array(a).elements.size(), 0.3);
      arrays.push_back(values[a].data());
    }
    const dydp::symbolic::Tape tape(*m.list);
    std::vector<double> out(tape.output_count());
    if (out.size() != m.list->outputs().size()) __builtin_trap();
    tape.evaluate<double>(arrays, out.data());
  } catch (const dydp::symbolic::ParseError&) {
    // refused, as bad input must be
  }
  return 0;
}
