#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace linesim::plots {

/// One line of a metric-against-parameter chart. x values are text as the
/// sweep gave them: numbers ("0.05") or categories ("true", "jacobi").
/// Without `scatter`, each point is the mean of the runs at that x with a
/// min-max error bar; with it, each point is one run (y in `mean`; min and
/// max may be empty).
struct SweepSeries {
  std::string label;  // the key entry; empty for none
  std::vector<std::string> x;
  std::vector<double> mean, min, max;
};

struct SweepChart {
  /// PNG file name in the output folder, made of [A-Za-z0-9._-] only (see
  /// SafeFileName), ending in ".png".
  std::string file;
  /// The metric drawn (a histogram's samples, the y of the others), by its
  /// name: the caption, axis label and unit come from it (DescribeMetric:
  /// lengths in mm, angles in degrees), the values stay in SI. Without it,
  /// `title`, `x_label` and `y_label` are used as given.
  std::string metric;
  /// What the runs are of (the sweep's or scenario's name), the caption's
  /// second line.
  std::string run_caption;
  std::string title, x_label, y_label;
  /// Categories are drawn at 0..n-1 with their text as tic labels, in the
  /// order of `categories` (those missing from it after, in first-seen
  /// order). Numeric x must read as finite numbers.
  bool categorical_x = false;
  std::vector<std::string> categories;
  bool scatter = false;
  /// A histogram of the samples in series[0].mean (x, min and max unused),
  /// with the normal density of their mean and sample standard deviation
  /// scaled to counts over it and the mean as a vertical line (as paper 2's
  /// Figs. 6-11 show a histogram and its normal distribution).
  bool histogram = false;
  /// A source's figures marked on a histogram (when `label` is not empty):
  /// +-max_abs as vertical lines (the bound style) and the zero-mean
  /// normal of `std` scaled to counts, dotted (NaN figures are left out;
  /// paper 2's Table 1 gives these three of its signed errors, not their
  /// mean; its mean_abs is in the written table, not drawn). The x range
  /// widens to show them.
  struct Reference {
    std::string label;
    double max_abs = 0.0, std = 0.0, mean_abs = 0.0;
  } reference;
  std::vector<SweepSeries> series;
};

/// `name` with every character outside [A-Za-z0-9._-] replaced by '_'.
std::string SafeFileName(std::string_view name);

/// Draws each chart into `dir`/chart.file (about 800 x 500 px). The
/// gnuplot script is left in `dir`/sweep_plots.gp with the data inline, so
/// `gnuplot sweep_plots.gp` run in `dir` redraws them. Returns the paths of
/// the PNG files written; with no charts, writes nothing. Non-finite points
/// are left out. Throws std::runtime_error for a chart that cannot be drawn
/// (unsafe or repeated file name, x not a number on a numeric axis, series
/// of unequal lengths: naming the file) or when gnuplot is missing or fails
/// (with gnuplot's error text).
std::vector<std::string> WriteSweepPlots(const std::string& dir,
                                         const std::vector<SweepChart>& charts);

}  // namespace linesim::plots
