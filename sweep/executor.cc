#include "sweep/executor.h"

#include <algorithm>
#include <exception>
#include <mutex>
#include <thread>

namespace linesim::sweep {

void RunOnThreads(const SweepSpec& spec, const std::vector<std::int64_t>& ids, int jobs,
                  std::atomic<bool>& stop, const OnRunDone& on_done) {
  std::atomic<std::size_t> next{0};
  std::mutex done_mutex;
  std::exception_ptr failure;
  const auto worker = [&] {
    while (!stop.load()) {
      const std::size_t i = next.fetch_add(1);
      if (i >= ids.size()) return;
      const RunSpec run = PlanRun(spec, ids[i]);
      const RunOutcome outcome = ExecuteRun(spec, run, &stop);
      if (outcome.status == RunStatus::kInterrupted) return;
      const std::lock_guard lock(done_mutex);
      if (failure) return;
      try {
        on_done(run, outcome);
      } catch (...) {
        failure = std::current_exception();
        stop = true;
      }
    }
  };
  const auto threads = static_cast<std::size_t>(std::max(1, jobs));
  std::vector<std::jthread> pool;
  for (std::size_t t = 1; t < std::min(threads, ids.size()); ++t) pool.emplace_back(worker);
  worker();  // the calling thread is one of the jobs
  pool.clear();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace linesim::sweep
