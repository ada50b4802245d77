#pragma once

#include <string>
#include <string_view>

namespace linesim::plots {

/// How a figure names and scales a metric of a run (docs/outputs.md lists
/// them): what it measures in words, and the unit a reader wants it in.
struct MetricAxis {
  std::string caption;  // "largest deviation from the path"
  std::string unit;     // "mm"; "" for a count
  double scale = 1.0;   // the recorded (SI) value times this is shown
  /// "caption (unit)", or the caption alone without a unit.
  std::string Label() const { return unit.empty() ? caption : caption + " (" + unit + ")"; }
};

/// `metric`'s caption and unit. The unit follows the name's suffix:
/// lengths (_m) in mm and speeds (_mps) in mm/s when `largest_abs` (the
/// largest magnitude drawn, SI) is under 1, else m and m/s; angles in
/// degrees (_rad, _deg); times in s (_s); shares in % (_fraction); no unit
/// otherwise. A fleet's metric ("raw3_a.max_path_deviation_m") names its
/// robot first; a metric not known by name is captioned from its name.
MetricAxis DescribeMetric(std::string_view metric, double largest_abs);

}  // namespace linesim::plots
