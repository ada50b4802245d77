#include <algorithm>
#include <numbers>

#include "loader/assembly/concerns.h"
#include "models/angle.h"

namespace linesim::loader::assembly {

namespace {
using models::kDegToRad;
}  // namespace

void AddTask(SystemBuilder& b, const RobotFile& file, const StartPose& start, Signals& s,
             RobotInfo& info) {
  YamlReader& r = b.reader();
  const YAML::Node task =
      b.Section(b.root(), "", "task",
                {"type", "waypoints", "point", "speed_mps", "acceleration_mps2", "yaw_deg"});
  info.task = r.String(task, "task", "type", std::nullopt, {"path", "hold"});
  b.Unit(kPathFollower, "path_follower");
  // The robot's follower settings first: the task's own values (speed,
  // acceleration) override them.
  b.MergeSettings(kPathFollower, file.follower_settings, file.robot.file, "path_follower");
  YAML::Node p = b.Params(kPathFollower);
  const bool differential = file.robot.controller == models::ControllerKind::kDifferential;
  if (info.task == "path") {
    const YAML::Node waypoints = Child(task, "waypoints");
    if (!waypoints.IsDefined()) {
      r.Error(task, "task.waypoints", "missing required key: a list of points [x, y] (m)");
    } else if (r.ExpectSequence(waypoints, "task.waypoints")) {
      // A stated limit: the follower and the deviation unit each keep the
      // path (and the plots draw it), a few kB per point in all.
      constexpr std::size_t kMaxWaypoints = 10000;
      if (waypoints.size() < 2) {
        r.Error(waypoints, "task.waypoints", "expected at least two points [x, y]");
      } else if (waypoints.size() > kMaxWaypoints) {
        r.Error(waypoints, "task.waypoints",
                std::to_string(waypoints.size()) + " points: at most " +
                    std::to_string(kMaxWaypoints) + " (a path of 10 km at 1 m spacing)");
        return;
      }
      for (std::size_t i = 0; i < waypoints.size(); ++i) {
        if (auto pt = r.AsPoint(waypoints[i], JoinPath("task.waypoints", std::to_string(i)),
                                {-1e6, 1e6})) {
          info.path.push_back(*pt);
        }
      }
    }
    p["mode"] = "path";
    // Up to the robot's top speed (its description's path_follower.max_speed).
    const double top_mps =
        YamlReader::DecodeReal(Child(file.follower_settings, "max_speed")).value_or(0.0);
    p["speed"] =
        Num(r.Real(task, "task", "speed_mps", std::min(0.3, top_mps), {0.0, top_mps, true}));
  } else if (info.task == "hold") {
    std::array<double, 2> point{start.x_m, start.y_m};
    if (Child(task, "point").IsDefined()) {
      if (auto pt = r.AsPoint(Child(task, "point"), "task.point", {-1e6, 1e6})) point = *pt;
    }
    info.path.push_back(point);
    p["mode"] = "hold";
  }
  if (Child(task, "acceleration_mps2").IsDefined()) {
    p["acceleration"] = Num(r.Real(task, "task", "acceleration_mps2", 0.3, {0.0, 10.0, true}));
    b.Derived("units.path_follower.parameters.acceleration", task, "task", "acceleration_mps2");
  }
  if (differential) {
    // A differential base heads along its motion; it holds no heading.
    p["base"] = "differential";
    if (Child(task, "yaw_deg").IsDefined()) {
      r.Error(Child(task, "yaw_deg"), "task.yaw_deg",
              "robot '" + file.robot.name +
                  "' is a differential base: it cannot hold a heading "
                  "while it moves; leave task.yaw_deg out");
    }
  } else {
    // An omnidirectional base keeps this heading while it moves.
    p["heading"] = Num(Child(task, "yaw_deg").IsDefined()
                           ? r.Real(task, "task", "yaw_deg", 0.0, {-360.0, 360.0}) * kDegToRad
                           : start.yaw_rad);
  }
  p["waypoints"] = PointList(info.path);

  b.RequireParameters(kPathFollower, file.follower_settings, file.robot.file, "path_follower");

  b.Connect(s.position, Signal(kPathFollower, "position"));
  b.Connect(s.yaw, Signal(kPathFollower, "yaw"));
  b.Connect(Signal(kPathFollower, "velocity_command"), s.velocity_command_input);
  b.Connect(Signal(kPathFollower, "yaw_rate_command"), s.yaw_rate_command_input);
  for (const char* v : {"velocity_command", "yaw_rate_command"}) {
    s.recorded.push_back(Signal(kPathFollower, v));
  }
}

}  // namespace linesim::loader::assembly
