#include "loader/assembly/people.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>

#include "cosim/system.h"
#include "models/angle.h"
#include "models/person.h"
#include "models/polygon.h"

namespace linesim::loader::assembly {

namespace {

constexpr int kCylindersPerWorker = 3;  // people::WorkerUnit: two legs, a torso
constexpr int kCylinderValues = 7;

// A polygon [[x, y], ...] (m, base_link) of at least 3 corners at `key` of
// `item`, moved into the frame of a scanner mounted at (mx, my) with yaw
// `myaw` in base_link.
YAML::Node ReadPolygonInScanner(YamlReader& r, const YAML::Node& item, const std::string& path,
                                const std::string& key, bool required, double mx, double my,
                                double myaw) {
  const YAML::Node list = Child(item, key);
  const std::string full = JoinPath(path, key);
  if (!list.IsDefined() || list.IsNull()) {
    if (required) r.Error(item, full, "missing required key: a polygon [[x, y], ...] (m, base_link)");
    return YAML::Node();
  }
  if (!r.ExpectSequence(list, full)) return YAML::Node();
  if (list.size() < 3) {
    r.Error(list, full, "a field needs at least 3 corners [x, y] (m, base_link)");
    return YAML::Node();
  }
  std::vector<std::array<double, 2>> given;
  for (std::size_t i = 0; i < list.size(); ++i) {
    if (auto p = r.AsPoint(list[i], JoinPath(full, std::to_string(i)), {-100.0, 100.0})) {
      given.push_back(*p);
    }
  }
  if (given.size() != list.size()) return YAML::Node();
  // Checked as written (base_link): a degenerate polygon holds no point, a
  // field that silently never stops the robot.
  if (const auto problem = models::PolygonProblem(given)) {
    r.Error(list, full, "the field " + *problem);
    return YAML::Node();
  }
  std::vector<std::array<double, 2>> corners;
  const double c = std::cos(myaw), s = std::sin(myaw);
  for (const auto& p : given) {
    const double dx = p[0] - mx, dy = p[1] - my;
    corners.push_back({c * dx + s * dy, -s * dx + c * dy});
  }
  return PointList(corners);
}

// How far forward a polygon of the scanner's frame (as ReadPolygonInScanner
// wrote it) reaches in base_link: its corners' largest x; NaN for none.
double ReachInBaseLink(const YAML::Node& polygon, const models::SensorMount& laser) {
  if (!polygon.IsDefined() || !polygon.IsSequence() || polygon.size() == 0) return NAN;
  const double c = std::cos(laser.yaw_rad), s = std::sin(laser.yaw_rad);
  double reach = -INFINITY;
  for (const auto& p : polygon) {
    const double x = p[0].as<double>(), y = p[1].as<double>();
    reach = std::max(reach, laser.x_m + c * x - s * y);
  }
  return reach;
}

const models::SensorMount* FindLaser(const Signals& s, const std::string& name) {
  for (const auto& m : s.sensors) {
    if (m.kind == "laser_scanner" && (name.empty() || m.name == name)) return &m;
  }
  return nullptr;
}

}  // namespace

void AddSafetyFields(SystemBuilder& b, const RobotFile& robot, Signals& s, RobotInfo& info) {
  YamlReader& r = b.reader();
  const YAML::Node safety = Child(b.root(), "safety");
  if (!safety.IsDefined() || safety.IsNull()) return;
  if (!r.ExpectMap(safety, "safety")) return;
  r.CheckKeys(safety, "safety", {"enabled", "scanner", "field_sets", "parameters"});
  // enabled: false keeps the section but takes the safety function out (the
  // same run without it, for comparison).
  if (!r.Boolean(safety, "safety", "enabled", true)) return;
  // The vehicle's configuration is the robot file's `safety:`; a key the
  // scenario's section gives replaces it (parameters key by key). A
  // problem is reported in the file the value is in.
  const YAML::Node vehicle = robot.safety;
  if (vehicle.IsMap()) {
    const YamlReader::InFile in(r, robot.robot.file);
    r.CheckKeys(vehicle, "safety", {"scanner", "field_sets", "parameters"});
  }
  struct Source {
    YAML::Node section;
    std::optional<YamlReader::InFile> in;  // while reading the robot file's
  };
  const auto from = [&](const char* key, Source& src) {
    const bool robot_file = !Child(safety, key).IsDefined() && vehicle.IsMap() &&
                            Child(vehicle, key).IsDefined();
    src.section = robot_file ? vehicle : safety;
    if (robot_file) src.in.emplace(r, robot.robot.file);
  };

  const models::SensorMount* laser = nullptr;
  {
    Source src;
    from("scanner", src);
    const YAML::Node section = src.section;
    const std::string scanner = r.String(section, "safety", "scanner", "");
    laser = FindLaser(s, scanner);
    const YAML::Node at = Child(section, "scanner").IsDefined() ? Child(section, "scanner") : section;
    if (laser == nullptr) {
      r.Error(at, "safety.scanner",
              scanner.empty() ? "the robot has no enabled laser scanner for the safety fields"
                              : "no enabled laser scanner '" + scanner + "' on the robot");
      return;
    }
    // The unit's beam geometry defaults are the S300's (the device whose
    // field sets these are).
    if (laser->model != "sick_s300") {
      r.Error(at, "safety.scanner",
              "the safety fields are the SICK S300's: scanner '" + laser->name + "' is model '" +
                  laser->model + "', expected sick_s300");
      return;
    }
  }
  b.Unit(kSafety, "safety_field");
  b.SetStep(kSafety, b.ControlPeriod());
  Parameters& p = b.Params(kSafety);
  p["beam_count"] = 541;
  YAML::Node out_sets(YAML::NodeType::Sequence);
  {
    Source src;
    from("field_sets", src);
    const YAML::Node sets = Child(src.section, "field_sets");
    if (!sets.IsDefined()) {
      r.Error(safety, "safety.field_sets",
              "missing required key: a list of {max_speed_mps, protective, warning} (here or in "
              "the robot file's safety section)");
    } else if (r.ExpectSequence(sets, "safety.field_sets")) {
      if (sets.size() == 0) r.Error(sets, "safety.field_sets", "expected at least one field set");
      for (std::size_t i = 0; i < sets.size(); ++i) {
        const std::string path = JoinPath("safety.field_sets", std::to_string(i));
        const YAML::Node item = sets[i];
        if (!r.ExpectMap(item, path)) continue;
        r.CheckKeys(item, path, {"max_speed_mps", "protective", "warning"});
        YAML::Node set;
        set["max_speed_mps"] =
            Num(r.Real(item, path, "max_speed_mps", std::nullopt, {0.0, 100.0}));
        set["protective"] = ReadPolygonInScanner(r, item, path, "protective", true, laser->x_m,
                                                 laser->y_m, laser->yaw_rad);
        const YAML::Node warning = ReadPolygonInScanner(r, item, path, "warning", false,
                                                        laser->x_m, laser->y_m, laser->yaw_rad);
        if (warning.IsDefined()) set["warning"] = warning;
        out_sets.push_back(set);
        info.field_reach_m.push_back(
            {ReachInBaseLink(set["protective"], *laser), ReachInBaseLink(warning, *laser)});
      }
    }
  }
  p["field_sets"] = ParameterValue(out_sets);
  // The robot file's parameters, then the scenario's over them.
  const std::string prefix = JoinPath(JoinPath("units", kSafety), "parameters");
  const YAML::Node vehicle_params = Child(vehicle, "parameters");
  if (vehicle_params.IsDefined() && !vehicle_params.IsNull()) {
    const YamlReader::InFile in(r, robot.robot.file);
    if (r.ExpectMap(vehicle_params, "safety.parameters")) {
      for (const auto& kv : vehicle_params) {
        const std::string key = kv.first.Scalar();
        p[key] = ParameterValue(kv.second);
        b.Origin(JoinPath(prefix, key),
                 {kv.second, JoinPath("safety.parameters", key), robot.robot.file});
      }
    }
  }
  const YAML::Node own = Child(safety, "parameters");
  if (own.IsDefined() && !own.IsNull() && r.ExpectMap(own, "safety.parameters")) {
    for (const auto& kv : own) {
      const std::string key = kv.first.Scalar();
      p[key] = ParameterValue(kv.second);
      b.Derived(JoinPath(prefix, key), own, "safety.parameters", key);
    }
  }
  b.Connect(Signal(laser->name, "ranges"), Signal(kSafety, "ranges"));
  b.Connect(Signal(laser->name, "scan_count"), Signal(kSafety, "scan_count"));
  // The safety unit takes the wheel controller's command inputs over.
  b.Connect(Signal(kSafety, "velocity_command_out"), s.velocity_command_input);
  b.Connect(Signal(kSafety, "yaw_rate_command_out"), s.yaw_rate_command_input);
  s.velocity_command_input = Signal(kSafety, "velocity_command");
  s.yaw_rate_command_input = Signal(kSafety, "yaw_rate_command");
}

namespace {

// The worker's body as workers.N.parameters give it, the defaults
// (models/person.h) otherwise: a value that is no number is the worker
// unit's to report.
models::PersonBody BodyOf(const YAML::Node& params) {
  models::PersonBody body;
  const auto number = [&](const char* key, double& into) {
    double x = 0.0;
    const YAML::Node v = Child(params, key);
    if (v.IsDefined() && v.IsScalar() && YAML::convert<double>::decode(v, x) && std::isfinite(x)) {
      into = x;
    }
  };
  number("leg_radius", body.leg_radius_m);
  number("leg_spacing", body.leg_spacing_m);
  number("crotch_height", body.crotch_height_m);
  number("torso_radius", body.torso_radius_m);
  number("stature", body.stature_m);
  return body;
}

// The worker's heading at the start: its first segment's, or initial_yaw
// (deg) when it stands at one point.
double StartYaw(const std::vector<std::array<double, 2>>& points, const YAML::Node& params) {
  if (points.size() >= 2 && points[1] != points[0]) {
    return std::atan2(points[1][1] - points[0][1], points[1][0] - points[0][0]);
  }
  double deg = 0.0;
  const YAML::Node v = Child(params, "initial_yaw");
  if (v.IsDefined() && v.IsScalar() && YAML::convert<double>::decode(v, deg) &&
      std::isfinite(deg)) {
    return deg * models::kDegToRad;
  }
  return 0.0;
}

// Person contact is not modelled (docs/scenarios.md, "Workers"): a worker
// that would start inside or touching the robot's body is refused at its
// first waypoint, naming the robot.
void CheckStartClear(SystemBuilder& b, const RobotFile& robot, const RobotInfo& info,
                     const std::string& name, const YAML::Node& waypoints,
                     const std::string& wp_path, const std::vector<std::array<double, 2>>& points,
                     const YAML::Node& params) {
  const models::BodyDescription& body = robot.robot.body;
  if (points.empty() || !(body.length_m > 0.0 && body.width_m > 0.0)) return;
  const double box[models::MovingBox::kValues] = {info.start_pose[0],
                                                  info.start_pose[1],
                                                  info.start_pose[2],
                                                  0.0,
                                                  0.0,
                                                  0.0,
                                                  body.length_m,
                                                  body.width_m,
                                                  body.com_height_m - 0.5 * body.height_m,
                                                  body.com_height_m + 0.5 * body.height_m};
  const auto person =
      models::StandingPerson(BodyOf(params), points[0][0], points[0][1], StartYaw(points, params));
  double nearest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < models::kPersonCylinders; ++k) {
    nearest = std::min(nearest, models::CylinderBoxDistance(
                                    person.data() + k * models::MovingCylinder::kValues, box));
  }
  if (nearest > 0.0) return;
  const std::string robot_name = info.name.empty() ? "the robot" : "robot '" + info.name + "'";
  b.reader().Error(waypoints[0], JoinPath(wp_path, "0"),
                   "worker '" + name + "' would start inside or touching the body of " +
                       robot_name + " (at " + b.reader().Scoped("robot.pose") +
                       "): contact with a person is not modelled, so a worker must start clear "
                       "of every robot");
}

// pause_s: one number for every waypoint, or one per waypoint.
void ReadPauses(YamlReader& r, const YAML::Node& item, const std::string& path,
                std::size_t waypoint_count, Parameters& p) {
  const YAML::Node pause = Child(item, "pause_s");
  if (!pause.IsDefined()) return;
  const std::string pause_path = JoinPath(path, "pause_s");
  if (pause.IsSequence()) {
    if (pause.size() != waypoint_count) {
      r.Error(pause, pause_path,
              "expected one pause per waypoint (" + std::to_string(waypoint_count) + "), got " +
                  std::to_string(pause.size()));
    }
    std::vector<double> v;
    for (std::size_t k = 0; k < pause.size(); ++k) {
      v.push_back(
          r.AsReal(pause[k], JoinPath(pause_path, std::to_string(k)), {0.0, 1e7}).value_or(0.0));
    }
    p["pause"] = v;
  } else {
    const double v = r.Real(item, path, "pause_s", 0.0, {0.0, 1e7});
    p["pause"] = std::vector<double>(waypoint_count, v);
  }
}

// Worker i of `workers:` as a worker unit, its values' origins at the
// worker's keys (so that the unit's complaints are reported there); its
// name, or nothing when the item is refused.
std::optional<std::string> AddWorker(SystemBuilder& b, const RobotFile& robot,
                                     const RobotInfo& info, const YAML::Node& item, std::size_t i) {
  YamlReader& r = b.reader();
  const std::string path = JoinPath("workers", std::to_string(i));
  if (!r.ExpectMap(item, path)) return std::nullopt;
  r.CheckKeys(item, path, {"name", "waypoints", "pause_s", "start_time_s", "parameters"});
  const std::string name = r.String(item, path, "name", "worker_" + std::to_string(i));
  const YAML::Node name_node = Child(item, "name").IsDefined() ? Child(item, "name") : item;
  if (!cosim::IsIdentifier(name)) {
    r.Error(name_node, JoinPath(path, "name"),
            "worker name '" + name +
                "' is not valid: expected letters, digits and _ (it names "
                "the worker's unit, its columns and its metrics)");
    return std::nullopt;
  }
  if (b.HasUnit(name)) {
    r.Error(name_node, JoinPath(path, "name"), "'" + name + "' is already the name of a unit");
    return std::nullopt;
  }
  const YAML::Node waypoints = Child(item, "waypoints");
  const std::string wp_path = JoinPath(path, "waypoints");
  if (!waypoints.IsDefined()) {
    r.Error(item, wp_path, "missing required key: a list of points [x, y] (m, map)");
    return std::nullopt;
  }
  if (!r.ExpectSequence(waypoints, wp_path)) return std::nullopt;
  if (waypoints.size() == 0) r.Error(waypoints, wp_path, "expected at least one point [x, y]");
  std::vector<std::array<double, 2>> points;
  for (std::size_t k = 0; k < waypoints.size(); ++k) {
    if (auto q = r.AsPoint(waypoints[k], JoinPath(wp_path, std::to_string(k)), {-1e6, 1e6})) {
      points.push_back(*q);
    }
  }
  const YAML::Node own = Child(item, "parameters");
  CheckStartClear(b, robot, info, name, waypoints, wp_path, points, own);
  b.Unit(name, "worker");
  Parameters& p = b.Params(name);
  const std::string prefix = JoinPath(JoinPath("units", name), "parameters");
  p["waypoints"] = points;
  b.Origin(JoinPath(prefix, "waypoints"), {waypoints, wp_path, ""});
  // The worker knows where the robot is (it yields to it with a
  // stop_distance; a fleet's are connected by the fleet).
  p["robots"] = 1;
  b.Connect(Signal(kChassis, "body_box"), Signal(name, "robots"));
  ReadPauses(r, item, path, points.size(), p);
  if (Child(item, "pause_s").IsDefined()) {
    b.Derived(JoinPath(prefix, "pause"), item, path, "pause_s");
  }
  if (Child(item, "start_time_s").IsDefined()) {
    p["start_time"] = r.Real(item, path, "start_time_s", 0.0, {0.0, 1e7});
    b.Derived(JoinPath(prefix, "start_time"), item, path, "start_time_s");
  }
  if (own.IsDefined() && !own.IsNull() && r.ExpectMap(own, JoinPath(path, "parameters"))) {
    for (const auto& kv : own) {
      const std::string key = kv.first.Scalar();
      p[key] = ParameterValue(kv.second);
      b.Derived(JoinPath(prefix, key), own, JoinPath(path, "parameters"), key);
    }
  }
  return name;
}

}  // namespace

