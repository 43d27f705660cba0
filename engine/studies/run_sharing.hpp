// Independent runs of a study (sweep points, screening samples) shared among worker threads,
// and among MPI ranks when dydp is started by mpirun: each run returns its result as a text
// record, and every record reaches one place (rank 0's calling thread) as its run ends.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace dydp::engine {

/// MPI for the process's lifetime when it was started by an MPI launcher (mpirun sets
/// OMPI_COMM_WORLD_SIZE, PMI_SIZE or PMIX_RANK) and dydp was built with MPI; otherwise nothing.
class RankSession {
 public:
  RankSession(int* argc, char*** argv);
  ~RankSession();
  RankSession(const RankSession&) = delete;
  RankSession& operator=(const RankSession&) = delete;
};

/// This process's rank and the number of ranks: 0 and 1 without MPI or outside mpirun.
int world_rank();
int world_size();
/// True when dydp was built with MPI.
bool built_with_mpi();

/// Runs run_one(k) for every k of `todo`, each once, spread over `threads` threads of every rank
/// (0: one per core in a single process, one per rank under MPI). Every result goes to
/// record(k, result) on rank 0 in the calling thread, one call at a time, as its run ends (under
/// MPI: as soon as rank 0 receives it). The first failure stops handing out runs; it is rethrown
/// on rank 0 once the runs under way have ended (other ranks return quietly, their part done).
void share_runs(const std::vector<int>& todo, const std::function<std::string(int)>& run_one,
                const std::function<void(int, const std::string&)>& record, int threads = 0);

/// Implementation of share_runs among the ranks (engine/studies/run_sharing_mpi.cpp).
void share_runs_over_ranks(const std::vector<int>& todo, const std::function<std::string(int)>& run_one,
                           const std::function<void(int, const std::string&)>& record, int threads);

}  // namespace dydp::engine
