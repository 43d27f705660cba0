// A progress bar for studies of many runs on stderr: runs done, and the time left at the pace of
// the runs so far. On a terminal it redraws one line; otherwise it prints a line per tenth.
#pragma once

#include <chrono>
#include <string>

namespace dydp::apps {

class ProgressBar {
 public:
  explicit ProgressBar(std::string label);
  /// `done` of `total` runs recorded.
  void update(int done, int total);
  /// Clears the terminal line.
  void finish();

 private:
  std::string label_;
  bool tty_;
  int last_tenth_ = -1;
  std::chrono::steady_clock::time_point start_;
};

/// "1h02m", "3m20s", "45s".
std::string format_duration(double seconds);

}  // namespace dydp::apps
