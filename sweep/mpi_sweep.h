#pragma once

#include <atomic>
#include <string>
#include <vector>

#include "sweep/executor.h"

namespace linesim::sweep {

/// True when this process was started by mpirun/mpiexec (Open MPI, MPICH or
/// PMIx set their rank in the environment). MPI is started only then: a
/// plain `linesim sweep` needs no MPI runtime.
bool LaunchedByMpi();

/// MPI_Init on construction, MPI_Finalize on destruction (one per process).
class MpiSession {
 public:
  MpiSession(int* argc, char*** argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  int rank() const { return rank_; }
  int size() const { return size_; }
  /// The worst (largest) of every rank's `status`, on every rank: all ranks
  /// go on together or stop together (no rank left waiting for work).
  int ShareStatus(int status) const;
  /// Rank 0's `status` (or `text`), on every rank.
  int LeaderStatus(int status) const;
  std::string LeaderText(const std::string& text) const;
  /// Ends every rank at once (an unexpected failure on one rank, which would
  /// otherwise leave the others waiting).
  [[noreturn]] void Abort(int status) const;

 private:
  int rank_ = 0;
  int size_ = 1;
};

/// Rank 0: hands the runs `ids` out one at a time to whichever worker rank asks
/// (dynamic balance), and calls `on_done` for each result, in arrival
/// order. Once `stop` is set it hands out nothing more and waits for the
/// running ones. With one rank only, rank 0 runs them itself.
void DispatchRuns(const SweepSpec& spec, const std::vector<std::int64_t>& ids,
                  std::atomic<bool>& stop, const OnRunDone& on_done);

/// Ranks other than 0: run what rank 0 sends until it says stop. `stop`
/// interrupts the running run (it then sends no row).
void ServeRuns(const SweepSpec& spec, std::atomic<bool>& stop);

}  // namespace linesim::sweep
