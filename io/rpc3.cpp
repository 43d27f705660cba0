#include "io/rpc3.hpp"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "engine/framework/errors.hpp"
#include "engine/framework/numbers.hpp"

namespace dydp::io {

using engine::InputError;
using engine::parse_number;
namespace {

static_assert(std::endian::native == std::endian::little, "RPC III data are read as little-endian");

constexpr size_t kBlock = 512, kRecord = 128, kKey = 32, kValue = 96;

std::string trimmed(const char* text, size_t size) {
  std::string s(text, strnlen(text, size));
  const auto b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

class HeaderReader {
 public:
  HeaderReader(std::string path, std::map<std::string, std::string>& header) : path_(std::move(path)), header_(header) {}

  [[noreturn]] void fail(const std::string& key, const std::string& why) const { throw InputError(path_, 0, key, why); }

  const std::string& text(const std::string& key) const {
    const auto it = header_.find(key);
    if (it == header_.end()) fail(key, "missing from the header");
    return it->second;
  }
  bool has(const std::string& key) const { return header_.count(key) != 0; }

  double number(const std::string& key) const {
    double v = 0;
    if (!parse_number(text(key), v)) fail(key, "'" + text(key) + "' is not a number");
    return v;
  }
  /// An integer in [low, high].
  long integer(const std::string& key, long low, long high) const {
    const double v = number(key);
    if (v != std::floor(v) || v < low || v > high)
      fail(key, "'" + text(key) + "' is not an integer in [" + std::to_string(low) + ", " + std::to_string(high) + "]");
    return static_cast<long>(v);
  }

 private:
  std::string path_;
  std::map<std::string, std::string>& header_;
};

void put_record(std::string& out, const std::string& key, const std::string& value) {
  char record[kRecord] = {};
  std::memcpy(record, key.data(), std::min(key.size(), kKey - 1));
  std::memcpy(record + kKey, value.data(), std::min(value.size(), kValue - 1));
  out.append(record, kRecord);
}

/// The shortest text that reads back as the same double (a reader gets DELTA_T and the
/// scales exactly).
std::string number_text(double v) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, v).ptr;
  return std::string(text, end);
}

}  // namespace

bool is_rpc3_path(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".rsp" || ext == ".drv" || ext == ".tim";
}

