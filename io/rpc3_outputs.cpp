#include "io/rpc3_outputs.hpp"

#include <cmath>
#include <stdexcept>

namespace dydp::io {

std::string run_rpc3(const engine::Diagram& d, const engine::RunResult& r, io::Rpc3DataType type) {
  const double dt = d.time.output_step;
  // RPC III files carry no time column: the samples must lie on t0 + k dt.
  for (size_t k = 0; k < r.t.size(); ++k)
    if (std::fabs(r.t[k] - r.t[0] - static_cast<double>(k) * dt) > 1e-9 * std::max(1.0, std::fabs(r.t[k])))
      throw std::runtime_error("RPC III output needs samples every output_step: t = " + std::to_string(r.t[k]) +
                               " s is off the grid");
  std::vector<io::Rpc3Channel> channels;
  for (int i = 0; i < r.num_signals(); ++i) {
    io::Rpc3Channel c;
    c.description = r.signal_names[i];
    c.units = d.signal_unit(d.logged[i].offset);
    for (size_t k = 0; k < r.t.size(); ++k) c.values.push_back(r.value(static_cast<int>(k), i));
    channels.push_back(std::move(c));
  }
  return io::rpc3_bytes(channels, dt, type);
}

}  // namespace dydp::io