void AddWorkers(SystemBuilder& b, const RobotFile& robot, Signals& s, RobotInfo& info) {
  YamlReader& r = b.reader();
  const auto add = [&](const std::string& name, const Port& of, cosim::Reduction reduce) {
    b.Metric(name, of, reduce);
  };
  if (b.HasUnit(kSafety)) {
    b.Connect(Signal(kPathFollower, "done"), Signal(kSafety, "task_done"));
    for (const char* v : {"protective_clear", "warning_clear", "speed_cap", "field_set"}) {
      s.recorded.push_back(Signal(kSafety, v));
    }
    s.recorded.push_back(Signal(kChassis, "linear_velocity"));
    add("protective_stops", Signal(kSafety, "protective_stops"), cosim::Reduction::kFinal);
    add("time_stopped_s", Signal(kSafety, "time_stopped"), cosim::Reduction::kFinal);
    add("task_time_s", Signal(kSafety, "task_time"), cosim::Reduction::kFinal);
    info.velocity_x_column = Element(kChassis, "linear_velocity", 0).Name();
    info.velocity_y_column = Element(kChassis, "linear_velocity", 1).Name();
    info.speed_cap_column = Signal(kSafety, "speed_cap").Name();
    info.protective_column = Signal(kSafety, "protective_clear").Name();
    info.warning_column = Signal(kSafety, "warning_clear").Name();
    info.field_set_column = Signal(kSafety, "field_set").Name();
  }

  const YAML::Node list = Child(b.root(), "workers");
  if (!list.IsDefined() || list.IsNull()) return;
  if (!r.ExpectSequence(list, "workers")) return;
  std::vector<std::string> names;
  for (std::size_t i = 0; i < list.size(); ++i) {
    if (auto name = AddWorker(b, robot, info, list[i], i)) names.push_back(std::move(*name));
  }
  if (names.empty()) return;

  // Every laser on the robot sees every worker's cylinders, at each beam's
  // time (units/sensors/ray_scene.h). The body does not collide with them:
  // contact with a person is not modelled (no force either way); the
  // person_clearance unit counts and times it and warns.
  const int per_worker = kCylindersPerWorker * kCylinderValues;
  std::vector<std::string> takers;
  for (const auto& m : s.sensors) {
    if (m.kind == "laser_scanner") takers.push_back(m.name);
  }
  takers.push_back(kPersonClearance);
  // The body's distance from the people: the clearance unit's box.
  const models::BodyDescription& body = robot.robot.body;
  b.Unit(kPersonClearance, "person_clearance");
  Parameters& c = b.Params(kPersonClearance);
  c["workers"] = static_cast<int>(names.size());
  YAML::Node worker_names(YAML::NodeType::Sequence);
  for (const auto& name : names) worker_names.push_back(name);
  c["worker_names"] = ParameterValue(worker_names);
  c["body_length"] = body.length_m;
  c["body_width"] = body.width_m;
  // The body box where the robot file puts it (the chassis's; flat floor).
  c["body_z_min"] = body.bottom_m;
  c["body_z_max"] = body.top_m();
  // A bad body is reported where the robot file gives it.
  const std::string prefix = JoinPath(JoinPath("units", kPersonClearance), "parameters");
  b.Origin(JoinPath(prefix, "body_length"), robot.At("body.length_m"));
  b.Origin(JoinPath(prefix, "body_width"), robot.At("body.width_m"));
  b.Origin(JoinPath(prefix, "body_z_min"), robot.At("body.bottom_m"));
  b.Origin(JoinPath(prefix, "body_z_max"), robot.At("body.height_m"));
  b.Connect(Signal(kChassis, "position_3d"), Signal(kPersonClearance, "position_3d"));
  b.Connect(Signal(kChassis, "orientation"), Signal(kPersonClearance, "orientation"));
  for (const auto& unit : takers) {
    if (unit != kPersonClearance) {
      b.Params(unit)["moving_cylinders"] = static_cast<int>(names.size()) * kCylindersPerWorker;
    }
    const std::string input = unit == kPersonClearance ? "cylinders" : "moving_cylinders";
    for (std::size_t w = 0; w < names.size(); ++w) {
      for (int j = 0; j < per_worker; ++j) {
        b.Connect(Element(names[w], "cylinders", static_cast<std::size_t>(j)),
                  Element(unit, input, w * per_worker + static_cast<std::size_t>(j)));
      }
    }
  }
  for (std::size_t w = 0; w < names.size(); ++w) {
    s.recorded.push_back(Signal(names[w], "pose"));
    info.worker_columns.emplace_back(Element(names[w], "pose", 0).Name(),
                                     Element(names[w], "pose", 1).Name());
    s.recorded.push_back(Signal(names[w], "legs"));
    info.worker_names.push_back(names[w]);
    std::array<std::string, 4> legs;
    for (std::size_t k = 0; k < 4; ++k) legs[k] = Element(names[w], "legs", k).Name();
    info.worker_leg_columns.push_back(legs);
    add(names[w] + "_time_waited_s", Signal(names[w], "time_waited"), cosim::Reduction::kFinal);
    add("robot_" + names[w] + "_collisions", Element(kPersonClearance, "worker_collisions", w),
        cosim::Reduction::kFinal);
  }
  s.recorded.push_back(Signal(kPersonClearance, "distance"));
  if (b.HasUnit(kSafety)) info.person_distance_column = Signal(kPersonClearance, "distance").Name();
  add("min_person_distance_m", Signal(kPersonClearance, "min_distance"), cosim::Reduction::kFinal);
  add("person_collisions", Signal(kPersonClearance, "collisions"), cosim::Reduction::kFinal);
  add("person_contact_time_s", Signal(kPersonClearance, "contact_time"), cosim::Reduction::kFinal);
}

}  // namespace linesim::loader::assembly