Rpc3File read_rpc3(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path, 0, "", "is a folder, not an RPC III file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, "", "cannot open the file");
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  Rpc3File f;
  f.path = path;
  HeaderReader h(path, f.header);
  if (bytes.size() < kBlock) h.fail("FORMAT", "the file is shorter than one 512-byte header block");

  // The first three records, in this order, say how long the rest of the header is.
  const char* const expected[3] = {"FORMAT", "NUM_HEADER_BLOCKS", "NUM_PARAMS"};
  for (int r = 0; r < 3; ++r) {
    const std::string key = trimmed(bytes.data() + r * kRecord, kKey);
    if (key != expected[r])
      h.fail(expected[r], "header record " + std::to_string(r + 1) + " must be " + expected[r] + ", found '" + key + "'");
    f.header[key] = trimmed(bytes.data() + r * kRecord + kKey, kValue);
  }
  const std::string& format = h.text("FORMAT");
  if (format == "BINARY_IEEE_BIG_END") h.fail("FORMAT", "big-endian data (BINARY_IEEE_BIG_END) are not read: only little-endian");
  if (format != "BINARY" && format != "BINARY_IEEE_LITTLE_END")
    h.fail("FORMAT", "'" + format + "' is not a binary RPC III format (BINARY, BINARY_IEEE_LITTLE_END)");
  const long blocks = h.integer("NUM_HEADER_BLOCKS", 1, 1 << 20);
  const long params = h.integer("NUM_PARAMS", 3, 4 * blocks);
  if (bytes.size() < static_cast<size_t>(blocks) * kBlock)
    h.fail("NUM_HEADER_BLOCKS", std::to_string(blocks) + " header blocks, but the file holds " + std::to_string(bytes.size()) + " bytes");
  for (long r = 3; r < params; ++r) {
    const std::string key = trimmed(bytes.data() + r * kRecord, kKey);
    if (key.empty()) h.fail("NUM_PARAMS", "header record " + std::to_string(r + 1) + " of " + std::to_string(params) + " has no key");
    if (f.header.count(key)) h.fail(key, "given twice in the header (record " + std::to_string(r + 1) + ")");
    f.header[key] = trimmed(bytes.data() + r * kRecord + kKey, kValue);
  }

  if (h.has("FILE_TYPE") && h.text("FILE_TYPE") != "TIME_HISTORY")
    h.fail("FILE_TYPE", "'" + h.text("FILE_TYPE") + "': only TIME_HISTORY files hold recorded signals");
  const long channels = h.integer("CHANNELS", 1, 256);
  f.delta_t = h.number("DELTA_T");
  if (!(f.delta_t > 0)) h.fail("DELTA_T", "'" + h.text("DELTA_T") + "' must be positive");
  f.points_per_frame = static_cast<int>(h.integer("PTS_PER_FRAME", 1, 1 << 24));
  f.points_per_group = static_cast<int>(h.integer("PTS_PER_GROUP", 1, 1 << 24));
  if (f.points_per_group % f.points_per_frame != 0)
    h.fail("PTS_PER_GROUP", h.text("PTS_PER_GROUP") + " is not a multiple of PTS_PER_FRAME = " + h.text("PTS_PER_FRAME"));
  f.frames = static_cast<int>(h.integer("FRAMES", 1, 1L << 30));
  const std::string& type = h.text("DATA_TYPE");
  if (type == "SHORT_INTEGER") f.data_type = Rpc3DataType::short_integer;
  else if (type == "FLOATING_POINT") f.data_type = Rpc3DataType::floating_point;
  else h.fail("DATA_TYPE", "'" + type + "' is neither SHORT_INTEGER nor FLOATING_POINT");

  std::vector<double> scale(channels, 1.0);
  f.channels.resize(channels);
  for (long c = 0; c < channels; ++c) {
    const std::string n = std::to_string(c + 1);
    f.channels[c].description = h.has("DESC.CHAN_" + n) ? h.text("DESC.CHAN_" + n) : "";
    f.channels[c].units = h.has("UNITS.CHAN_" + n) ? h.text("UNITS.CHAN_" + n) : "";
    if (f.data_type == Rpc3DataType::short_integer) {
      scale[c] = h.number("SCALE.CHAN_" + n);
      if (!(scale[c] > 0)) h.fail("SCALE.CHAN_" + n, "'" + h.text("SCALE.CHAN_" + n) + "' must be positive");
    }
    for (long e = 0; e < c; ++e)
      if (!f.channels[c].description.empty() && f.channels[e].description == f.channels[c].description)
        h.fail("DESC.CHAN_" + n, "'" + f.channels[c].description + "' also describes channel " + std::to_string(e + 1) +
                                     ": channels are found by their descriptions");
  }

  // Data: group after group; inside a group, PTS_PER_GROUP points of channel 1, then of channel
  // 2, ...; the points past FRAMES x PTS_PER_FRAME in the last group are padding.
  const size_t points = static_cast<size_t>(f.frames) * f.points_per_frame;
  const size_t per_group = f.points_per_group;
  const size_t groups = (points + per_group - 1) / per_group;
  const size_t width = f.data_type == Rpc3DataType::short_integer ? 2 : 4;
  const size_t start = static_cast<size_t>(blocks) * kBlock;
  // Compared by division: FRAMES x PTS_PER_FRAME x CHANNELS x width may not fit in 64 bits.
  const size_t available = (bytes.size() - start) / (channels * width);
  if (groups * per_group > available)
    h.fail("FRAMES", h.text("FRAMES") + " frames of " + h.text("PTS_PER_FRAME") + " points need " +
                         std::to_string(groups * per_group) + " points per channel (whole groups of " +
                         h.text("PTS_PER_GROUP") + "), the file's data hold " + std::to_string(available));
  for (auto& ch : f.channels) ch.values.resize(points);
  for (size_t g = 0; g < groups; ++g)
    for (long c = 0; c < channels; ++c)
      for (size_t k = 0; k < per_group; ++k) {
        const size_t point = g * per_group + k;
        if (point >= points) break;
        const char* at = bytes.data() + start + ((g * channels + c) * per_group + k) * width;
        if (f.data_type == Rpc3DataType::short_integer) {
          int16_t v;
          std::memcpy(&v, at, 2);
          f.channels[c].values[point] = v * scale[c];
        } else {
          float v;
          std::memcpy(&v, at, 4);
          if (!std::isfinite(v))
            h.fail("DESC.CHAN_" + std::to_string(c + 1), "sample " + std::to_string(point) + " is not a finite number");
          f.channels[c].values[point] = v;
        }
      }
  return f;
}

