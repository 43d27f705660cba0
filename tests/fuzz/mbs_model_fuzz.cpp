// libFuzzer target: any bytes as a multibody model file (`*.mbs.yaml`), read with
// mbs::parse_model, the reader dydp-gen uses. Reading must either give a model or throw
// symbolic::ParseError (`file:line: field: message`); any other exception, a crash, a leak or
// undefined behaviour is a finding. A model that is read is walked as the generator walks it
// (joint order, parents, inputs, sensors, parameter values): every index the reader accepted
// must be inside what it refers to. Seeds: generated_models/*.mbs.yaml (scripts/fuzz_run.sh).
#include <cstdint>
#include <string>

#include "symbolic/eqs_reader.hpp"  // ParseError
#include "symbolic/mbs/model.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const dydp::mbs::Model m = dydp::mbs::parse_model(text, "fuzz.mbs.yaml");
    const int n = m.coordinates();
    if (static_cast<int>(m.order.size()) != n) __builtin_trap();  // a joint left out of the order
    for (int j : m.order)
      if (j < 0 || j >= n) __builtin_trap();
    for (int j : m.independent)
      if (j < 0 || j >= n) __builtin_trap();
    (void)m.constraint_count();
    (void)m.input_count();
    (void)m.load_input_count();
    (void)m.symbolic_parameter_count();
    if (static_cast<int>(m.input_names().size()) != m.input_count()) __builtin_trap();
    (void)m.sensor_output_names();
    for (int j : m.driven_joints())
      if (j < 0 || j >= n) __builtin_trap();
  } catch (const dydp::symbolic::ParseError&) {
    // refused, as bad input must be
  }
  return 0;
}
