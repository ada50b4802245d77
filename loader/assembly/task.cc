#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include "loader/assembly/concerns.h"
#include "loader/route_graph_file.h"
#include "models/angle.h"
#include "models/polynomial_path.h"

namespace linesim::loader::assembly {

namespace {
using models::kDegToRad;

// The keys only a route task takes, and those only path and hold take.
const std::vector<std::string> kRouteKeys = {"graph", "route", "gains", "deceleration_mps2"};
const std::vector<std::string> kPathKeys = {"waypoints", "point", "acceleration_mps2", "yaw_deg"};
// task.gains: the route follower's parameters a scenario may set there.
const std::vector<std::string> kRouteGains = {"k_p_distance",
                                              "k_i_distance",
                                              "k_p_orientation",
                                              "k_i_orientation",
                                              "distance_integral",
                                              "max_distance_integral_rate",
                                              "max_orientation_integral_rate",
                                              "stop_tolerance"};

// The robot's top speed (its description's path_follower.max_speed), when
// it is a positive number. Another value bounds nothing here: the path
// follower's parameter check reports it where it was written (the robot
// file's key), not at task.speed_mps, which was not wrong.
std::optional<double> TopSpeed(const RobotFile& file) {
  const auto top = YamlReader::DecodeReal(Child(file.follower_settings, "max_speed"));
  if (top && std::isfinite(*top) && *top > 0.0) return top;
  return std::nullopt;
}
// task.speed_mps: at most the top speed; 0.3 m/s by default, or the top
// speed when lower.
Range SpeedRange(const RobotFile& file) {
  return {0.0, TopSpeed(file).value_or(std::numeric_limits<double>::infinity()), true};
}
double DefaultSpeed(const RobotFile& file) { return std::min(0.3, TopSpeed(file).value_or(0.3)); }

// task.type route: paper 2's parametric trajectory controller (the
// `route_follower` unit, under the follower's unit name) along a route
// through a route graph (loader/route_graph_file.h).
void AddRoute(SystemBuilder& b, const RobotFile& file, const YAML::Node& task, Signals& s,
              RobotInfo& info) {
  YamlReader& r = b.reader();
  for (const std::string& key : kPathKeys) {
    const YAML::Node node = Child(task, key);
    if (!node.IsDefined()) continue;
    r.Error(node, JoinPath("task", key),
            key == "yaw_deg"
                ? "a route steers the robot's heading along the path (paper 2 Eqs. 10-13): it "
                  "holds no heading; leave task.yaw_deg out"
                : "only for task.type path or hold: a route's path is task.graph and task.route");
  }
  b.Unit(kPathFollower, "route_follower");
  Parameters& p = b.Params(kPathFollower);

  // The graph and the route through it.
  std::vector<models::PolynomialSegment> segments;
  const YAML::Node graph_node = Child(task, "graph");
  if (!graph_node.IsDefined() || graph_node.IsNull()) {
    r.Error(task, "task.graph",
            "missing required key: a route graph (a name in models/graphs/ or a path relative to "
            "the scenario)");
  } else if (const auto name = r.AsString(graph_node, "task.graph")) {
    if (auto graph = ReadRouteGraphModel(r, graph_node, "task.graph", *name, r.file())) {
      const YAML::Node route_node = Child(task, "route");
      if (auto route = RouteSegments(r, *graph, route_node, "task.route")) {
        segments = std::move(*route);
        // Where the route ends: the last node's pose (the work pose the
        // final pose error is measured against).
        const std::string last = route_node[route_node.size() - 1].Scalar();
        for (const auto& node : graph->nodes) {
          if (node.name == last) s.route_end = {node.x_m, node.y_m, node.yaw_rad};
        }
        s.route_maps = graph->maps;
      }
    }
  }

  // Speed: the constant V of Eq. 5, up to the robot's top speed.
  const double speed = r.Real(task, "task", "speed_mps", DefaultSpeed(file), SpeedRange(file));
  p["speed"] = speed;
  b.Derived("units.path_follower.parameters.speed", task, "task", "speed_mps");
  // The robot's yaw-rate limit (its description's path_follower.max_yaw_rate).
  if (const YAML::Node limit = Child(file.follower_settings, "max_yaw_rate"); limit.IsDefined()) {
    p["max_yaw_rate"] = ParameterValue(limit);
    b.Origin("units.path_follower.parameters.max_yaw_rate",
             {limit, "path_follower.max_yaw_rate", file.robot.file});
  }
  // K_P,D keeps the design of the unit's defaults (a critically damped
  // double pole at 1.5 rad/s of e'' + K_P,theta e' + V K_P,D e = 0) at this
  // speed: K_P,D = 1.5^2 / V, unless task.gains gives it.
  if (speed > 0.0) {
    p["k_p_distance"] = 1.5 * 1.5 / speed;
    b.Derived("units.path_follower.parameters.k_p_distance", task, "task", "speed_mps");
  }
  const YAML::Node gains = b.Section(task, "task", "gains", kRouteGains);
  for (const std::string& key : kRouteGains) {
    const YAML::Node value = Child(gains, key);
    if (!value.IsDefined()) continue;
    p[key] = ParameterValue(value);
    b.Derived(JoinPath("units.path_follower.parameters", key), gains, "task.gains", key);
  }
  if (Child(task, "deceleration_mps2").IsDefined()) {
    p["deceleration"] = r.Real(task, "task", "deceleration_mps2", 0.25, {0.0, 10.0, true});
    b.Derived("units.path_follower.parameters.deceleration", task, "task", "deceleration_mps2");
  }

  // The segments, and the path they draw for the plots and the deviation
  // (sampled every 2 cm: a chord is off a curve of curvature k by k h^2 / 8,
  // 0.05 mm at k = 1/m; coarser on a route longer than 180 m, to stay within
  // the 10000 points of a path).
  YAML::Node list(YAML::NodeType::Sequence);
  double length_m = 0.0;
  for (const auto& segment : segments) {
    YAML::Node item;
    item["x"] = List(segment.x);
    item["y"] = List(segment.y);
    item["map"] = segment.map;
    list.push_back(item);
    length_m += models::SegmentArcLength(segment, 0.0, 1.0);
  }
  p["segments"] = ParameterValue(list);
  b.Derived("units.path_follower.parameters.segments", task, "task", "route");
  if (!segments.empty()) {
    info.path = models::SamplePolynomialPath(segments, std::max(0.02, length_m / 9000.0),
                                             9000 / segments.size() + 4);
  }

  b.Connect(s.position, Signal(kPathFollower, "position"));
  b.Connect(s.yaw, Signal(kPathFollower, "yaw"));
  b.Connect(Signal(kPathFollower, "velocity_command"), s.velocity_command_input);
  b.Connect(Signal(kPathFollower, "yaw_rate_command"), s.yaw_rate_command_input);
  s.map_index_output = Signal(kPathFollower, "map_index");
  s.route_done = Signal(kPathFollower, "done");
  info.task_done_column = s.route_done.Name();
  for (const char* v : {"velocity_command", "yaw_rate_command", "distance_error",
                        "orientation_error", "segment", "map_index", "done"}) {
    s.recorded.push_back(Signal(kPathFollower, v));
  }
}
}  // namespace

void AddTask(SystemBuilder& b, const RobotFile& file, const StartPose& start, Signals& s,
             RobotInfo& info) {
  YamlReader& r = b.reader();
  const YAML::Node task = b.Section(b.root(), "", "task",
                                    {"type", "waypoints", "point", "speed_mps", "acceleration_mps2",
                                     "yaw_deg", "graph", "route", "gains", "deceleration_mps2"});
  info.task = r.String(task, "task", "type", std::nullopt, {"path", "hold", "route"});
  if (info.task == "route") {
    AddRoute(b, file, task, s, info);
    return;
  }
  for (const std::string& key : kRouteKeys) {
    if (Child(task, key).IsDefined()) {
      r.Error(Child(task, key), JoinPath("task", key), "only for task.type route");
    }
  }
  b.Unit(kPathFollower, "path_follower");
  // The robot's follower settings first: the task's own values (speed,
  // acceleration) override them.
  b.MergeSettings(kPathFollower, file.follower_settings, file.robot.file, "path_follower");
  Parameters& p = b.Params(kPathFollower);
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
    // Up to the robot's top speed.
    p["speed"] = r.Real(task, "task", "speed_mps", DefaultSpeed(file), SpeedRange(file));
  } else if (info.task == "hold") {
    std::array<double, 2> point{start.x_m, start.y_m};
    if (Child(task, "point").IsDefined()) {
      if (auto pt = r.AsPoint(Child(task, "point"), "task.point", {-1e6, 1e6})) point = *pt;
    }
    info.path.push_back(point);
    p["mode"] = "hold";
  }
  if (Child(task, "acceleration_mps2").IsDefined()) {
    p["acceleration"] = r.Real(task, "task", "acceleration_mps2", 0.3, {0.0, 10.0, true});
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
    p["heading"] = Child(task, "yaw_deg").IsDefined()
                       ? r.Real(task, "task", "yaw_deg", 0.0, {-360.0, 360.0}) * kDegToRad
                       : start.yaw_rad;
  }
  p["waypoints"] = info.path;
  // A problem the follower finds with a waypoint (one that repeats the one
  // before it) is reported at the point the user wrote.
  if (const YAML::Node written = Child(task, "waypoints");
      info.task == "path" && written.IsSequence() && written.size() == info.path.size()) {
    for (std::size_t i = 0; i < written.size(); ++i) {
      const std::string index = std::to_string(i);
      b.Origin(JoinPath("units.path_follower.parameters.waypoints", index),
               {written[i], JoinPath("task.waypoints", index), ""});
    }
  }

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
