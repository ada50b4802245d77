#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <mutex>
#include <optional>
#include <sstream>
#include <stop_token>
#include <thread>

#include "app/commands.h"
#include "app/console.h"
#include "config/scenario_error.h"
#include "platform/provenance.h"
#include "sweep/executor.h"
#include "sweep/mpi_sweep.h"
#include "sweep/progress.h"
#include "sweep/results_file.h"
#include "sweep/run_plan.h"
#include "sweep/summary.h"
#include "sweep/sweep_spec.h"

namespace linesim::app {

namespace fs = std::filesystem;

namespace {

// The sweep folder made ready on rank 0: results.csv started or resumed and
// sweep.json saying which sweep it holds. Prints why not and returns nothing
// when the folder cannot take this sweep.
std::optional<sweep::ResultsFile> PrepareFolder(const sweep::SweepSpec& spec, const fs::path& dir,
                                                const std::string& fingerprint, bool resume,
                                                bool force) {
  const fs::path results = dir / "results.csv";
  const fs::path identity = dir / "sweep.json";
  std::error_code ec;  // a bad name is reported when the folder is made
  const bool exists = fs::exists(results, ec);
  if (exists && !resume && !force) {
    std::cerr << "linesim: " << results.string()
              << " exists: --resume continues that sweep, --force starts it afresh, or choose "
                 "another --out\n";
    return std::nullopt;
  }
  std::optional<sweep::SweepIdentity> held;
  if (exists && resume) {
    held = sweep::ReadSweepIdentity(identity.string());
    if (!held) {
      std::cerr << "linesim: cannot resume in " << dir.string() << ": " << identity.string()
                << " is missing or unreadable (or from an older linesim); --force starts "
                   "afresh\n";
      return std::nullopt;
    }
    // Every file a row's run read must still be what it read: the rows and
    // the runs still to do are then of one model.
    if (const auto changed = sweep::ChangedInputs(held->inputs); !changed.empty()) {
      std::cerr << "linesim: cannot resume in " << dir.string()
                << ": the rows there were computed from files that changed since:\n";
      for (const auto& c : changed) std::cerr << "  " << c << "\n";
      std::cerr << "  --force starts afresh\n";
      return std::nullopt;
    }
    if (held->fingerprint != fingerprint) {
      std::cerr << "linesim: cannot resume in " << dir.string()
                << ": it holds another sweep, or the sweep's settings or the files its base "
                   "scenario reads changed since; --force starts afresh\n";
      return std::nullopt;
    }
  }
  if (!CreateOutputFolder(dir.string())) return std::nullopt;
  try {
    if (exists && resume) {
      sweep::ResultsFile resumed = sweep::ResultsFile::Resume(results.string(), spec);
      resumed.TrackInputs(identity.string(), spec, fingerprint, held->inputs);
      return resumed;
    }
    // The old identity goes first: a folder is never left saying it holds
    // this sweep while it holds another's rows.
    fs::remove(identity, ec);
    sweep::ResultsFile created = sweep::ResultsFile::Create(results.string(), spec);
    sweep::WriteSweepIdentity(identity.string(), spec, fingerprint, spec.inputs);
    created.TrackInputs(identity.string(), spec, fingerprint, spec.inputs);
    return created;
  } catch (const std::exception& e) {
    std::cerr << "linesim: " << e.what() << "\n";
    return std::nullopt;
  }
}

}  // namespace

int SweepCommand(const SweepArgs& args, sweep::MpiSession* mpi) {
  const bool leader = !mpi || mpi->rank() == 0;
  // Every rank checks for itself; all go on or all stop. Rank 0 speaks for
  // all, and a rank that alone finds a problem speaks for itself.
  std::ostringstream problems;
  const auto share = [&](int status) {
    if (!mpi) {
      std::cerr << problems.str();
      return status;
    }
    const int leader_status = mpi->LeaderStatus(status);
    if (leader || leader_status == kExitOk) {
      std::istringstream text(problems.str());
      for (std::string line; std::getline(text, line);) {
        std::cerr << (leader ? "" : "rank " + std::to_string(mpi->rank()) + ": ") << line << "\n";
      }
    }
    problems.str("");
    return mpi->ShareStatus(status);
  };

  sweep::SweepSpec spec;
  std::string fingerprint;
  int status = kExitOk;
  try {
    spec = args.repeats > 0 ? sweep::RepeatSweepSpec(args.file, args.sets, args.repeats)
                            : sweep::LoadSweepSpec(args.file);
    fingerprint = sweep::SweepFingerprint(spec);
  } catch (const config::ScenarioError& e) {
    PrintIssues(e, args.repeats > 0 ? "scenario" : "sweep", problems);
    status = kExitBadInput;
  }
  if (share(status) != kExitOk) return kExitBadInput;
  // Ranks on other machines must run the same sweep from the same files.
  if (const std::string held = mpi ? mpi->LeaderText(fingerprint) : fingerprint;
      held != fingerprint) {
    problems << "linesim: the sweep's settings or a file its base scenario reads differs from "
                "rank 0's (fingerprint "
             << fingerprint << " against " << held << ")\n";
    status = kExitBadInput;
  }
  if (share(status) != kExitOk) return kExitBadInput;

  std::optional<sweep::ResultsFile> results =
      leader ? PrepareFolder(spec, args.out_dir, fingerprint, args.resume, args.force)
             : std::nullopt;
  if (leader && !results) status = kExitBadInput;
  if (share(status) != kExitOk) return kExitBadInput;

  // Ctrl-C or SIGTERM: no new run starts, running ones stop at their next
  // step and leave no row; a second signal ends the process at once.
  std::atomic<bool>& stop = InstallStopSignals(
      "\nlinesim: interrupted: stopping the running runs (again to quit at once)\n");
  if (!leader) {
    sweep::ServeRuns(spec, stop);
    return kExitOk;
  }

  const std::int64_t total = sweep::RunCount(spec);
  std::vector<std::int64_t> pending;
  for (std::int64_t id = 0; id < total; ++id) {
    if (!results->HasRow(id)) pending.push_back(id);
  }
  const auto done_before = total - static_cast<std::int64_t>(pending.size());
  if (mpi && args.jobs_given) {
    std::cerr << "linesim: --jobs does not apply under mpirun: each rank but 0 runs one run at "
                 "a time\n";
  }
  std::cout << "sweep " << spec.name << ": " << total << " runs";
  if (done_before > 0) std::cout << " (" << done_before << " already have rows)";
  if (results->dropped_count() > 0) {
    std::cout << " (" << results->dropped_count()
              << " rows did not match the plan (values, seed, status or numbers) and are run "
                 "again)";
  }
  std::cout << " of " << spec.scenario << ", ";
  if (!mpi) {
    std::cout << args.jobs << " job(s)\n";
  } else if (mpi->size() == 1) {
    std::cout << "on rank 0 alone (mpirun -n 1)\n";
  } else {
    std::cout << mpi->size() - 1 << " MPI worker rank(s)\n";
  }
  std::cout << std::flush;

  sweep::ProgressBar bar(std::cerr, isatty(STDERR_FILENO) != 0, total, done_before,
                         results->failed_count());
  std::mutex bar_mutex;
  const auto on_done = [&](const sweep::RunSpec& run, const sweep::RunOutcome& outcome) {
    results->Append(run.id, sweep::FormatRow(run, outcome), outcome.status == sweep::RunStatus::kOk,
                    outcome.inputs);
    const std::lock_guard lock(bar_mutex);
    bar.RunDone(outcome.status == sweep::RunStatus::kOk);
  };
  // Elapsed time and ETA move on between runs too.
  std::jthread ticker;
  if (bar.enabled()) {
    ticker = std::jthread([&](std::stop_token token) {
      std::mutex sleep_mutex;
      std::condition_variable_any wake;
      std::unique_lock sleep_lock(sleep_mutex);
      while (!wake.wait_for(sleep_lock, token, std::chrono::seconds(1), [] { return false; })) {
        if (token.stop_requested()) return;
        const std::lock_guard lock(bar_mutex);
        bar.Redraw();
      }
    });
  }
  const auto wall0 = std::chrono::steady_clock::now();
  try {
    if (mpi) {
      sweep::DispatchRuns(spec, pending, stop, on_done);
    } else {
      sweep::RunOnThreads(spec, pending, args.jobs, stop, on_done);
    }
  } catch (const std::exception& e) {
    ticker = {};
    bar.Finish();
    std::cerr << "linesim: the sweep stopped: " << e.what() << "\n";
    return kExitRunFailed;
  }
  ticker = {};  // joined: the bar is finished once, with nothing drawing after
  bar.Finish();
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  const fs::path dir(args.out_dir);
  if (static_cast<std::int64_t>(results->row_count()) < total) {
    std::cerr << "linesim: interrupted: " << results->row_count() << " of " << total
              << " runs have rows in " << (dir / "results.csv").string()
              << "; the same command with --resume runs the rest\n";
    return kExitInterrupted;
  }
  try {
    results->SortByRunId();
  } catch (const std::exception& e) {
    std::cerr << "linesim: " << e.what() << "\n";
    return kExitRunFailed;
  }
  sweep::SweepTable table = results->Table(spec);
  table.provenance = platform::ProvenanceJson(spec.scenario_sha256, spec.seed);
  std::cout << "sweep " << spec.name << ": finished in " << std::setprecision(3) << wall_s
            << " s wall\n";
  sweep::PrintSummary(table, std::cout);
  std::vector<std::string> written;
  try {
    written = sweep::WriteSweepReport(dir.string(), table);
  } catch (const std::exception& e) {
    std::cerr << "linesim: " << e.what() << "\n";
    return kExitRunFailed;
  }
  std::cout << "  wrote " << (dir / "results.csv").string();
  for (const auto& f : written) std::cout << ", " << fs::path(f).filename().string();
  std::cout << "\n";
  int one_run = kExitOk;
  if (args.repeats > 0) {
    // One run's signals and plots (top view, side view, ...): the first
    // run's seed again, as `linesim run` writes them.
    std::vector<std::string> sets = args.sets;
    sets.push_back("seed=" + std::to_string(sweep::PlanRun(spec, 0).seed));
    std::cout << "\nthe first run again, with its signals and plots, into "
              << (dir / "run_0").string() << ":\n"
              << std::flush;
    one_run = RunCommand(args.file, (dir / "run_0").string(), sets, args.max_output_mb, args.format,
                         nullptr, /*replay=*/true, args.mcap);
  }
  if (one_run == kExitInterrupted) return kExitInterrupted;
  return results->failed_count() == 0 && one_run == kExitOk ? kExitOk : kExitRunFailed;
}

}  // namespace linesim::app
