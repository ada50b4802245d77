#pragma once

#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "plots/robot_plots.h"
#include "plots/signals_table.h"

/// What the robot figures share once signals.csv has been read (plots/
/// only): the columns found, the one pass's results, and one function per
/// figure (robot_plots.cc: the time plots; robot_views.cc: the views).
namespace linesim::plots::robot {

struct Point {
  double x, y;
};

/// Extent of what a view shows, ignoring non-finite points.
struct Bounds {
  double x_min = INFINITY, x_max = -INFINITY, y_min = INFINITY, y_max = -INFINITY;
  void Add(double x, double y) {
    if (!std::isfinite(x) || !std::isfinite(y)) return;
    x_min = std::min(x_min, x);
    x_max = std::max(x_max, x);
    y_min = std::min(y_min, y);
    y_max = std::max(y_max, y);
  }
  bool empty() const { return x_min > x_max; }
};

/// The columns of the spec in signals.csv (1-based; 0: not drawn).
struct Columns {
  int x = 0, y = 0, yaw = 0, z = 0, error = 0, bound_from = 0, flow_reference = 0;
  std::vector<std::pair<int, int>> wheels;
  std::vector<int> belt_speeds, belt_ons, belt_travels, flows, flow_truths, flow_filtered;
  struct Other {
    int x, y, yaw;
  };
  std::vector<Other> others;
  struct Worker {
    int x, y;
    std::array<int, 4> legs;
  };
  std::vector<Worker> workers;
  std::vector<int> ranges;
  int scan_time = 0;
  int vx = 0, vy = 0, cap = 0, protective = 0, warning = 0, distance = 0, field_set = 0;
};

/// The run as the figures need it after one pass over signals.csv.
struct RobotRun {
  RobotRun(const RobotPlotSpec& s, table::Signals& rows, Columns columns,
           std::vector<std::string>* files)
      : spec(s), signals(rows), col(std::move(columns)), outputs(files) {}

  const RobotPlotSpec& spec;
  table::Signals& signals;
  Columns col;
  table::DataColumns data;  // the $signals block's columns
  double t_first = 0.0, t_last = 0.0;
  /// Each belt's travel at the last row that gives one.
  std::vector<std::optional<double>> travel_end;
  /// The other robots' and the workers' tracks (every row with a pose).
  std::vector<std::vector<Point>> other_tracks, worker_tracks;
  /// The robot's track and desired path, and the other robots' tracks.
  Bounds tracks;
  /// The nearest approach of a person: its time and distance (NaN: none).
  double closest_t = NAN, closest_m = NAN;
  /// Spans [from, to] of time (s) where any belt is scheduled on, and
  /// where the protective and the warning field are infringed.
  std::vector<std::array<double, 2>> line_on, protective_infringed, warning_infringed;
  /// The safety unit's field set from each time it changed on (s, index).
  std::vector<std::pair<double, int>> field_sets;
  /// When the bound's from column first rose (s; NaN: never).
  double bound_from_t = NAN;
  /// The figures' file names, in the spec's format, as they are begun.
  std::vector<std::string>* outputs;
};

// The views (robot_views.cc): each returns its figure's script lines, or
// nothing when the spec does not ask for it.
std::string TopView(RobotRun& run);
std::string ScanView(RobotRun& run);
std::string SideView(RobotRun& run);

/// Corners of a rectangle centred at (x, y), `length` along heading `yaw`.
std::array<Point, 4> Rectangle(double x, double y, double yaw, double length, double width);

}  // namespace linesim::plots::robot
