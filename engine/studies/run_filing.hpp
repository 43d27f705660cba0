// What every worker of a shared study does with one run, whether the runs are shared among
// threads (run_sharing.cpp) or among MPI ranks (run_sharing_mpi.cpp): run it, and file its
// record, or its failure as the study's first, under the study's lock.
#pragma once

#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <string>
#include <utility>

namespace dydp::engine {

/// Records of runs that have ended, (k, record), in the order they ended.
using FiledRuns = std::deque<std::pair<int, std::string>>;

/// Runs run_one(k) outside the lock; then, under `mutex`, appends its record to `done`, or keeps
/// its exception in `failure` when it is the first.
inline void run_and_file(int k, const std::function<std::string(int)>& run_one, std::mutex& mutex, FiledRuns& done,
                         std::exception_ptr& failure) {
  try {
    std::string result = run_one(k);
    std::lock_guard<std::mutex> lock(mutex);
    done.emplace_back(k, std::move(result));
  } catch (...) {
    std::lock_guard<std::mutex> lock(mutex);
    if (!failure) failure = std::current_exception();
  }
}

}  // namespace dydp::engine
