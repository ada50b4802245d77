#include <CLI/CLI.hpp>
#include <cmath>
#include <exception>
#include <string>
#include <iostream>
#include <memory>
#include <thread>

#include "app/commands.h"
#include "platform/provenance.h"
#include "sweep/mpi_sweep.h"

namespace {

// CLI::Range lets NaN through (every comparison with it is false): a number
// option must be a finite number first.
const CLI::Validator kFinite(
    [](std::string& text) -> std::string {
      try {
        std::size_t used = 0;
        const double v = std::stod(text, &used);
        if (used == text.size() && std::isfinite(v)) return "";
      } catch (const std::exception&) {
      }
      return "expected a finite number, got '" + text + "'";
    },
    "FINITE");

}  // namespace

int main(int argc, char** argv) {
  using namespace linesim::app;
  CLI::App cli{"linesim: co-simulation of mobile robots on moving-floor assembly lines"};
  cli.require_subcommand(1);
  // Version, commit, compiler and build type: what a result was made with.
  cli.set_version_flag("--version", linesim::platform::VersionLine());

  std::string run_file, out_dir;
  std::vector<std::string> run_sets;
  CLI::App* run =
      cli.add_subcommand("run", "run a scenario and write summary.json and signals.csv");
  run->add_option("file", run_file, "scenario YAML file")->required();
  run->add_option("--out,-o", out_dir, "output folder (created if missing)")->required();
  run->add_option("--set", run_sets, "override a value: dotted.path=value (repeatable)")
      ->take_all();
  std::string run_format = "png";
  run->add_option("--format", run_format,
                  "the plots' file format: png (default), or svg or pdf (vector, for papers)")
      ->check(CLI::IsMember({"png", "svg", "pdf"}));
  bool run_mcap = false;
  run->add_flag("--mcap", run_mcap,
                "also write run.mcap (frames, laser scans, scene, every recorded signal) for "
                "Foxglove and PlotJuggler; with --runs, for run_0");
  std::int64_t runs = 1;
  bool no_replay = false;
  run->add_flag("--no-replay", no_replay,
                "do not write replay.html (a robot run writes it: its top view and plots, "
                "animated in a browser)");
  double max_output_mb = linesim::app::kDefaultMaxOutputMb;
  run->add_option("--max-output-mb", max_output_mb,
                  "refuse a run whose files could exceed this many MB together (default 1024)")
      ->check(kFinite)
      ->check(CLI::Range(0.001, 1e9));
  CLI::Option* runs_option = run->add_option("--runs", runs,
                  "run the scenario N times, each with its own seed, as a sweep (results.csv, "
                  "summary.json with the statistics and the scenario's reference, histograms), "
                  "then the first run again into DIR/run_0")
      ->check(CLI::Range(std::int64_t{1}, std::int64_t{1000000}));
  int run_jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  CLI::Option* run_jobs_option =
      run->add_option("--jobs,-j", run_jobs, "with --runs: runs at a time (default: the cores)");
  run_jobs_option->check(CLI::Range(1, 4096))->needs(runs_option);

  std::string what;
  std::vector<std::string> inspect_sets;
  CLI::App* inspect =
      cli.add_subcommand("inspect", "print the variables of a unit type, of a scenario's units or of an FMU");
  bool inspect_all = false;
  CLI::Option* what_option =
      inspect->add_option("what", what, "unit type name, a scenario YAML file, or an FMU (.fmu)");
  inspect->add_flag("--all", inspect_all,
                    "every unit type with its variables, in Markdown (docs/units.md)")
      ->excludes(what_option);
  inspect->add_option("--set", inspect_sets, "override a value: dotted.path=value (repeatable)")
      ->take_all();

  std::string export_type, export_out, export_scene;
  std::vector<std::string> export_sets;
  CLI::App* export_fmu = cli.add_subcommand(
      "export-fmu", "write an FMI 2.0 co-simulation FMU of a unit type (runs linesim's unit in "
                    "other masters)");
  export_fmu->add_option("type", export_type, "unit type name (linesim inspect TYPE)")->required();
  export_fmu->add_option("--set", export_sets,
                         "a structural key, `model` or a parameter of the unit: key=value "
                         "(repeatable)")
      ->take_all();
  export_fmu->add_option("--scene", export_scene,
                         "the scene a unit that needs one (belt, sensors) is built for: a name "
                         "of models/scenes/ or a file (default: the open floor)");
  int export_fmi = 0;
  export_fmu->add_option("--fmi", export_fmi,
                         "FMI version, 2 or 3 (default: 3 when the unit has a Real array of "
                         "more than one element, else 2)")
      ->check(CLI::IsMember({2, 3}));
  export_fmu->add_option("--out,-o", export_out, "the FMU to write (NAME.fmu)")->required();

  SweepArgs sweep_args;
  sweep_args.jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  CLI::App* sweep = cli.add_subcommand(
      "sweep", "run a sweep file's runs (threads, or MPI ranks under mpirun) into results.csv");
  sweep->add_option("file", sweep_args.file, "sweep YAML file")->required();
  sweep->add_option("--out,-o", sweep_args.out_dir, "output folder (created if missing)")
      ->required();
  CLI::Option* jobs =
      sweep->add_option("--jobs,-j", sweep_args.jobs,
                        "runs at a time on this machine (default: its cores); under mpirun the "
                        "ranks other than 0 are the jobs");
  jobs->check(CLI::Range(1, 4096));
  CLI::Option* resume =
      sweep->add_flag("--resume", sweep_args.resume, "run only the runs without a row in DIR");
  sweep->add_flag("--force", sweep_args.force, "start afresh, replacing DIR's results")
      ->excludes(resume);

  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // Help is a success (cli.exit returns 0); a usage error is bad input.
    const int status = cli.exit(e);
    return status == 0 ? kExitOk : kExitBadInput;
  }
  // MPI only for a sweep under mpirun: a plain sweep needs no MPI runtime.
  std::unique_ptr<linesim::sweep::MpiSession> mpi;
  // The commands report what they expect; anything else escaping is still
  // answered with a message and an exit status, never an abort.
  try {
    if (run->parsed() && runs > 1 && IsComparisonFile(run_file)) {
      std::cerr << "linesim: " << run_file
                << ": --runs repeats a scenario; a comparison file (compare:) runs each of its "
                   "runs once (a run's set: may give it a seed)\n";
      return kExitBadInput;
    }
    if (run->parsed() && runs > 1) {
      // Repeats are a sweep without parameters, on threads or MPI ranks.
      if (linesim::sweep::LaunchedByMpi()) {
        mpi = std::make_unique<linesim::sweep::MpiSession>(&argc, &argv);
      }
      SweepArgs repeats;
      repeats.file = run_file;
      repeats.out_dir = out_dir;
      repeats.jobs = run_jobs;
      repeats.jobs_given = run_jobs_option->count() > 0;
      // As `linesim run` does, a new run replaces the folder's last one.
      repeats.force = true;
      repeats.repeats = runs;
      repeats.sets = run_sets;
      repeats.max_output_mb = max_output_mb;
      repeats.format = *linesim::plots::ParsePlotFormat(run_format);
      repeats.mcap = run_mcap;
      return SweepCommand(repeats, mpi.get());
    }
    if (run->parsed()) {
      return RunCommand(run_file, out_dir, run_sets, max_output_mb,
                        *linesim::plots::ParsePlotFormat(run_format), nullptr, !no_replay,
                        run_mcap);
    }
    if (sweep->parsed()) {
      if (linesim::sweep::LaunchedByMpi()) {
        mpi = std::make_unique<linesim::sweep::MpiSession>(&argc, &argv);
      }
      sweep_args.jobs_given = jobs->count() > 0;
      return SweepCommand(sweep_args, mpi.get());
    }
    if (export_fmu->parsed()) return ExportFmuCommand(export_type, export_sets, export_scene, export_fmi, export_out);
    if (inspect_all) return UnitReferenceCommand();
    if (what.empty()) {
      std::cerr << "linesim inspect: give a unit type, a scenario file or an FMU, or --all\n";
      return kExitBadInput;
    }
    return InspectCommand(what, inspect_sets);
  } catch (const std::exception& e) {
    std::cerr << "linesim: " << e.what() << "\n";
    // The other ranks may be waiting on this one: end them all.
    if (mpi) mpi->Abort(kExitRunFailed);
    return kExitBadInput;
  }
}
