#include "io/recording.hpp"

#include <deque>
#include <filesystem>
#include <mutex>
#include <system_error>

#include "io/rpc3.hpp"

namespace dydp::io {

CsvFile read_recording(const std::string& path) {
  if (!is_rpc3_path(path)) return read_csv(path);
  const Rpc3File rpc = read_rpc3(path);
  CsvFile table;
  table.path = path;
  table.names.push_back("t");
  const size_t n = rpc.channels[0].values.size();
  std::vector<double> t(n);
  for (size_t k = 0; k < n; ++k) t[k] = static_cast<double>(k) * rpc.delta_t;
  table.columns.push_back(std::move(t));
  for (const Rpc3Channel& c : rpc.channels) {
    table.names.push_back(c.description);
    table.columns.push_back(c.values);
  }
  return table;
}

namespace {

struct Kept {
  std::string path;
  std::uintmax_t size;
  std::filesystem::file_time_type modified;
  std::shared_ptr<const CsvFile> table;
};

constexpr size_t kKeptRecordings = 8;

}  // namespace

std::shared_ptr<const CsvFile> load_recording(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const std::string key = fs::absolute(path, ec).lexically_normal().string();
  const std::uintmax_t size = fs::file_size(path, ec);
  const fs::file_time_type modified = ec ? fs::file_time_type{} : fs::last_write_time(path, ec);
  if (ec) return std::make_shared<const CsvFile>(read_recording(path));  // its error names the file

  static std::mutex mutex;
  static std::deque<Kept> kept;  // most recent first
  {
    const std::lock_guard<std::mutex> lock(mutex);
    for (const Kept& k : kept)
      if (k.path == key && k.size == size && k.modified == modified) return k.table;
  }
  auto table = std::make_shared<const CsvFile>(read_recording(path));
  const std::lock_guard<std::mutex> lock(mutex);
  std::erase_if(kept, [&](const Kept& k) { return k.path == key; });  // an older version of the file
  kept.push_front({key, size, modified, table});
  if (kept.size() > kKeptRecordings) kept.pop_back();
  return table;
}

}  // namespace dydp::io