std::string rpc3_bytes(const std::vector<Rpc3Channel>& channels, double delta_t, Rpc3DataType type,
                       int points_per_frame) {
  const size_t n = channels.empty() ? 0 : channels[0].values.size();
  const size_t ppf = static_cast<size_t>(points_per_frame);
  const size_t frames = (n + ppf - 1) / ppf;
  std::vector<double> scale(channels.size(), 1.0);
  for (size_t c = 0; c < channels.size(); ++c) {
    double peak = 0;
    for (double v : channels[c].values) peak = std::max(peak, std::fabs(v));
    scale[c] = peak > 0 ? peak / 32767.0 : 1.0;
  }

  std::vector<std::pair<std::string, std::string>> records = {
      {"FORMAT", "BINARY_IEEE_LITTLE_END"}, {"NUM_HEADER_BLOCKS", ""}, {"NUM_PARAMS", ""},
      {"FILE_TYPE", "TIME_HISTORY"}, {"TIME_TYPE", "RESPONSE"}, {"DATA_TYPE", type == Rpc3DataType::short_integer ? "SHORT_INTEGER" : "FLOATING_POINT"},
      {"CHANNELS", std::to_string(channels.size())}, {"DELTA_T", number_text(delta_t)},
      {"PTS_PER_FRAME", std::to_string(ppf)}, {"PTS_PER_GROUP", std::to_string(ppf)},
      {"FRAMES", std::to_string(frames)}, {"REPEATS", "1"}, {"HALF_FRAMES", "0"},
      {"INT_FULL_SCALE", "32768"}, {"BYPASS_FILTER", "0"}};
  for (size_t c = 0; c < channels.size(); ++c) {
    const std::string k = std::to_string(c + 1);
    double lo = 0, hi = 0;
    if (!channels[c].values.empty()) {
      const auto [mn, mx] = std::minmax_element(channels[c].values.begin(), channels[c].values.end());
      lo = *mn, hi = *mx;
    }
    records.push_back({"DESC.CHAN_" + k, channels[c].description});
    records.push_back({"UNITS.CHAN_" + k, channels[c].units});
    records.push_back({"SCALE.CHAN_" + k, number_text(scale[c])});
    records.push_back({"LOWER_LIMIT.CHAN_" + k, number_text(lo)});
    records.push_back({"UPPER_LIMIT.CHAN_" + k, number_text(hi)});
    records.push_back({"MAP.CHAN_" + k, k});
  }
  const size_t blocks = (records.size() * kRecord + kBlock - 1) / kBlock;
  records[1].second = std::to_string(blocks);
  records[2].second = std::to_string(records.size());
  std::string out;
  for (const auto& [key, value] : records) put_record(out, key, value);
  out.resize(blocks * kBlock, '\0');

  // One frame per group: frame f holds points [f ppf, (f + 1) ppf), the last padded with the
  // channel's last value.
  for (size_t f = 0; f < frames; ++f)
    for (size_t c = 0; c < channels.size(); ++c)
      for (size_t k = 0; k < ppf; ++k) {
        const double v = channels[c].values[std::min(f * ppf + k, n - 1)];
        if (type == Rpc3DataType::short_integer) {
          const int16_t q = static_cast<int16_t>(std::lround(v / scale[c]));
          out.append(reinterpret_cast<const char*>(&q), 2);
        } else {
          const float q = static_cast<float>(v);
          out.append(reinterpret_cast<const char*>(&q), 4);
        }
      }
  return out;
}

}  // namespace dydp::io
