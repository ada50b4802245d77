#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "loader/reference.h"

namespace linesim::sweep {

/// How a parameter's values are chosen.
enum class ParameterKind {
  kValues,  // `values: [...]`: the listed YAML values
  kRange,   // `range: {from, to, count}`: count evenly spaced numbers, both ends included
  kRandom,  // `random: {distribution, ...}`: one draw per Monte-Carlo sample
};

enum class Distribution { kUniform, kNormal, kLogUniform };

/// One varied setting of the base scenario, by the dotted path `--set` takes.
struct ParameterSpec {
  std::string path;
  ParameterKind kind = ParameterKind::kValues;
  /// kValues and kRange: the values as YAML text, in order.
  std::vector<std::string> values;
  /// kRandom: uniform and log-uniform draw in [a, b]; normal has mean a and
  /// standard deviation b.
  Distribution distribution = Distribution::kUniform;
  double a = 0, b = 0;
};

enum class Combination {
  kGrid,        // every combination of the listed values
  kMonteCarlo,  // `samples` random draws, crossed with the listed values
};

/// Which scenario seed each run gets.
enum class SeedPolicy {
  /// Runs with the same sample and repeat number share a seed at every grid
  /// point (common random numbers: differences between points are the
  /// parameters' doing, not the noise's).
  kCommon,
  /// Every run its own seed.
  kPerRun,
};

/// The most runs one sweep may have (each is a row of results.csv).
inline constexpr std::int64_t kMaxRuns = 10'000'000;

/// A sweep file, read and checked.
struct SweepSpec {
  std::string file;  // the sweep file as given
  std::string name;
  std::string description;
  std::string scenario;  // the base scenario, resolved against the sweep file's folder
  std::vector<std::pair<std::string, std::string>> fixed;  // `set:`, applied to every run
  std::vector<ParameterSpec> parameters;
  Combination combination = Combination::kGrid;
  std::int64_t samples = 1;  // Monte-Carlo draws (1 for a grid)
  std::int64_t repeats = 1;  // runs per point, each with its own seed
  std::uint64_t seed = 1;
  SeedPolicy seeds = SeedPolicy::kCommon;
  /// The base scenario's SHA-256 with `set:` applied (loader::Scenario::sha256).
  std::string scenario_sha256;
  /// Every file the base scenario's loads read while the sweep was checked
  /// (scenario, robot, scene, model files, route graphs, FMUs): absolute
  /// path -> SHA-256 of its bytes (config/input_files.h). A run records
  /// its own (RunOutcome::inputs); SweepFingerprint covers these.
  std::map<std::string, std::string> inputs;
  /// Metrics of the base scenario to collect; all of them when the file
  /// names none.
  std::vector<std::string> metrics;
  /// Published figures the report prints beside the sweep's: the sweep
  /// file's `reference:`, else, for a sweep without parameters, the base
  /// scenario's (empty title: none).
  /// Each of its metrics is one of `metrics`.
  loader::Reference reference;
};

/// The `set:` entries as `--set` arguments ("path=value"), in file order.
std::vector<std::string> FixedOverrides(const SweepSpec& spec);

/// Reads and checks a sweep file, and that its base scenario loads with the
/// fixed settings, every parameter path exists in it and every metric is
/// one it defines. Throws config::ScenarioError listing every problem (file,
/// line, key path, what was expected).
SweepSpec LoadSweepSpec(const std::string& file);
/// The same for a sweep given as data (the Python package's dicts): `root`
/// is what the file would hold, `label` names it in messages ("<dict>"),
/// and a relative `scenario` is relative to the current folder.
SweepSpec LoadSweepSpecTree(const YAML::Node& root, const std::string& label);

/// The sweep `linesim run FILE --runs N` makes: the scenario as it is with
/// `set_args` ("dotted.path=value", as --set takes them), run N times, each
/// run with its own seed derived from the scenario's seed, collecting every
/// metric, with the scenario's reference. Throws config::ScenarioError as
/// loader::LoadScenario does; N must be in [2, 1e6].
SweepSpec RepeatSweepSpec(const std::string& scenario, const std::vector<std::string>& set_args,
                          std::int64_t runs);

}  // namespace linesim::sweep
