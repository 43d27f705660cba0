// The output folder contract (DESIGN.md section 5): signals.csv, objectives.json, run.json.
// Each file is written to a temporary name in the folder and renamed when complete; a replay
// streams signals.csv one output time at a time (SignalsCsvStream), in the same format.
#pragma once

#include <fstream>
#include <string>

#include "engine/analysis/run_result.hpp"
#include "engine/framework/diagram.hpp"

namespace dydp::io {

std::string signals_csv(const engine::RunResult& r);
std::string objectives_json(const engine::RunResult& r);
std::string run_json(const engine::Diagram& d, const engine::RunResult& r);

/// signals.csv written as the run goes: each sample() appends the run's latest output time and
/// flushes it, to PATH.partial; finish() renames it to PATH. Unfinished, the partial file is
/// removed, so no reader sees half a signals.csv under its name.
class SignalsCsvStream {
 public:
  explicit SignalsCsvStream(std::string path);
  ~SignalsCsvStream();
  SignalsCsvStream(const SignalsCsvStream&) = delete;
  SignalsCsvStream& operator=(const SignalsCsvStream&) = delete;
  void sample(const engine::RunResult& r);
  void finish();

 private:
  std::string path_, partial_;
  std::ofstream out_;
  bool done_ = false;
};

/// Creates dir if needed and writes the three files.
void write_outputs(const std::string& dir, const engine::Diagram& d, const engine::RunResult& r);

}  // namespace dydp::io
