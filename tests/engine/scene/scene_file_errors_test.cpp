// Scene validation of the file itself: unknown top-level keys, YAML syntax errors, a missing
// scene file, and the CSV tables a scene reads (malformed numbers, times that do not increase,
// unknown columns), each error naming the file (the CSV's own where the fault is in it) and line.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"
#include "tests/engine/scene/scene_validation.hpp"

namespace dydp::engine {
namespace {

namespace fs = std::filesystem;

TEST_F(SceneValidation, UnknownTopLevelKey) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
solvr: {method: bdf}
blocks:
  src: {type: source.sine}
outputs: [src.y]
)");
  const InputError e = load_error(path);
  EXPECT_EQ(e.file(), path);
  EXPECT_EQ(e.line(), 3) << e.what();
  // The field names the unknown key (prefixed by its context).
  const std::string& field = e.field();
  EXPECT_TRUE(field.size() >= 5 && field.compare(field.size() - 5, 5, "solvr") == 0) << field;
  EXPECT_NE(std::string(e.what()).find("unknown key"), std::string::npos) << e.what();
}

TEST_F(SceneValidation, YamlSyntaxError) {
  // Line 5 opens a flow sequence that is never closed.
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}
outputs: [src.y
)");
  const InputError e = load_error(path);
  EXPECT_EQ(e.file(), path);
  // yaml-cpp reports the point where it gave up: on or after the unclosed bracket.
  EXPECT_GE(e.line(), 5) << e.what();
  EXPECT_LE(e.line(), 6) << e.what();
  EXPECT_NE(std::string(e.what()).find("YAML syntax"), std::string::npos) << e.what();
}

TEST_F(SceneValidation, YamlSyntaxErrorInTheMiddle) {
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  src: {type: source.sine}: 3
outputs: [src.y]
)");
  const InputError e = load_error(path);
  EXPECT_EQ(e.file(), path);
  EXPECT_EQ(e.line(), 4) << e.what();
  EXPECT_NE(std::string(e.what()).find("YAML syntax"), std::string::npos) << e.what();
}

TEST_F(SceneValidation, MissingSceneFile) {
  const std::string path = (dir_ / "absent.yaml").string();
  const InputError e = load_error(path);
  EXPECT_EQ(e.file(), path);
  EXPECT_NE(std::string(e.what()).find("cannot open"), std::string::npos) << e.what();
}

TEST_F(SceneValidation, MalformedCsvTableNamesTheCsvFileAndRow) {
  const std::string csv = write("road.csv", "t,z\n0.0,0.0\n0.5,0.01\n1.0,abc\n");
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  road: {type: source.table, file: road.csv, column: z}
outputs: [road.y]
)");
  const InputError e = load_error(path);
  EXPECT_EQ(fs::path(e.file()).lexically_normal(), fs::path(csv).lexically_normal()) << e.what();
  EXPECT_EQ(e.line(), 4) << e.what();  // header is row 1
  EXPECT_EQ(e.field(), "z") << e.what();
  EXPECT_NE(std::string(e.what()).find("malformed number"), std::string::npos) << e.what();
}

TEST_F(SceneValidation, CsvTableTimesMustIncrease) {
  const std::string csv = write("road.csv", "t,z\n0.0,0.0\n0.5,0.01\n0.5,0.02\n");
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  road: {type: source.table, file: road.csv, column: z}
outputs: [road.y]
)");
  const InputError e = load_error(path);
  EXPECT_EQ(fs::path(e.file()).lexically_normal(), fs::path(csv).lexically_normal()) << e.what();
  EXPECT_EQ(e.line(), 4) << e.what();
  EXPECT_EQ(e.field(), "t") << e.what();
  EXPECT_NE(std::string(e.what()).find("times must increase"), std::string::npos) << e.what();
}

TEST_F(SceneValidation, CsvTableUnknownColumnNamesTheSceneLine) {
  write("road.csv", "t,z\n0.0,0.0\n1.0,0.01\n");
  const std::string path = write("s.yaml", R"(scene: t
time: {stop: 1.0, output_step: 0.1}
blocks:
  road:
    type: source.table
    file: road.csv
    column: height
outputs: [road.y]
)");
  expect_error(load_error(path), path, 7, "road.column", "no column 'height'");
}

}  // namespace
}  // namespace dydp::engine
