// MTS RPC III time-history files (.rsp, .drv, .tim), read as recorded input and written from a
// run's signals: 512-byte header blocks of 128-byte records (32-byte key, 96-byte value, ASCII,
// NUL-padded), FORMAT, NUM_HEADER_BLOCKS and NUM_PARAMS first; then the data, group by group,
// channel by channel inside a group, as 16-bit integers times SCALE.CHAN_n or 32-bit floats,
// little-endian; the last group padded. docs/formats.md describes what is read and written.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace dydp::io {

struct Rpc3Channel {
  std::string description;     ///< DESC.CHAN_n: how channels are found by name
  std::string units;           ///< UNITS.CHAN_n
  std::vector<double> values;  ///< FRAMES x PTS_PER_FRAME samples (the last frame's padding too)
};

enum class Rpc3DataType { short_integer, floating_point };

struct Rpc3File {
  std::string path;
  double delta_t = 0.0;      ///< DELTA_T [s]: samples at t = k * delta_t
  int points_per_frame = 0;  ///< PTS_PER_FRAME
  int points_per_group = 0;  ///< PTS_PER_GROUP
  int frames = 0;            ///< FRAMES
  Rpc3DataType data_type = Rpc3DataType::floating_point;
  std::map<std::string, std::string> header;  ///< every record, key -> value
  std::vector<Rpc3Channel> channels;
};

/// Reads a time-history file. A malformed header or short data throws
/// InputError(path, 0, KEY, why) naming the key (or the record) at fault.
Rpc3File read_rpc3(const std::string& path);

/// The bytes of a time-history file of the channels (all of one length n >= 1), sampled every
/// delta_t: frames of points_per_frame points, one frame per group, the last frame padded with
/// the channel's last value. SHORT_INTEGER scales each channel by max|value| / 32767.
std::string rpc3_bytes(const std::vector<Rpc3Channel>& channels, double delta_t, Rpc3DataType type,
                       int points_per_frame = 1024);

/// Whether a path names an RPC III file by its extension (.rsp, .drv, .tim, any case).
bool is_rpc3_path(const std::string& path);

}  // namespace dydp::io
