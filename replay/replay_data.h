#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "models/scene.h"

/// replay.html's content as data, and the page written from it. The
/// recorder (replay_recorder.h) fills a ReplayData while the run goes; the
/// page is the template (replay/page.html) with the data as JSON inside.
namespace linesim::replay {

/// What the page shows: the scene, the robot over time, its plots, the
/// other movers, the lasers' scans and how the run ended. Every per-frame
/// vector is as long as `t` (the recorder keeps them so; the page shows
/// nothing of a frame a vector lacks).
struct ReplayData {
  std::string title;        // the scenario's name
  std::string description;  // the scenario's description
  std::string task;         // path, hold or route
  double frame_hz = 50.0, scan_hz = 10.0;
  models::Scene scene;
  std::vector<std::array<double, 2>> path;
  double body_length_m = 0.0, body_width_m = 0.0;
  std::vector<double> t, x, y, yaw;
  struct Wheel {
    std::vector<double> x, y, surface;  // contact point (map), surface code
  };
  std::vector<Wheel> wheels;
  /// Per scene belt: travel (m) and on state (0/1), or empty.
  std::vector<std::vector<double>> belt_travel, belt_on;
  struct Curve {
    std::string label;
    std::vector<double> values;
  };
  /// A plot: title, unit, an optional bound (drawn dashed at +bound), curves.
  struct Plot {
    std::string title, unit;
    double bound = 0.0;
    std::string bound_label;
    std::vector<Curve> curves;
  };
  std::vector<Plot> plots;
  /// A fleet's other robots (a box with a heading) and the workers (a
  /// circle of radius_m).
  struct Mover {
    std::string name;
    bool robot = false;
    double length_m = 0.0, width_m = 0.0, radius_m = 0.0;
    std::vector<double> x, y, yaw;  // yaw: robots only
  };
  std::vector<Mover> movers;
  struct Scan {
    double time_s = 0.0;
    double x = 0.0, y = 0.0, yaw = 0.0;  // the robot's pose at the scan's start
    std::vector<double> ranges;          // m; no_return_m or not finite: no echo
  };
  /// A laser scanner: its mount in base_link, its beams' angles (first +
  /// i * step in the scanner frame), the range meaning no echo, its scans.
  struct Laser {
    std::string name;
    double mount_x_m = 0.0, mount_y_m = 0.0, mount_yaw_rad = 0.0;
    double first_beam_rad = 0.0, beam_step_rad = 0.0, no_return_m = 0.0;
    std::vector<Scan> scans;
  };
  std::vector<Laser> lasers;
  /// How the run ended: "ok", "failed" or "interrupted", at `end_s` of a
  /// run meant to reach `stop_s`; `message` says why when not ok. The page
  /// shows a banner unless ok.
  struct Outcome {
    std::string status = "ok";
    double end_s = 0.0, stop_s = 0.0;
    std::string message;
  };
  Outcome outcome;
};

/// The page's data as JSON text: numbers in fixed notation, each scaled to
/// a whole number of its precision by llround and written as digits (0.1 mm,
/// 1e-5 rad, 1e-5 of a plot's unit, ranges in whole mm and -1 for no echo);
/// a number too large for that (beyond 9e15 of its precision) in shortest
/// round-trip form; not finite: null. No locale, no printf: the same data
/// give the same bytes. Strings escaped so that nothing closes the page's
/// <script> element ('<', '>', '&' as \u00XX) and every byte sequence that
/// is not UTF-8 as U+FFFD (the page reads the file as UTF-8).
std::string DataJson(const ReplayData& data);

/// The whole page: the template with its Content-Security-Policy (the
/// hashes of its own script and style; nothing else may run, load or
/// connect) and the data inside.
std::string PageHtml(const ReplayData& data);

/// The most bytes one number of the data takes, its comma included: a
/// sign, 17 digits and the point, or the shortest round-trip text of a
/// double (24 characters) for one too large; "null" for one not finite.
inline constexpr std::uint64_t kMaxNumberBytes = 25;

/// The page's size without its data (the template and the policy).
std::uint64_t PageBytesWithoutData();

/// The template (replay/page.html), with kDataMarker where the data goes
/// and kPolicyMarker where the Content-Security-Policy's sources go.
const char* PageTemplate();
inline constexpr const char* kDataMarker = "\"__LINESIM_REPLAY_DATA__\"";
inline constexpr const char* kPolicyMarker = "__LINESIM_REPLAY_POLICY__";

}  // namespace linesim::replay
