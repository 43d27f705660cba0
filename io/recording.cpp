#include "io/recording.hpp"

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

}  // namespace dydp::io
