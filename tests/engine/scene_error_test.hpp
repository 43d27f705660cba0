// A fixture for scenes that must be refused: a fresh folder to write scene files into, the
// InputError loading one raises, and the check that it names file, line and field
// ("file:line: field: message") with a key phrase of the message.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"
#include "tests/temp_folder_test.hpp"

namespace dydp::test {

class SceneErrorTest : public TempFolderTest {
 protected:
  using Overrides = std::vector<std::pair<std::string, std::string>>;
  using TempFolderTest::TempFolderTest;

  /// Writes `text` to dir/relative (folders created) and returns its path.
  std::string put(const std::string& relative, const std::string& text) const {
    std::filesystem::create_directories((dir_ / relative).parent_path());
    return write(relative, text);
  }

  /// Loads the scene and returns the InputError it must raise (a failure when none is raised).
  static engine::InputError load_error(const std::string& path, const Overrides& overrides = {}) {
    try {
      engine::load_scene(path, overrides);
    } catch (const engine::InputError& e) {
      return e;
    }
    ADD_FAILURE() << path << " loaded without an InputError";
    return engine::InputError("", -1, "", "no error");
  }

  /// Asserts file, line, field and a key phrase of the message, and the "file:line:" prefix.
  static void expect_error(const engine::InputError& e, const std::string& file, int line,
                           const std::string& field, const std::string& phrase) {
    EXPECT_EQ(e.file(), file) << e.what();
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_EQ(e.field(), field) << e.what();
    const std::string what = e.what();
    EXPECT_NE(what.find(phrase), std::string::npos) << "'" << phrase << "' not in: " << what;
    const std::string prefix = line > 0 ? file + ":" + std::to_string(line) + ": " : file + ": ";
    EXPECT_EQ(what.rfind(prefix, 0), 0u) << "expected prefix '" << prefix << "' in: " << what;
    if (!field.empty()) {
      EXPECT_NE(what.find(field + ": "), std::string::npos) << "field not in: " << what;
    }
  }
};

}  // namespace dydp::test
