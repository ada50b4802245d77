#include "plots/metric_labels.h"

#include <array>
#include <numbers>
#include <utility>

namespace linesim::plots {

namespace {

// The metrics a robot run measures (docs/outputs.md), without their unit
// suffix, in words.
constexpr std::array<std::pair<std::string_view, std::string_view>, 31> kCaptions = {{
    {"max_path_deviation", "largest deviation from the path"},
    {"final_path_deviation", "deviation from the path at the end"},
    {"final_progress", "progress along the path at the end"},
    {"max_position_drift", "largest drift from the held position"},
    {"final_position_drift", "drift from the held position at the end"},
    {"final_yaw", "heading at the end"},
    {"min_clearance", "smallest clearance to the scene"},
    {"collisions", "collisions with the scene"},
    {"surface_velocity_rmse_raw", "RMS error of the raw surface velocity (Eq. 2)"},
    {"surface_velocity_rmse_filtered", "RMS error of the filtered surface velocity"},
    {"optic_flow_quality_mean", "mean PX4Flow quality"},
    {"localization_error_max", "largest localization error"},
    {"localization_error_rms", "RMS localization error"},
    {"localization_yaw_error_max", "largest localization heading error"},
    {"localization_yaw_error_rms", "RMS localization heading error"},
    {"final_error_x", "true final pose error in X"},
    {"final_error_y", "true final pose error in Y"},
    {"final_error_yaw", "true final heading error"},
    {"beacon_error_x", "final pose error in X by the beacons"},
    {"beacon_error_y", "final pose error in Y by the beacons"},
    {"beacon_error_yaw", "final heading error by the beacons"},
    {"beacon_self_error_position", "the beacon system's own position error"},
    {"beacon_self_error_yaw", "the beacon system's own heading error"},
    {"protective_stops", "protective stops"},
    {"time_stopped", "time stopped by the safety function"},
    {"task_time", "time to finish the task"},
    {"min_person_distance", "closest approach of a person"},
    {"person_collisions", "collisions with people"},
    {"min_robot_distance", "closest approach of another robot"},
    {"robot_collisions", "collisions with other robots"},
    {"wall", "wall-clock time of the run"},
}};

// The unit suffixes, longest first ("_mps" before "_s").
struct Suffix {
  std::string_view text;
  enum class Kind { kLength, kSpeed, kRad, kDeg, kSeconds, kShare } kind;
};
constexpr std::array<Suffix, 6> kSuffixes = {{{"_fraction", Suffix::Kind::kShare},
                                              {"_mps", Suffix::Kind::kSpeed},
                                              {"_rad", Suffix::Kind::kRad},
                                              {"_deg", Suffix::Kind::kDeg},
                                              {"_m", Suffix::Kind::kLength},
                                              {"_s", Suffix::Kind::kSeconds}}};

std::string Words(std::string_view name) {
  std::string out(name);
  for (char& c : out) {
    if (c == '_') c = ' ';
  }
  return out;
}

}  // namespace

MetricAxis DescribeMetric(std::string_view metric, double largest_abs) {
  MetricAxis axis;
  // A fleet's robot (or a unit) before the dot.
  std::string owner;
  if (const auto dot = metric.rfind('.'); dot != std::string_view::npos) {
    owner = std::string(metric.substr(0, dot));
    metric.remove_prefix(dot + 1);
  }
  std::string_view base = metric;
  const Suffix* suffix = nullptr;
  for (const Suffix& s : kSuffixes) {
    if (metric.size() > s.text.size() && metric.ends_with(s.text)) {
      suffix = &s;
      base = metric.substr(0, metric.size() - s.text.size());
      break;
    }
  }
  axis.caption = Words(base);
  for (const auto& [name, words] : kCaptions) {
    if (base == name) axis.caption = std::string(words);
  }
  if (base.starts_with("robot_") && base.ends_with("_collisions") && base != "robot_collisions") {
    axis.caption = "collisions with " + std::string(base.substr(6, base.size() - 6 - 11));
  } else if (base.ends_with("_time_waited")) {
    axis.caption = std::string(base.substr(0, base.size() - 12)) + ": time waited for robots";
  } else if (base.ends_with("_fallback")) {
    axis.caption =
        std::string(base.substr(0, base.size() - 9)) + ": share of the run on its fallback";
  }
  if (!owner.empty()) axis.caption = owner + ": " + axis.caption;
  if (suffix == nullptr) return axis;
  const bool small = largest_abs < 1.0;
  switch (suffix->kind) {
    case Suffix::Kind::kLength:
      axis.unit = small ? "mm" : "m";
      axis.scale = small ? 1000.0 : 1.0;
      break;
    case Suffix::Kind::kSpeed:
      axis.unit = small ? "mm/s" : "m/s";
      axis.scale = small ? 1000.0 : 1.0;
      break;
    case Suffix::Kind::kRad:
      axis.unit = "deg";
      axis.scale = 180.0 / std::numbers::pi;
      break;
    case Suffix::Kind::kDeg:
      axis.unit = "deg";
      break;
    case Suffix::Kind::kSeconds:
      axis.unit = "s";
      break;
    case Suffix::Kind::kShare:
      axis.unit = "%";
      axis.scale = 100.0;
      break;
  }
  return axis;
}

}  // namespace linesim::plots
