#include "engine/studies/run_sharing.hpp"

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <exception>
#include <mutex>
#include <thread>

#include "engine/studies/run_filing.hpp"

namespace dydp::engine {

#ifndef DYDP_HAVE_MPI
RankSession::RankSession(int*, char***) {}
RankSession::~RankSession() = default;
int world_rank() { return 0; }
int world_size() { return 1; }
bool built_with_mpi() { return false; }
void share_runs_over_ranks(const std::vector<int>&, const std::function<std::string(int)>&,
                           const std::function<void(int, const std::string&)>&, int) {}
#endif

void share_runs(const std::vector<int>& todo, const std::function<std::string(int)>& run_one,
                const std::function<void(int, const std::string&)>& record, int threads) {
  if (world_size() > 1) return share_runs_over_ranks(todo, run_one, record, threads);
  if (todo.empty()) return;
  const int n = static_cast<int>(todo.size());
  const int workers = std::max(1, std::min(n, threads > 0 ? threads : static_cast<int>(std::thread::hardware_concurrency())));

  // Workers take the next run and queue its record; the calling thread records in turn.
  std::mutex mutex;
  std::condition_variable ready;
  FiledRuns done;
  int next = 0, running = workers;
  std::exception_ptr failure;
  auto worker = [&] {
    for (;;) {
      int k;
      {
        std::lock_guard<std::mutex> lock(mutex);
        if (failure || next >= n) break;
        k = todo[next++];
      }
      run_and_file(k, run_one, mutex, done, failure);
      ready.notify_one();
    }
    std::lock_guard<std::mutex> lock(mutex);
    --running;
    ready.notify_one();
  };
  std::vector<std::thread> pool;
  for (int i = 0; i < workers; ++i) pool.emplace_back(worker);
  std::exception_ptr record_failure;
  for (;;) {
    std::unique_lock<std::mutex> lock(mutex);
    ready.wait(lock, [&] { return !done.empty() || running == 0; });
    if (done.empty()) break;
    auto [k, result] = std::move(done.front());
    done.pop_front();
    lock.unlock();
    try {
      if (!record_failure) record(k, result);
    } catch (...) {
      // A record that cannot be written ends the study like a failed run.
      record_failure = std::current_exception();
      std::lock_guard<std::mutex> stop(mutex);
      if (!failure) failure = record_failure;
    }
  }
  for (auto& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace dydp::engine
