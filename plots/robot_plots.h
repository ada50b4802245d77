#pragma once

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "models/scene.h"
#include "plots/gnuplot.h"

namespace linesim::plots {

/// What to draw for one robot run. Column names are header names of
/// signals.csv as the recorder writes them ("chassis.position[0]"); an
/// empty name leaves out what it would draw.
struct RobotPlotSpec {
  /// The run the figures are of, the second line of every caption (the
  /// scenario's description, its name and seed); none when empty.
  std::string run_caption;
  /// What the top view draws around the robot: belts (rectangles with
  /// arrows along their motion), obstacles (filled outlines; cylinders as
  /// circles), carried objects at their time-zero pose.
  models::Scene scene;
  /// Distance travelled by each scene belt's surface (m; one column per
  /// belt, in scene order, or none): when given, carried objects are drawn
  /// again at the last row, moved along their belt by its travel.
  std::vector<std::string> belt_travel_columns;
  /// The top view frames the robot's path, track and outlines, and what of
  /// the scene lies within `near_m` of them; with `whole_scene`, the whole
  /// floor (when bounded) and everything on it.
  double near_m = 1.5;
  bool whole_scene = false;
  /// Desired path polyline in the map frame; a single point is a hold target.
  std::vector<std::array<double, 2>> path_m;
  /// Robot position (m) and yaw (rad) in the map frame. x and y are
  /// required; without yaw no outlines are drawn.
  std::string x_column, y_column, yaw_column;
  /// Height of base_link above the map's z = 0 (m): with it, side_view.png
  /// draws the height profile along the track (distance travelled in the
  /// plane) over the ground under the track (the floor, or the highest
  /// terrain top face), as a climb into a van shows it.
  std::string z_column;
  /// x and y columns (map frame, m) of each wheel's contact point, drawn as
  /// footprints with the outlines.
  std::vector<std::pair<std::string, std::string>> wheel_columns;
  /// Deviation from the path or drift from the hold target against time
  /// (error.png, drawn in mm); none when empty. The label names it on the
  /// y axis and in the caption, without its unit.
  std::string error_column;
  std::string error_label = "error";
  /// The curve's name in the legend ("deviation of the robot's centre from
  /// the desired path"); the label when empty.
  std::string error_name;
  /// The published bound the run is judged by (m), drawn across error.png
  /// with its legend entry; none when 0. With `from_column` (a 0/1 column:
  /// the task done), it is drawn only from the time that column first
  /// rises: a bound on the final pose. The time plots mark the spans where
  /// any belt is scheduled on (from belt_on_columns) in a band at the top.
  struct Bound {
    double value_m = 0.0;
    std::string label;
    std::string from_column;
  };
  Bound error_bound;
  /// Belt speed (m/s) and on state (0/1) columns for belt.png; none when
  /// both are empty.
  std::vector<std::string> belt_speed_columns, belt_on_columns;
  /// Optic flow against ground truth (optic_flow.png, as paper 1 Fig. 4):
  /// what each sensor reads along the belt (m/s: the surface relative to
  /// it) with its label, the same from ground truth (same order; may be
  /// empty), and the belt's ground-truth speed; none when empty.
  std::vector<std::string> flow_columns, flow_labels;
  std::vector<std::string> flow_truth_columns;
  /// The filtered estimate per sensor (same order; empty without one).
  std::vector<std::string> flow_filtered_columns;
  std::string flow_reference_column;
  /// One laser scan over the scene (scan.png): the scan the scanner had
  /// completed at `time_s`, its rays and hits drawn from the robot's pose
  /// at the scan's start, with the carried objects where the belts had
  /// moved them then. None when `range_columns` is empty.
  struct Scan {
    std::string sensor;
    double time_s = 0.0;
    std::vector<std::string> range_columns;  // one per beam
    std::string scan_time_column;            // start time of the completed scan
    /// Mount in base_link (x, y, yaw) and the beams' angles in the scanner
    /// frame: first + k * step; a range equal to no_return is no echo.
    double mount_x_m = 0.0, mount_y_m = 0.0, mount_yaw_rad = 0.0;
    double first_beam_rad = 0.0, beam_step_rad = 0.0, no_return_m = 0.0;
  };
  Scan scan;
  /// The S300's safety function against a person (safety.png): the robot's
  /// speed (from its map velocity's x and y columns), the safety unit's
  /// speed cap (-1: none), the protective and warning fields' states (1
  /// clear, 0 infringed), the distance from the body to the nearest person
  /// and, from the active field set's index, how far each field reaches
  /// beyond the body's front. None when cap_column is empty.
  struct Safety {
    std::string velocity_x_column, velocity_y_column, cap_column, protective_column, warning_column,
        distance_column, field_set_column;
    /// Per field set: the protective and the warning field's reach beyond
    /// the body's front (m; NaN: no warning field).
    std::vector<std::array<double, 2>> field_depths_m;
  };
  Safety safety;
  /// The workers: each one's track in the top view (its pose's x and y
  /// columns), with its name; in scan.png its legs (the
  /// [x_left, y_left, x_right, y_right] columns, "" for none) and its
  /// torso as the scanner meets them.
  struct Worker {
    std::string name, x_column, y_column;
    std::array<std::string, 4> leg_columns;
    double leg_radius_m = 0.0, torso_radius_m = 0.0;
  };
  std::vector<Worker> workers;
  /// A fleet's other robots in the top view (their tracks, and their
  /// outlines at the same instants as the robot's) and in scan.png (their
  /// outlines at the scan).
  struct OtherRobot {
    std::string name, x_column, y_column, yaw_column;
    double body_length_m = 0.0, body_width_m = 0.0;
    /// Its place in the fleet (0: the first robot): its colour, the same
    /// in every robot's figures.
    std::size_t fleet_index = 0;
  };
  std::vector<OtherRobot> others;
  /// The robot's name in a fleet ("" for one robot).
  std::string robot_name;
  /// Put before every file's name (a fleet's other robots: "raw3_b_",
  /// giving raw3_b_top_view.png and raw3_b_plots.gp).
  std::string file_prefix;
  /// Robot outlines and wheel footprints drawn at this many instants,
  /// evenly spaced over the recorded rows from first to last.
  int footprint_count = 5;
  /// Body rectangle centred on the robot position, length along its x axis
  /// (Rob@Work 3: 1.03 x 0.57 m, paper 1 Table I).
  double body_length_m = 1.03;
  double body_width_m = 0.57;
  /// The pictures' format (and file extension): PNG, SVG or PDF.
  PlotFormat format = PlotFormat::kPng;
};

/// Writes top_view.png, and error.png, belt.png, optic_flow.png, scan.png, side_view.png and
/// safety.png when the spec asks for
/// them, into `dir`, from `dir`/signals.csv. The gnuplot script is left in
/// `dir`/plots.gp with paths relative to `dir`, so `gnuplot plots.gp` run in
/// `dir` redraws the plots. Returns the paths of the pictures written (spec.format).
/// Throws std::runtime_error when signals.csv cannot be read, a column is
/// unknown (naming every unknown column and the closest known ones), or
/// gnuplot is missing or fails (with gnuplot's error text).
std::vector<std::string> WriteRobotPlots(const std::string& dir, const RobotPlotSpec& spec);

/// Every file WriteRobotPlots may write with `prefix` (the script and each
/// picture in every format), so that a new run can clear a previous run's
/// before it starts.
std::vector<std::string> RobotPlotFiles(const std::string& prefix = "");

}  // namespace linesim::plots
