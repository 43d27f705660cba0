// Running the built dydp program from a test: a process runner capturing stdout, stderr and
// the exit status, the entries of an output folder (refused input writes nothing), and a fixture
// with a temporary folder that runs `dydp ARGS` and reads the CSV and JSON files a run writes.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/csv.hpp"
#include "tests/temp_folder_test.hpp"

namespace dydp::test {

struct ProcessResult {
  int status = -1;
  std::string out, err;
};

inline std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// `s` quoted for the shell.
inline std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

/// Runs `exe ARGS` (ARGS already quoted), stdout and stderr captured through files in `scratch`.
inline ProcessResult run_process(const std::string& exe, const std::string& args,
                                 const std::filesystem::path& scratch) {
  const auto out = scratch / "stdout.txt", err = scratch / "stderr.txt";
  const std::string cmd = quote(exe) + " " + args + " >" + quote(out.string()) + " 2>" + quote(err.string());
  const int raw = std::system(cmd.c_str());
  ProcessResult r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = read_text(out);
  r.err = read_text(err);
  return r;
}

/// Every entry of a folder (files and folders, hidden ones included); none when it is absent.
inline std::vector<std::string> entries(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  if (!std::filesystem::exists(dir)) return names;
  for (const auto& e : std::filesystem::directory_iterator(dir)) names.push_back(e.path().filename().string());
  return names;
}

inline std::filesystem::path source_path(const std::string& relative) {
  return std::filesystem::path(DYDP_SOURCE_DIR) / relative;
}

/// The text of a scene file with its subsystem includes (`{file: PATH}`) made absolute, so that
/// an edited copy written to another folder includes the same subsystem files.
inline std::string scene_copy_text(const std::filesystem::path& scene) {
  std::string text = read_text(scene);
  const std::string key = "{file: ";
  for (size_t at = text.find(key); at != std::string::npos; at = text.find(key, at + key.size())) {
    const size_t begin = at + key.size(), end = text.find('}', begin);
    const std::filesystem::path rel = text.substr(begin, end - begin);
    if (rel.is_absolute()) continue;
    text.replace(begin, end - begin, (scene.parent_path() / rel).lexically_normal().string());
  }
  return text;
}

/// A column of a CSV file the program wrote, by name; throws when it is missing.
inline const std::vector<double>& column(const io::CsvFile& csv, const std::string& name) {
  const int c = csv.find(name);
  if (c < 0) throw std::runtime_error(csv.path + ": no column " + name);
  return csv.columns[static_cast<size_t>(c)];
}

class DydpProcessTest : public TempFolderTest {
 protected:
  explicit DydpProcessTest(std::string prefix) : TempFolderTest(std::move(prefix)) {}

  /// Runs `dydp ARGS` (ARGS already quoted).
  ProcessResult dydp(const std::string& args) const { return run_process(DYDP_EXE, args, dir_); }

  /// The text of a shipped file with `from` replaced by `to` (which must occur once).
  static std::string replaced(std::string text, const std::string& from, const std::string& to) {
    const size_t at = text.find(from);
    if (at == std::string::npos || text.find(from, at + 1) != std::string::npos)
      throw std::runtime_error("expected exactly one '" + from + "'");
    return text.replace(at, from.size(), to);
  }

  /// `text` with every `from` replaced by `to`; there must be exactly `count` of them.
  static std::string replaced_all(std::string text, const std::string& from, const std::string& to, int count) {
    int found = 0;
    for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()), ++found)
      text.replace(at, from.size(), to);
    if (found != count)
      throw std::runtime_error("expected " + std::to_string(count) + " of '" + from + "', found " + std::to_string(found));
    return text;
  }
};

}  // namespace dydp::test
