// share_runs among MPI ranks: rank 0 hands out the runs one at a time (the next index to each
// rank that reports), records what the ranks send back, and runs its own share on local threads
// meanwhile; only its calling thread talks to MPI (MPI_THREAD_FUNNELED).
#include <mpi.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <exception>
#include <mutex>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <thread>

#include "engine/framework/errors.hpp"
#include "engine/studies/run_filing.hpp"
#include "engine/studies/run_sharing.hpp"

namespace dydp::engine {
namespace {

bool g_initialized_here = false;

constexpr int kTagReport = 1;  ///< rank -> 0: kind, index, payload
constexpr int kTagAssign = 2;  ///< 0 -> rank: the next index, -1 to stop

enum Kind : int { kReady = 0, kResult = 1, kSolverFailure = 2, kInputFailure = 3, kOtherFailure = 4 };

bool started_by_launcher() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE") || std::getenv("PMIX_RANK");
}

void check(int code, const char* call) {
  if (code != MPI_SUCCESS) throw std::runtime_error(std::string("MPI: ") + call + " failed");
}

void send_report(int kind, int index, const std::string& payload) {
  std::string message(2 * sizeof(int), '\0');
  std::memcpy(message.data(), &kind, sizeof(int));
  std::memcpy(message.data() + sizeof(int), &index, sizeof(int));
  message += payload;
  check(MPI_Send(message.data(), static_cast<int>(message.size()), MPI_CHAR, 0, kTagReport, MPI_COMM_WORLD), "MPI_Send");
}

/// The text after the prefix an error's constructor puts before its message.
std::string message_after(const std::string& what, const std::string& prefix) {
  return what.rfind(prefix, 0) == 0 ? what.substr(prefix.size()) : what;
}

/// A failed run as a report payload, and back into the exception on rank 0.
std::pair<int, std::string> describe(std::exception_ptr e) {
  try {
    std::rethrow_exception(e);
  } catch (const SolverError& s) {
    return {kSolverFailure, nlohmann::json{{"time", s.time()}, {"block", s.block()},
                                           {"reason", message_after(s.what(), SolverError(s.time(), s.block(), "").what())}}
                                .dump()};
  } catch (const InputError& s) {
    return {kInputFailure, nlohmann::json{{"file", s.file()}, {"line", s.line()}, {"field", s.field()},
                                          {"message", message_after(s.what(), InputError(s.file(), s.line(), s.field(), "").what())}}
                               .dump()};
  } catch (const std::exception& s) {
    return {kOtherFailure, nlohmann::json{{"what", s.what()}}.dump()};
  }
}

std::exception_ptr rebuild(int kind, const std::string& payload, int rank) {
  const auto j = nlohmann::json::parse(payload);
  if (kind == kSolverFailure)
    return std::make_exception_ptr(SolverError(j["time"], j["block"], j["reason"].get<std::string>()));
  if (kind == kInputFailure)
    return std::make_exception_ptr(InputError(j["file"], j["line"], j["field"], j["message"].get<std::string>()));
  return std::make_exception_ptr(std::runtime_error("rank " + std::to_string(rank) + ": " + j["what"].get<std::string>()));
}

/// Ranks other than 0: report, take the next index, run it, until told to stop.
void serve(const std::function<std::string(int)>& run_one) {
  send_report(kReady, -1, "");
  for (;;) {
    int index = -1;
    check(MPI_Recv(&index, 1, MPI_INT, 0, kTagAssign, MPI_COMM_WORLD, MPI_STATUS_IGNORE), "MPI_Recv");
    if (index < 0) return;
    try {
      send_report(kResult, index, run_one(index));
    } catch (...) {
      auto [kind, payload] = describe(std::current_exception());
      send_report(kind, index, payload);
    }
  }
}

}  // namespace

RankSession::RankSession(int* argc, char*** argv) {
  if (!started_by_launcher()) return;
  int provided = 0;
  check(MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
  g_initialized_here = true;
}

RankSession::~RankSession() {
  if (g_initialized_here) MPI_Finalize();
}

int world_rank() {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (!initialized) return 0;
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank;
}

int world_size() {
  int initialized = 0;
  MPI_Initialized(&initialized);
  if (!initialized) return 1;
  int size = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  return size;
}

bool built_with_mpi() { return true; }

void share_runs_over_ranks(const std::vector<int>& todo, const std::function<std::string(int)>& run_one,
                           const std::function<void(int, const std::string&)>& record, int threads) {
  if (world_rank() != 0) return serve(run_one);

  std::mutex mutex;
  FiledRuns done;  // local threads' records, in the order they end
  size_t next = 0;
  std::exception_ptr failure;
  auto take = [&]() -> int {  // under mutex
    if (failure || next >= todo.size()) return -1;
    return todo[next++];
  };
  auto local = [&] {
    for (;;) {
      int k;
      {
        std::lock_guard<std::mutex> lock(mutex);
        k = take();
      }
      if (k < 0) return;
      run_and_file(k, run_one, mutex, done, failure);
    }
  };
  std::vector<std::thread> pool;
  for (int i = 0; i < std::max(1, threads); ++i) pool.emplace_back(local);

  auto write = [&](int k, const std::string& result) {
    try {
      record(k, result);
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex);
      if (!failure) failure = std::current_exception();
    }
  };
  int serving = world_size() - 1;  // ranks not yet told to stop
  for (;;) {
    bool busy = false;
    for (;;) {  // local records first: they are ready now
      std::pair<int, std::string> item;
      {
        std::lock_guard<std::mutex> lock(mutex);
        if (done.empty()) break;
        item = std::move(done.front());
        done.pop_front();
      }
      write(item.first, item.second);
      busy = true;
    }
    int waiting = 0;
    MPI_Status status;
    if (serving > 0) check(MPI_Iprobe(MPI_ANY_SOURCE, kTagReport, MPI_COMM_WORLD, &waiting, &status), "MPI_Iprobe");
    if (waiting) {
      int size = 0;
      MPI_Get_count(&status, MPI_CHAR, &size);
      std::string message(size, '\0');
      check(MPI_Recv(message.data(), size, MPI_CHAR, status.MPI_SOURCE, kTagReport, MPI_COMM_WORLD, MPI_STATUS_IGNORE),
            "MPI_Recv");
      int kind = 0, index = 0;
      std::memcpy(&kind, message.data(), sizeof(int));
      std::memcpy(&index, message.data() + sizeof(int), sizeof(int));
      const std::string payload = message.substr(2 * sizeof(int));
      if (kind == kResult) {
        write(index, payload);
      } else if (kind != kReady) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!failure) failure = rebuild(kind, payload, status.MPI_SOURCE);
      }
      int assign;
      {
        std::lock_guard<std::mutex> lock(mutex);
        assign = take();
      }
      check(MPI_Send(&assign, 1, MPI_INT, status.MPI_SOURCE, kTagAssign, MPI_COMM_WORLD), "MPI_Send");
      if (assign < 0) --serving;
      busy = true;
    }
    if (!busy) {
      bool finished;
      {
        std::lock_guard<std::mutex> lock(mutex);
        finished = serving == 0 && done.empty() && (failure || next >= todo.size());
      }
      if (finished) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }
  for (auto& t : pool) t.join();
  // Records of runs that ended while the pool was joining.
  for (auto& [k, result] : done) write(k, result);
  if (failure) std::rethrow_exception(failure);
}

}  // namespace dydp::engine
