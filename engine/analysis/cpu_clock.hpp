// CPU time of the calling thread, for run statistics (parallel sweeps time each run alone).
#pragma once

#include <ctime>

namespace dydp::engine {

class CpuClock {
 public:
  CpuClock() : start_(now()) {}
  double seconds() const { return now() - start_; }

 private:
  static double now() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
  }
  double start_;
};

}  // namespace dydp::engine
