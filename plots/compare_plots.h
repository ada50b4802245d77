#pragma once

#include <string>
#include <vector>

#include "plots/gnuplot.h"

namespace linesim::plots {

/// Several runs' deviation (or drift) against time in one figure, as paper
/// 1 Fig. 6 sets the nominal system beside the modified one.
struct ComparisonPlotSpec {
  /// What the comparison is, the caption's second line (its description
  /// and name).
  std::string run_caption;
  /// What is compared, without its unit (drawn in mm): the y axis and the
  /// caption.
  std::string error_label = "deviation from the path";
  struct Run {
    std::string signals_csv;   // relative to the output folder
    std::string error_column;  // its header name in that file
    std::string label;         // the curve's name in the legend
  };
  std::vector<Run> runs;
  /// The line's on state (one column per belt, in the first run's file):
  /// the spans where any belt is on are marked in a band along the top;
  /// none when empty.
  std::vector<std::string> belt_on_columns;
  /// A bound drawn across the figure (m) with its legend entry; none when 0.
  double bound_m = 0.0;
  std::string bound_label;
  PlotFormat format = PlotFormat::kPng;
};

/// The gnuplot script of the comparison: `comparison.FORMAT` from the runs'
/// signals.csv (columns found by name in each file's header; paths relative
/// to `dir`). Throws std::runtime_error naming the file and column when a
/// file cannot be read or has no such column.
std::string ComparisonScript(const std::string& dir, const ComparisonPlotSpec& spec);

/// Writes `dir`/comparison.gp and draws `dir`/comparison.FORMAT with
/// gnuplot; returns the picture's path. Throws as ComparisonScript, and
/// when gnuplot fails.
std::string WriteComparisonPlot(const std::string& dir, const ComparisonPlotSpec& spec);

}  // namespace linesim::plots
