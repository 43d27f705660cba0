// The CSV reader, the recording reader that picks CSV or RPC III by extension, and the atomic
// file writer: values read as written, every malformed cell or row reported as file:row: column,
// the recording cache re-reading a file that changed, no temporary file left behind.
#include "io/csv.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "engine/framework/errors.hpp"
#include "io/files.hpp"
#include "io/recording.hpp"
#include "io/rpc3.hpp"
#include "tests/temp_folder_test.hpp"

namespace dydp::test {
namespace {

namespace fs = std::filesystem;
using engine::InputError;

class Csv : public TempFolderTest {
 protected:
  Csv() : TempFolderTest("dydp_csv_") {}

  /// The InputError read_csv throws on `text`; fails the test when it throws none.
  InputError error_of(const std::string& text) const {
    const std::string path = write("bad.csv", text);
    try {
      io::read_csv(path);
    } catch (const InputError& e) {
      return e;
    }
    ADD_FAILURE() << "no error for:\n" << text;
    return InputError(path, 0, "", "none");
  }
};

TEST_F(Csv, ColumnsByNameWithSpacesAndBlankLines) {
  const std::string path = write("pads.csv", " t , pad_fl,pad_fr\r\n0, 1e-3, -2.5\n\n  \n0.01,0.5,  3\n");
  const io::CsvFile f = io::read_csv(path);
  EXPECT_EQ(f.path, path);
  ASSERT_EQ(f.names, (std::vector<std::string>{"t", "pad_fl", "pad_fr"}));
  EXPECT_EQ(f.find("pad_fr"), 2);
  EXPECT_EQ(f.find("pad_rl"), -1);
  ASSERT_EQ(f.columns.size(), 3u);
  EXPECT_EQ(f.columns[0], (std::vector<double>{0.0, 0.01}));
  EXPECT_EQ(f.columns[1], (std::vector<double>{1e-3, 0.5}));
  EXPECT_EQ(f.columns[2], (std::vector<double>{-2.5, 3.0}));
}

TEST_F(Csv, ValuesReadBackExactlyAtFullPrecision) {
  std::ostringstream text;
  text.precision(17);
  text << "t,x\n";
  std::vector<double> x;
  for (int k = 0; k < 200; ++k) {
    x.push_back(std::sin(0.37 * k) * std::pow(10.0, k % 13 - 6));
    text << 0.001 * k << "," << x.back() << "\n";
  }
  const io::CsvFile f = io::read_csv(write("x.csv", text.str()));
  EXPECT_EQ(f.columns[1], x);
}

TEST_F(Csv, AMalformedCellNamesItsRowAndColumn) {
  const InputError e = error_of("t,force\n0,1\n0.1,12x\n");
  EXPECT_EQ(e.line(), 3);
  EXPECT_EQ(e.field(), "force");
  EXPECT_NE(std::string(e.what()).find("malformed number '12x'"), std::string::npos) << e.what();
  EXPECT_NE(std::string(e.what()).find("bad.csv:3"), std::string::npos) << e.what();
}

TEST_F(Csv, RowsCountBlankLinesAndAShortRowIsRefused) {
  const InputError e = error_of("t,a,b\n0,1,2\n\n0.2,3\n");
  EXPECT_EQ(e.line(), 4);
  EXPECT_NE(std::string(e.what()).find("expected 3 values, found 2"), std::string::npos) << e.what();
  EXPECT_EQ(error_of("t,a,b\n0,,2\n").field(), "a");  // an empty cell is not a zero
  // A trailing comma ends the row (files written with one on every line, header included, read
  // as without it), so a row short of its last value is refused by its length.
  EXPECT_EQ(io::read_csv(write("trailing.csv", "t,a,\n0,1,\n")).columns.size(), 2u);
  EXPECT_NE(std::string(error_of("t,a\n0,\n").what()).find("expected 2 values, found 1"), std::string::npos);
}

TEST_F(Csv, EmptyMissingAndFolderAreRefusedByName) {
  EXPECT_EQ(error_of("").line(), 1);
  const std::string missing = (dir_ / "none.csv").string();
  try {
    io::read_csv(missing);
    ADD_FAILURE() << "no error for a missing file";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), missing);
  }
  EXPECT_THROW(io::read_csv(dir_.string()), InputError);
}

TEST_F(Csv, ARecordingIsReadByItsExtension) {
  const std::string csv = write("r.csv", "t,pad\n0,1\n0.5,2\n");
  EXPECT_EQ(io::read_recording(csv).columns[1], (std::vector<double>{1.0, 2.0}));
  std::vector<io::Rpc3Channel> channels{{"pad_fl", "m", {0.25, -0.5, 0.125}}};
  const std::string rsp = write("r.rsp", io::rpc3_bytes(channels, 0.004, io::Rpc3DataType::floating_point));
  const io::CsvFile f = io::read_recording(rsp);
  ASSERT_EQ(f.names.size(), 2u);
  EXPECT_EQ(f.names[0], "t");
  EXPECT_EQ(f.names[1], "pad_fl");
  ASSERT_GE(f.columns[1].size(), 3u);
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_DOUBLE_EQ(f.columns[0][k], 0.004 * static_cast<double>(k));
    EXPECT_EQ(f.columns[1][k], channels[0].values[k]);
  }
  // A CSV named .rsp is read as RPC III, and refused as one.
  EXPECT_THROW(io::read_recording(write("csv_named.rsp", "t,pad\n0,1\n")), InputError);
}

TEST_F(Csv, TheRecordingCacheRereadsAFileThatChanged) {
  const std::string path = write("c.csv", "t,pad\n0,1\n");
  const auto first = io::load_recording(path);
  EXPECT_EQ(io::load_recording(path), first);  // unchanged: the same table
  write("c.csv", "t,pad\n0,1\n0.1,7\n");         // longer: another size
  const auto second = io::load_recording(path);
  ASSERT_EQ(second->columns[1].size(), 2u);
  EXPECT_EQ(second->columns[1][1], 7.0);
  EXPECT_EQ(first->columns[1].size(), 1u);  // a table handed out stays as it was
}

TEST_F(Csv, AnAtomicWriteReplacesTheFileAndLeavesNoTemporary) {
  const std::string path = (dir_ / "out.json").string();
  io::write_file_atomically(path, "{\"a\": 1}\n");
  io::write_file_atomically(path, "{\"a\": 2}\n");
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), "{\"a\": 2}\n");
  int files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir_)) ++files;
  EXPECT_EQ(files, 1);
  EXPECT_THROW(io::write_file_atomically((dir_ / "no_such_folder" / "x").string(), "x"), std::runtime_error);
}

}  // namespace
}  // namespace dydp::test
