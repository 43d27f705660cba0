// The RPC III writer's files read back by the reader: both data types, a padded last frame, the
// header's keys; SHORT_INTEGER samples within half a quantisation step (peak / 32767 / 2) of the
// values written, FLOATING_POINT samples their float rounding. (Files from an independent
// writer: python/tests/test_rpc3.py.)
#include "io/rpc3.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "engine/framework/errors.hpp"
#include "tests/temp_folder_test.hpp"

namespace dydp::test {
namespace {

class Rpc3 : public TempFolderTest {
 protected:
  Rpc3() : TempFolderTest("dydp_rpc3_") {}
};

std::vector<io::Rpc3Channel> two_channels(size_t n) {
  io::Rpc3Channel a{"pad_fl", "m", {}}, b{"force", "N", {}};
  for (size_t k = 0; k < n; ++k) {
    a.values.push_back(0.01 * std::sin(0.05 * static_cast<double>(k)));
    b.values.push_back(1500.0 * std::cos(0.013 * static_cast<double>(k)) - 200.0);
  }
  return {a, b};
}

TEST_F(Rpc3, BothDataTypesReadBackWithThePaddedLastFrame) {
  const size_t n = 2500;  // 3 frames of 1024 points, the last one holding 452
  const auto channels = two_channels(n);
  for (const auto type : {io::Rpc3DataType::short_integer, io::Rpc3DataType::floating_point}) {
    const std::string path = write("signals.rsp", io::rpc3_bytes(channels, 0.002, type));
    const io::Rpc3File f = io::read_rpc3(path);
    EXPECT_EQ(f.frames, 3);
    EXPECT_EQ(f.points_per_frame, 1024);
    EXPECT_EQ(f.delta_t, 0.002);
    EXPECT_EQ(f.data_type, type);
    EXPECT_EQ(f.header.at("FILE_TYPE"), "TIME_HISTORY");
    EXPECT_EQ(std::stoul(f.header.at("NUM_PARAMS")), f.header.size());
    ASSERT_EQ(f.channels.size(), 2u);
    for (size_t c = 0; c < 2; ++c) {
      EXPECT_EQ(f.channels[c].description, channels[c].description);
      EXPECT_EQ(f.channels[c].units, channels[c].units);
      ASSERT_EQ(f.channels[c].values.size(), 3u * 1024u);
      double peak = 0;
      for (double v : channels[c].values) peak = std::max(peak, std::fabs(v));
      for (size_t k = 0; k < n; ++k) {
        const double written = channels[c].values[k], read = f.channels[c].values[k];
        if (type == io::Rpc3DataType::short_integer)
          ASSERT_LE(std::fabs(read - written), 0.5 * peak / 32767 * (1 + 1e-6)) << c << " " << k;
        else
          ASSERT_EQ(read, static_cast<double>(static_cast<float>(written))) << c << " " << k;
      }
      // The padding holds the last sample.
      for (size_t k = n; k < 3 * 1024; ++k) ASSERT_EQ(f.channels[c].values[k], f.channels[c].values[n - 1]);
    }
  }
}

TEST_F(Rpc3, TruncatedDataNameTheFrames) {
  std::string bytes = io::rpc3_bytes(two_channels(100), 0.01, io::Rpc3DataType::floating_point);
  bytes.resize(bytes.size() - 4);
  const std::string path = write("short.rsp", bytes);
  try {
    io::read_rpc3(path);
    FAIL() << "truncated data accepted";
  } catch (const engine::InputError& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.field(), "FRAMES");
  }
}

TEST(Rpc3Paths, ByExtension) {
  EXPECT_TRUE(io::is_rpc3_path("a/b.rsp"));
  EXPECT_TRUE(io::is_rpc3_path("DRIVE.DRV"));
  EXPECT_TRUE(io::is_rpc3_path("x.tim"));
  EXPECT_FALSE(io::is_rpc3_path("x.csv"));
  EXPECT_FALSE(io::is_rpc3_path("rsp"));
}

}  // namespace
}  // namespace dydp::test
