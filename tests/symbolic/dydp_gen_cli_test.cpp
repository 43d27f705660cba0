// The dydp-gen command line: outputs, stats.json shape, the in-extenso option, exit statuses.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <sys/wait.h>

namespace {

namespace fs = std::filesystem;

struct CommandResult {
  int status;
  std::string err;
};

CommandResult run(const std::string& args, const fs::path& dir) {
  const fs::path err = dir / "stderr.txt";
  const std::string command = std::string("\"") + DYDP_GEN_EXE + "\" " + args + " 2> \"" + err.string() + "\"";
  const int raw = std::system(command.c_str());
  std::ifstream in(err);
  std::stringstream text;
  text << in.rdbuf();
  return CommandResult{WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, text.str()};
}

std::string read(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class DydpGen : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = fs::path(DYDP_TEST_WORK_DIR) / ("gen_cli_" + std::to_string(::getpid()) + "_" +
                                          ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void TearDown() override { fs::remove_all(dir); }
  fs::path dir;
};

TEST_F(DydpGen, WritesCodeAndStats) {
  const CommandResult r = run(std::string(DYDP_TEST_DATA_DIR) + "/chain3.eqs --out \"" + (dir / "out").string() + "\" --stats", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string cpp = read(dir / "out" / "chain3.cpp");
  EXPECT_NE(cpp.find("void chain3("), std::string::npos);
  EXPECT_NE(cpp.find("void chain3_tangent("), std::string::npos);
  EXPECT_NE(cpp.find("const double OM23 = OM22*C3 + OM32*S3;"), std::string::npos) << cpp;
  EXPECT_EQ(cpp.find("UNUSED"), std::string::npos) << "eliminated assignments are not written";
  EXPECT_NE(read(dir / "out" / "chain3.hpp").find("noexcept;"), std::string::npos);
  const std::string stats = read(dir / "out" / "stats.json");
  for (const char* key : {"\"functions\"", "\"chain3\"", "\"chain3_tangent\"", "\"equations_before\": 6",
                          "\"equations_after\": 5", "\"ops\"", "\"add\"", "\"mul\"", "\"div\"", "\"call\"",
                          "\"ops_total\"", "\"seconds\""}) {
    EXPECT_NE(stats.find(key), std::string::npos) << key << " missing from\n" << stats;
  }
  for (const auto& entry : fs::directory_iterator(dir / "out")) {
    EXPECT_EQ(entry.path().extension() == ".tmp", false) << "temporary left behind: " << entry.path();
  }
}

TEST_F(DydpGen, ExpandWritesTheInExtensoForm) {
  const CommandResult r = run(std::string(DYDP_TEST_DATA_DIR) + "/chain3.eqs --out \"" + (dir / "out").string() + "\" --stats --expand", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string cpp = read(dir / "out" / "chain3.cpp");
  EXPECT_EQ(cpp.find("const double OM"), std::string::npos) << "no auxiliaries in the in-extenso form";
  EXPECT_NE(cpp.find("out[1] = "), std::string::npos);
}

// The sedan's emitted code read as text: a recursive scheme prints every line small and never
// assigns the same right-hand side twice within one function.
TEST_F(DydpGen, SedanCodeHasSmallLinesAndNoRepeatedRightHandSides) {
  const CommandResult r = run(std::string(DYDP_MODELS_DIR) + "/sedan.mbs.yaml --out \"" + (dir / "out").string() + "\"", dir);
  ASSERT_EQ(r.status, 0) << r.err;
  std::size_t files = 0, assignments = 0;
  for (const auto& entry : fs::directory_iterator(dir / "out")) {
    ++files;
    std::istringstream text(read(entry.path()));
    std::set<std::string> right_hand_sides;  // of the current function
    std::string line;
    int number = 0;
    while (std::getline(text, line)) {
      ++number;
      EXPECT_LE(line.size(), 200u) << entry.path().filename() << ":" << number;
      if (line.rfind("void ", 0) == 0) right_hand_sides.clear();
      const std::size_t start = line.find("const double ");
      const std::size_t equals = line.find(" = ");
      if (start == std::string::npos || equals == std::string::npos || line.find('(', start) < equals ||
          line.find('[', start) < equals)
        continue;  // a signature or a descriptor's array
      ++assignments;
      EXPECT_TRUE(right_hand_sides.insert(line.substr(equals + 3)).second)
          << entry.path().filename() << ":" << number << " repeats " << line.substr(equals + 3);
    }
  }
  EXPECT_GE(files, 6u);
  EXPECT_GT(assignments, 1000u);
}

TEST_F(DydpGen, BadInputExitsWithTwoAndFileLine) {
  std::ofstream(dir / "bad.eqs") << "input q 2\nA = q[0] +* q[1]\noutput A\n";
  const CommandResult r = run("\"" + (dir / "bad.eqs").string() + "\" --out \"" + (dir / "out").string() + "\"", dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("bad.eqs:2: "), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out" / "bad.cpp"));
  EXPECT_EQ(run("\"" + (dir / "missing.eqs").string() + "\" --out \"" + (dir / "out").string() + "\"", dir).status, 2);
  EXPECT_EQ(run("--out \"" + (dir / "out").string() + "\"", dir).status, 2) << "no model given";
}

}  // namespace
