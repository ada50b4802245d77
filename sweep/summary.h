#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <ostream>
#include <span>
#include <string>
#include <vector>

#include "plots/sweep_plots.h"
#include "sweep/sweep_table.h"

namespace linesim::sweep {

/// Statistics of one metric over a group of runs: mean, sample standard
/// deviation (n - 1; 0 for a single run), extremes. With n == 0 all four
/// are NaN.
struct Stats {
  std::int64_t n = 0;
  double mean = 0.0, std = 0.0, min = 0.0, max = 0.0;
  /// Largest and mean absolute value (paper 2's Table 1 reports signed
  /// errors by these and the standard deviation).
  double max_abs = 0.0, mean_abs = 0.0;
};

/// Stats of the finite values among `values` (the others are not counted).
Stats StatsOf(std::span<const double> values);

/// Pearson correlation of paired samples; NaN when undefined (fewer than two
/// pairs, or either side constant).
double Correlation(std::span<const double> x, std::span<const double> y);

/// The report of a finished sweep, for summary.json:
///   {"name", "runs", "ok", "failed", "parameters", "metrics",
///    "by_parameter": {path: [{"value", "runs", "failed", "metrics": {metric:
///      {"n", "mean", "std", "min", "max"}}}, ...]},
///    "by_point": [{"values": {path: value}, "runs", "failed", "metrics"}, ...],
///    "failures": [{"id", "seed", "values", "error": {"unit", "time_s",
///                  "phase", "variable", "cause", "message"}}, ...],
///    "overall": {metric: {"n", "mean", "std", "min", "max", "max_abs",
///      "mean_abs"}},
///    "reference": {"title", "metrics": {metric: {"label", "ours": {"max_abs",
///      "std", "mean_abs"}, "reference": {...}}}} (only with a reference)}
/// Statistics are over the ok runs; "failed" counts the others. Groups of
/// by_parameter follow the parameter's levels; a parameter drawn at random
/// (no levels) has instead {"min", "max", "correlation": {metric: r}}: its
/// numeric range over all runs and Pearson's r with each metric over the ok
/// runs. by_point (grid sweeps only) has one entry per combination of values
/// across repeats, in first-seen row order. Values keep their YAML text;
/// non-finite numbers are null. Throws std::invalid_argument when the
/// table's rows do not match its parameters and metrics.
nlohmann::ordered_json Summarize(const SweepTable& table);

/// The summary as an aligned terminal table: per parameter, per value, each
/// metric's mean ± std [min, max] (4 significant digits); for a sweep
/// without parameters each metric over all runs with its largest and mean
/// absolute value; the reference's table, ours beside the source's; then
/// the failed runs (at most 10).
void PrintSummary(const SweepTable& table, std::ostream& out);

/// A sweep without parameters: one histogram per metric (wall_s left out)
/// of the ok runs. Otherwise one chart per (metric, varied parameter), wall_s included, of the ok
/// runs. In a grid with several parameters each combination of the other
/// parameters' values is its own series when there are at most 8 of them
/// (else one series pools them); each point is the mean, min and max of the
/// runs at that value, across repeats. A parameter drawn at random gives a
/// scatter of the runs. Charts without ok runs are left out.
std::vector<plots::SweepChart> SweepCharts(const SweepTable& table);

/// With a reference: writes `dir`/FILE.csv (metric, label, figure, ours,
/// reference: max_abs, std, mean_abs of both; mean, min, max and runs of
/// ours) and `dir`/FILE.md (the source's table, ours | theirs per cell, our
/// mean and range, and each metric's note), FILE the reference's `file`;
/// returns their paths (none without a reference). Throws
/// std::runtime_error when they cannot be written.
std::vector<std::string> WriteReferenceTable(const std::string& dir, const SweepTable& table);

/// Writes `dir`/summary.json (through a temporary file and a rename), the
/// reference's table (WriteReferenceTable) and the plots of SweepCharts
/// (a histogram for each metric that varies over the runs, with the
/// reference's figures marked); returns the paths written, summary.json
/// first.
/// A plot failure (no gnuplot, gnuplot errors) does not throw: summary.json
/// then says {"plots": {"error": text}} instead of {"plots": {"files":
/// [names]}}. Throws std::runtime_error when summary.json cannot be written.
std::vector<std::string> WriteSweepReport(const std::string& dir, const SweepTable& table);

}  // namespace linesim::sweep
