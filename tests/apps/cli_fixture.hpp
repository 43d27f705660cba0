// The fixture of the end-to-end tests of the dydp command line (cli_*_test.cpp): a temporary
// folder, `dydp ARGS` run in it (dydp_process.hpp), the shipped mass-spring-damper scene, and
// splitting the text files a run writes into lines and cells.
#pragma once

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "tests/apps/dydp_process.hpp"

namespace dydp::test {

using Result = ProcessResult;

/// `text` cut at every `sep` (a trailing separator gives no empty last item).
inline std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> out;
  std::string item;
  std::istringstream in(text);
  while (std::getline(in, item, sep)) out.push_back(item);
  return out;
}

/// The names separated by blanks, for messages.
inline std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += x + " ";
  return s;
}

/// The text of a shipped scene, to edit before writing a copy.
inline std::string scene_text(const std::filesystem::path& p) { return read_text(p); }

class Cli : public DydpProcessTest {
 protected:
  Cli() : DydpProcessTest("dydp_cli_") {}

  static std::string msd_scene() { return source_path("scenarios/msd_sensitivity.yaml").string(); }
};

}  // namespace dydp::test
