// dydp-gen: generates C++ (a function and its tangent) from one model description.
// Front ends by extension: `.eqs` equation lists and `.mbs.yaml` multibody models.
// Exit status: 0 success, 2 bad input (`file:line: message` on stderr), 1 other failure.
#include <CLI/CLI.hpp>

#include <chrono>
#include <iostream>

#include "generate.hpp"
#include "generate_mbs.hpp"
#include "symbolic/eqs_reader.hpp"

namespace {

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string identifier(std::string name) {
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') c = '_';
  }
  if (name.empty() || std::isdigit(static_cast<unsigned char>(name[0]))) name = "model_" + name;
  return name;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"dydp-gen: generate C++ dynamics and tangents from a model description"};
  std::string model_path;
  std::string out_dir;
  bool stats = false;
  bool expand = false;
  app.add_option("MODEL", model_path, "model file (.eqs equation list or .mbs.yaml multibody model)")->required();
  app.add_option("--out", out_dir, "output folder for NAME.hpp, NAME.cpp (and stats.json)")->required();
  app.add_flag("--stats", stats, "also write OUT/stats.json (equations and operation counts)");
  app.add_flag("--expand", expand, "emit the in-extenso (non-recursive) form instead");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }

  const auto start = std::chrono::steady_clock::now();
  try {
    if (ends_with(model_path, ".mbs.yaml")) {
      const dydp::gen::MbsGeneration g = dydp::gen::generate_mbs(model_path, {out_dir, expand});
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (!g.independent.empty()) {
        std::cout << "independent coordinates" << (g.independent_automatic ? " (automatic):" : ":");
        for (const auto& u : g.independent) std::cout << " " << u;
        std::cout << "\n";
      }
      if (stats) dydp::gen::write_atomically(std::filesystem::path(out_dir) / "stats.json",
                                             dydp::gen::stats_json(g.functions, seconds, g.scheme_assignments, g.parts));
      return 0;
    }
    if (!ends_with(model_path, ".eqs")) {
      std::cerr << model_path << ":0: unknown model format (expected .eqs or .mbs.yaml)\n";
      return 2;
    }
    const dydp::symbolic::EqsModel model = dydp::symbolic::read_eqs(model_path);
    dydp::gen::GenerationInput input;
    input.name = identifier(model.name);
    input.origin = model_path + (expand ? " (in extenso)" : " (recursive)");
    input.list = model.list.get();
    input.tangent_arrays = model.tangent_arrays;
    const auto functions = dydp::gen::generate(input, {out_dir, expand});
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (stats) dydp::gen::write_atomically(std::filesystem::path(out_dir) / "stats.json",
                                           dydp::gen::stats_json(functions, seconds));
    return 0;
  } catch (const dydp::symbolic::ParseError& e) {
    std::cerr << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "dydp-gen: " << e.what() << "\n";
    return 1;
  }
}
