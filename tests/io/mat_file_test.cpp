// The MAT v5 writer read back by libmatio's own reader: a matrix's values in their place
// (column-major), a cell of strings, a JSON document as a struct with its keys made field names;
// nothing at the path until commit(), and nothing left when the writer is dropped uncommitted.
#include "io/mat_file.hpp"

#include <gtest/gtest.h>
#include <matio.h>

#include <cctype>
#include <filesystem>
#include <memory>

#include "tests/temp_folder_test.hpp"

namespace dydp::test {
namespace {

namespace fs = std::filesystem;

class MatFileTest : public TempFolderTest {
 protected:
  MatFileTest() : TempFolderTest("dydp_mat_") {}

  int files() const {
    int n = 0;
    for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir_)) ++n;
    return n;
  }
};

struct MatCloser {
  void operator()(mat_t* m) const { Mat_Close(m); }
};
struct VarFreer {
  void operator()(matvar_t* v) const { Mat_VarFree(v); }
};
using Mat = std::unique_ptr<mat_t, MatCloser>;
using Var = std::unique_ptr<matvar_t, VarFreer>;

TEST_F(MatFileTest, AMatrixAStringCellAndAStructReadBackByMatio) {
  const std::string path = (dir_ / "results.mat").string();
  {
    io::MatFile f(path);
    f.matrix("signals", 2, 3, {1.0, 2.0, 3.0, 4.0, 5.0, -6.5});
    f.strings("names", {"t", "body_acc_z"});
    f.json("run", nlohmann::ordered_json{{"solver", "bdf"}, {"steps", 412}, {"d(rms)/d(i)", {0.5, -1.25}}});
    EXPECT_FALSE(fs::exists(path));  // not before commit
    f.commit();
  }
  ASSERT_TRUE(fs::exists(path));
  EXPECT_EQ(files(), 1);

  Mat mat(Mat_Open(path.c_str(), MAT_ACC_RDONLY));
  ASSERT_TRUE(mat);
  Var signals(Mat_VarRead(mat.get(), "signals"));
  ASSERT_TRUE(signals);
  ASSERT_EQ(signals->rank, 2);
  EXPECT_EQ(signals->dims[0], 2u);
  EXPECT_EQ(signals->dims[1], 3u);
  ASSERT_EQ(signals->class_type, MAT_C_DOUBLE);
  const auto* v = static_cast<const double*>(signals->data);
  EXPECT_EQ(v[1], 2.0);   // (1, 0)
  EXPECT_EQ(v[4], 5.0);   // (0, 2)
  EXPECT_EQ(v[5], -6.5);  // (1, 2)

  Var names(Mat_VarRead(mat.get(), "names"));
  ASSERT_TRUE(names);
  ASSERT_EQ(names->class_type, MAT_C_CELL);
  EXPECT_EQ(names->dims[0] * names->dims[1], 2u);
  matvar_t* second = Mat_VarGetCell(names.get(), 1);
  ASSERT_NE(second, nullptr);
  ASSERT_EQ(second->class_type, MAT_C_CHAR);
  EXPECT_EQ(second->dims[1], std::string("body_acc_z").size());

  Var run(Mat_VarRead(mat.get(), "run"));
  ASSERT_TRUE(run);
  ASSERT_EQ(run->class_type, MAT_C_STRUCT);
  matvar_t* steps = Mat_VarGetStructFieldByName(run.get(), "steps", 0);
  ASSERT_NE(steps, nullptr);
  EXPECT_EQ(*static_cast<const double*>(steps->data), 412.0);
  matvar_t* gradient = Mat_VarGetStructFieldByName(run.get(), io::MatFile::field_name("d(rms)/d(i)").c_str(), 0);
  ASSERT_NE(gradient, nullptr);
  EXPECT_EQ(gradient->dims[0] * gradient->dims[1], 2u);
  EXPECT_EQ(static_cast<const double*>(gradient->data)[1], -1.25);
}

TEST_F(MatFileTest, AWriterDroppedUncommittedLeavesNothing) {
  {
    io::MatFile f((dir_ / "half.mat").string());
    f.matrix("x", 1, 2, {1.0, 2.0});
  }
  EXPECT_EQ(files(), 0);
}

TEST_F(MatFileTest, KeysBecomeMatlabFieldNames) {
  EXPECT_EQ(io::MatFile::field_name("body_acc_z"), "body_acc_z");
  const std::string f = io::MatFile::field_name("d(comfort_rms)/d(valve_current)");
  ASSERT_FALSE(f.empty());
  EXPECT_TRUE(std::isalpha(static_cast<unsigned char>(f[0])));
  EXPECT_LE(f.size(), 63u);
  for (char c : f) EXPECT_TRUE(std::isalnum(static_cast<unsigned char>(c)) || c == '_') << f;
  EXPECT_TRUE(std::isalpha(static_cast<unsigned char>(io::MatFile::field_name("2nd")[0])));
  EXPECT_LE(io::MatFile::field_name(std::string(100, 'a')).size(), 63u);
}

}  // namespace
}  // namespace dydp::test
