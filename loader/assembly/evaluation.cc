#include "cosim/time.h"
#include "loader/assembly/concerns.h"

namespace linesim::loader::assembly {

void AddEvaluation(SystemBuilder& b, Signals& s, RobotInfo& info) {
  // The deviation is measured on the ground truth, whatever the robot
  // believes.
  b.Unit(kDeviation, "path_deviation");
  YAML::Node waypoints(YAML::NodeType::Sequence);
  waypoints.SetStyle(YAML::EmitterStyle::Flow);
  for (const auto& pt : info.path) waypoints.push_back(List({pt[0], pt[1]}));
  b.Params(kDeviation)["path"] = waypoints;
  b.Connect(s.true_position, Signal(kDeviation, "position"));
  s.recorded.push_back(Signal(kDeviation, "deviation"));

  YAML::Node metrics(YAML::NodeType::Sequence);
  const YAML::Node extra = Child(b.root(), "metrics");
  if (extra.IsDefined() && !extra.IsNull() && b.reader().ExpectSequence(extra, "metrics")) {
    for (const auto& m : extra) metrics.push_back(m);
  }
  const auto add = [&](const char* name, const std::string& of, const char* reduce) {
    YAML::Node m;
    m["name"] = name;
    m["of"] = of;
    m["reduce"] = reduce;
    metrics.push_back(m);
  };
  const std::string deviation = Signal(kDeviation, "deviation");
  if (info.task == "path") {
    add("max_path_deviation_m", deviation, "max");
    add("final_path_deviation_m", deviation, "final");
    add("final_progress_m", Signal(kDeviation, "progress"), "final");
  } else {
    add("max_position_drift_m", deviation, "max");
    add("final_position_drift_m", deviation, "final");
  }
  add("final_yaw_rad", s.true_yaw, "final");
  b.out()["metrics"] = metrics;
  info.error_column = deviation;
}

void AddRecording(SystemBuilder& b, const Signals& s, RobotInfo& info) {
  // The columns the plots read, as the recorder names them.
  info.x_column = Element(kChassis, "position", 0);
  info.y_column = Element(kChassis, "position", 1);
  info.yaw_column = Signal(kChassis, "yaw");
  for (std::size_t w = 0; w < static_cast<std::size_t>(info.wheel_count); ++w) {
    info.wheel_columns.emplace_back(Element(kChassis, "wheel_contact", 2 * w),
                                    Element(kChassis, "wheel_contact", 2 * w + 1));
  }
  for (std::size_t k = 0; k < s.belt_count; ++k) {
    info.belt_speed_columns.push_back(Element(kBelt, "speed", k));
    info.belt_on_columns.push_back(Element(kBelt, "on", k));
    info.belt_travel_columns.push_back(Element(kBelt, "travel", k));
  }

  if (Child(b.root(), "recording").IsDefined()) {
    b.out()["recording"] = Child(b.root(), "recording");
    return;
  }
  YAML::Node vars(YAML::NodeType::Sequence);
  vars.SetStyle(YAML::EmitterStyle::Flow);
  for (const auto& v : s.recorded) vars.push_back(v);
  b.out()["recording"]["variables"] = vars;
  // About 100 Hz is enough for the plots and keeps signals.csv small; it
  // must be a whole number of master steps (the master refuses bad steps).
  constexpr cosim::TimeNs kInterval = cosim::kNsPerSecond / 100;
  const cosim::TimeNs step = b.MasterStep();
  const cosim::TimeNs interval = step < kInterval ? (kInterval + step - 1) / step * step : step;
  b.out()["recording"]["interval_s"] = Num(cosim::NsToSeconds(interval));
}

}  // namespace linesim::loader::assembly
