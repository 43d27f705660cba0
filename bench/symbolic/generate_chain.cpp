// Build-time generator for the benchmark: writes the chain model's dynamics and tangent as C++,
// so the benchmark can time compiled code against the interpreter on the same list.
#include <fstream>
#include <iostream>

#include "chain_model.hpp"
#include "symbolic/differentiate.hpp"
#include "symbolic/eliminate.hpp"
#include "symbolic/emit_cpp.hpp"

int main(int argc, char** argv) {
  using namespace dydp::symbolic;
  if (argc != 4) {
    std::cerr << "usage: generate_chain BODIES OUT.hpp OUT.cpp\n";
    return 2;
  }
  Context ctx;
  EquationList raw(ctx);
  const auto model = bench::build_chain(raw, std::stoul(argv[1]));
  const EquationList list = eliminate(raw);
  const ArrayId seeded[2] = {model.q, model.qd};
  const EquationList tangent = tangent_list(list, seeded);
  EmitOptions options;
  options.namespace_name = "dydp::bench_generated";
  options.origin = std::string("benchmark chain of ") + argv[1] + " bodies (bench/symbolic/chain_model.hpp)";
  options.function_name = "chain_dynamics";
  std::vector<EmittedFunction> functions{emit_function(list, options)};
  options.function_name = "chain_tangent";
  functions.push_back(emit_tangent(tangent, seeded, options));
  std::ofstream(argv[2]) << emit_header_file(functions, options);
  const std::string header = std::string(argv[2]).substr(std::string(argv[2]).find_last_of('/') + 1);
  std::ofstream(argv[3]) << emit_source_file(functions, header, options);
  return 0;
}
