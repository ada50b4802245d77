#include "loader/robot_scenario.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <set>

#include "cosim/system.h"
#include "cosim/variable_table.h"
#include "loader/assembly/concerns.h"
#include "loader/assembly/people.h"
#include "loader/robot_file.h"
#include "models/angle.h"
#include "models/moving_solids.h"

namespace linesim::loader {

namespace {

using models::kDegToRad;

// `units:` in a robot scenario adds to or overrides the expanded units, in
// the system-level shape units.NAME.{type, step_s, parameters}; its
// connections come before the expansion's, so that a problem found in them
// keeps the index it has in the file.
void Passthrough(assembly::SystemBuilder& b) {
  SystemSpec& spec = b.spec();
  ReadUnits(Child(b.root(), "units"), b.reader(), spec, false);
  std::vector<ConnectionSpec> expansion = std::move(spec.connections);
  spec.connections.clear();
  ReadConnections(Child(b.root(), "connections"), b.reader(), spec);
  spec.connections.insert(spec.connections.end(), expansion.begin(), expansion.end());
}

// A positive number the chassis will get, for the plots; nothing otherwise
// (the chassis unit reports a bad one).
std::optional<double> PositiveChassisValue(assembly::SystemBuilder& b, const std::string& chassis,
                                           const std::string& key) {
  const UnitSpec* unit = b.spec().FindUnit(chassis);
  const ParameterValue* value = unit ? unit->parameters.Find(key) : nullptr;
  const auto number = value ? value->Number() : std::nullopt;
  if (number && std::isfinite(*number) && *number > 0.0) return number;
  return std::nullopt;
}

// The robot's start position must be on the scene's floor and outside its
// obstacles and the objects its belts carry (at time zero): the physics
// would otherwise start with the body inside a solid.
void CheckStartPose(assembly::SystemBuilder& b, const models::Scene& scene,
                    const assembly::StartPose& start) {
  const YAML::Node pose = Child(Child(b.root(), "robot"), "pose");
  const auto refuse = [&](const std::string& message) {
    b.reader().Error(pose.IsDefined() ? pose : Child(b.root(), "robot"), "robot.pose", message);
  };
  const models::Floor& f = scene.floor;
  if (start.x_m < f.min_x_m || start.x_m > f.max_x_m || start.y_m < f.min_y_m ||
      start.y_m > f.max_y_m) {
    refuse("(" + cosim::FormatValue(start.x_m) + ", " + cosim::FormatValue(start.y_m) +
           ") m is off the scene's floor, x " + cosim::FormatValue(f.min_x_m) + " to " +
           cosim::FormatValue(f.max_x_m) + " m, y " + cosim::FormatValue(f.min_y_m) + " to " +
           cosim::FormatValue(f.max_y_m) + " m");
  }
  const auto inside = [&](const models::Solid& solid) {
    const double dx = start.x_m - solid.x_m, dy = start.y_m - solid.y_m;
    if (solid.kind == models::Solid::Kind::kCylinder) {
      return std::hypot(dx, dy) < solid.radius_m;
    }
    const double c = std::cos(solid.yaw_rad), s = std::sin(solid.yaw_rad);
    return std::abs(c * dx + s * dy) < 0.5 * solid.length_m &&
           std::abs(-s * dx + c * dy) < 0.5 * solid.width_m;
  };
  for (const auto& o : scene.obstacles) {
    if (inside(o.solid)) refuse("the robot would start inside obstacle '" + o.name + "'");
  }
  for (const auto& o : scene.carried) {
    // One waiting upstream of its belt is not there yet.
    const bool on_line = o.belt >= 0 && static_cast<std::size_t>(o.belt) < scene.belts.size() &&
                         models::CarriedTravelRange(
                             scene.belts[static_cast<std::size_t>(o.belt)].area, o.solid)[0] <= 0.0;
    if (on_line && inside(o.solid)) {
      refuse("the robot would start inside carried object '" + o.name + "'");
    }
  }
}

// The sections of a robot scenario that describe one robot: the shorthand's
// top-level keys, each robot's keys in `robots:`.
// The longest robot name of a fleet (see where it is checked).
constexpr std::size_t kMaxRobotName = 64;

const std::vector<std::string> kRobotSections = {"task",         "control", "sensing",
                                                 "localization", "sensors", "safety"};

// The concerns, one after another, for the robot at `robot` of b.root()
// (whose keys are `robot_keys`) on `scene`.
void AssembleRobot(assembly::SystemBuilder& b, const std::vector<std::string>& robot_keys,
                   const models::Scene& scene, RobotInfo& info) {
  YamlReader& r = b.reader();
  const YAML::Node robot = b.Section(b.root(), "", "robot", robot_keys);
  const YAML::Node pose = b.Section(robot, "robot", "pose", {"x_m", "y_m", "yaw_deg"});
  assembly::StartPose start;
  start.x_m = r.Real(pose, "robot.pose", "x_m", 0.0, {-1e6, 1e6});
  start.y_m = r.Real(pose, "robot.pose", "y_m", 0.0, {-1e6, 1e6});
  start.yaw_rad = r.Real(pose, "robot.pose", "yaw_deg", 0.0, {-360.0, 360.0}) * kDegToRad;
  const std::string model = r.String(robot, "robot", "model", std::nullopt);
  std::optional<RobotFile> file =
      model.empty() ? std::nullopt
                    : ReadRobotFile(r, Child(robot, "model"), "robot.model", model, r.file());
  // robot.payload replaces the robot file's payload (mass_kg 0: none).
  if (const YAML::Node p = Child(robot, "payload"); p.IsDefined() && !p.IsNull()) {
    const auto payload = ReadPayload(r, p, "robot.payload");
    if (file && payload) file->robot.payload = payload;
  }
  CheckStartPose(b, scene, start);
  info.start_pose = {start.x_m, start.y_m, start.yaw_rad};
  if (file) {
    assembly::Signals s = assembly::AddDriveTrain(b, *file, start, scene, info);
    assembly::AddLine(b, scene, s);
    assembly::AddSensors(b, *file, s);
    assembly::AddSensing(b, *file, start, scene, s);
    assembly::AddControl(b, *file, s);
    assembly::AddSafetyFields(b, *file, s, info);
    assembly::AddTask(b, *file, start, s, info);
    assembly::ConnectMapSwitch(b, s);
    assembly::AddBeaconGroundTruth(b, *file, start, scene, s);
    assembly::AddEvaluation(b, file->robot, s, info);
    assembly::AddWorkers(b, *file, s, info);
    assembly::AddRecording(b, s, info);
  }
}

// The body as the chassis unit `chassis` will get it (after `units:`).
void ReadBody(assembly::SystemBuilder& b, const std::string& chassis, RobotInfo& info) {
  info.body_length_m = PositiveChassisValue(b, chassis, "body_length");
  info.body_width_m = PositiveChassisValue(b, chassis, "body_width");
}

// figures: {bound: {value_m, label, over: run | final_pose}}: the published
// bound the run's figures judge it by (docs/scenarios.md). A bound on the
// final pose needs a task that finishes: a route.
RobotInfo::FigureBound ReadFigureBound(const YAML::Node& root, YamlReader& r,
                                       const RobotInfo& info) {
  RobotInfo::FigureBound bound;
  const YAML::Node figures = Child(root, "figures");
  if (!figures.IsDefined() || figures.IsNull() || !r.ExpectMap(figures, "figures")) return bound;
  r.CheckKeys(figures, "figures", {"bound"});
  const YAML::Node node = Child(figures, "bound");
  if (!node.IsDefined() || node.IsNull() || !r.ExpectMap(node, "figures.bound")) return bound;
  r.CheckKeys(node, "figures.bound", {"value_m", "label", "over"});
  bound.value_m = r.Real(node, "figures.bound", "value_m", std::nullopt, {0.0, 100.0, true});
  bound.label = r.String(node, "figures.bound", "label", std::nullopt);
  bound.final_pose =
      r.String(node, "figures.bound", "over", "run", {"run", "final_pose"}) == "final_pose";
  if (bound.final_pose && info.task_done_column.empty()) {
    r.Error(Child(node, "over"), "figures.bound.over",
            "a bound on the final pose needs a task that finishes (task.type: route)");
  }
  return bound;
}

// Every "unit.variable" column of `info` through `scope`.
void ScopeColumns(RobotInfo& info, const std::function<std::string(const std::string&)>& scope) {
  const auto one = [&](std::string& c) {
    if (!c.empty()) c = scope(c);
  };
  const auto all = [&](std::vector<std::string>& v) {
    for (auto& c : v) one(c);
  };
  for (std::string* c :
       {&info.x_column, &info.y_column, &info.yaw_column, &info.z_column,
        &info.wheel_surface_column, &info.motor_current_column, &info.error_column,
        &info.task_done_column, &info.field_set_column, &info.flow_reference_column,
        &info.velocity_x_column, &info.velocity_y_column, &info.speed_cap_column,
        &info.protective_column, &info.warning_column, &info.person_distance_column}) {
    one(*c);
  }
  for (auto& [x, y] : info.wheel_columns) one(x), one(y);
  for (auto& [x, y] : info.worker_columns) one(x), one(y);
  for (auto* v : {&info.belt_speed_columns, &info.belt_on_columns, &info.belt_travel_columns,
                  &info.flow_columns, &info.flow_truth_columns, &info.flow_filtered_columns}) {
    all(*v);
  }
  // A unit name, not a column: scoped the same way.
  if (!info.scan_unit.empty()) info.scan_unit = scope(info.scan_unit + ".x");
  if (!info.scan_unit.empty()) info.scan_unit.resize(info.scan_unit.size() - 2);
}

// Whether two robots' bodies (rectangles length x width at their start
// poses) overlap: separating axes of two rectangles.
bool BodiesOverlap(const RobotInfo& a, const RobotInfo& b) {
  if (!a.body_length_m || !a.body_width_m || !b.body_length_m || !b.body_width_m) return false;
  const auto axes = [](const RobotInfo& i) {
    const double c = std::cos(i.start_pose[2]), s = std::sin(i.start_pose[2]);
    return std::array<std::array<double, 2>, 2>{{{c, s}, {-s, c}}};
  };
  const auto half = [](const RobotInfo& i) {
    return std::array<double, 2>{0.5 * *i.body_length_m, 0.5 * *i.body_width_m};
  };
  const auto aa = axes(a), ba = axes(b);
  const auto ah = half(a), bh = half(b);
  const double dx = b.start_pose[0] - a.start_pose[0], dy = b.start_pose[1] - a.start_pose[1];
  for (const auto& axis : {aa[0], aa[1], ba[0], ba[1]}) {
    const auto radius = [&](const std::array<std::array<double, 2>, 2>& ax,
                            const std::array<double, 2>& h) {
      return h[0] * std::abs(ax[0][0] * axis[0] + ax[0][1] * axis[1]) +
             h[1] * std::abs(ax[1][0] * axis[0] + ax[1][1] * axis[1]);
    };
    if (std::abs(dx * axis[0] + dy * axis[1]) >= radius(aa, ah) + radius(ba, bh)) return false;
  }
  return true;
}

// One world: every robot's chassis, lasers and robot clearance see every
// other robot's body: the chassis' body_box, gathered by one moving_bodies
// unit (units/world) into an array each of them reads whole, skipping its
// own robot's box.
void ConnectFleet(assembly::SystemBuilder& b, const std::vector<RobotInfo>& robots,
                  const std::vector<std::vector<std::string>>& lasers,
                  std::vector<std::string>& recorded) {
  constexpr std::size_t kBox = models::MovingBox::kValues;
  const auto add = [&](const std::string& name, const assembly::Port& of) {
    b.Metric(name, of, cosim::Reduction::kFinal);
  };
  const int count = static_cast<int>(robots.size());
  b.Unit(assembly::kMovingBodies, "moving_bodies");
  b.Params(assembly::kMovingBodies)["count"] = count;
  const assembly::Port bodies = assembly::Signal(assembly::kMovingBodies, "bodies");
  for (std::size_t i = 0; i < robots.size(); ++i) {
    const std::string chassis = robots[i].name + "." + assembly::kChassis;
    for (std::size_t k = 0; k < kBox; ++k) {
      b.Connect(assembly::Element(chassis, "body_box", k),
                assembly::Element(assembly::kMovingBodies, "bodies_in", i * kBox + k));
    }
  }
  // The workers yield to every robot.
  for (auto& unit : b.spec().units) {
    if (unit.type != "worker") continue;
    unit.parameters["robots"] = count;
    b.Connect(bodies, assembly::Signal(unit.name, "robots"));
  }
  for (std::size_t i = 0; i < robots.size(); ++i) {
    const std::string& name = robots[i].name;
    const std::string clearance = name + "." + assembly::kRobotClearance;
    b.Unit(clearance, "robot_clearance");
    b.Params(clearance)["bodies"] = count;
    b.Params(clearance)["own"] = static_cast<int>(i);
    b.Connect(bodies, assembly::Signal(clearance, "bodies"));
    std::vector<std::string> takers = {name + "." + assembly::kChassis};
    takers.insert(takers.end(), lasers[i].begin(), lasers[i].end());
    for (const auto& unit : takers) {
      b.Params(unit)["moving_boxes"] = count;
      b.Params(unit)["own_box"] = static_cast<int>(i);
      b.Connect(bodies, assembly::Signal(unit, "moving_boxes"));
    }
    for (std::size_t j = 0; j < robots.size(); ++j) {
      if (j == i) continue;
      add(name + ".robot_" + robots[j].name + "_collisions",
          assembly::Element(clearance, "robot_collisions", j));
    }
    add(name + ".min_robot_distance_m", assembly::Signal(clearance, "min_distance"));
    add(name + ".robot_collisions", assembly::Signal(clearance, "collisions"));
    recorded.push_back(assembly::Signal(clearance, "distance").Name());
  }
}

// A worker is one of the scene's units, named as the user wrote it: a
// worker named as a robot would give its metrics the names of the robots'
// pair metrics (robot_NAME_collisions).
void CheckWorkerNames(const YAML::Node& root, const std::vector<RobotInfo>& robots, YamlReader& r) {
  const YAML::Node workers = Child(root, "workers");
  if (!workers.IsSequence()) return;
  for (std::size_t i = 0; i < workers.size(); ++i) {
    const YAML::Node name = Child(workers[i], "name");
    if (!name.IsScalar()) continue;
    for (const auto& robot : robots) {
      if (robot.name != name.Scalar()) continue;
      r.Error(name, JoinPath(JoinPath("workers", std::to_string(i)), "name"),
              "'" + robot.name +
                  "' is the name of a robot: workers and robots need names of "
                  "their own");
    }
  }
}

// Before anything is built: every robot's lasers and person clearance take
// every worker, so the cost grows with the robot-worker pairs.
bool WorkerCountWithinLimit(const YAML::Node& root, std::size_t robots, YamlReader& r) {
  const YAML::Node workers = Child(root, "workers");
  if (!workers.IsSequence() || robots == 0) return true;
  const std::size_t most = kMaxRobotWorkerPairs / robots;
  if (workers.size() <= most) return true;
  r.Error(workers, "workers",
          std::to_string(workers.size()) + " workers with " + std::to_string(robots) + " robot" +
              (robots == 1 ? "" : "s") + ": at most " + std::to_string(most) + " (" +
              std::to_string(kMaxRobotWorkerPairs) +
              " robot-worker pairs: " + kMaxRobotWorkerPairsWhy + ")");
  return false;
}

// What the robots' expansions give the fleet's.
struct FleetParts {
  std::vector<RobotInfo> robots;
  std::vector<std::size_t> list_index;           // each robot's item of `robots:`
  std::vector<std::vector<std::string>> lasers;  // each robot's laser units
  std::vector<std::string> recorded;
};

// Adds robot `robot`'s expansion `b` to the fleet's `top`: its own units
// get its name as scope (in units, connections, recording, metrics,
// origins and plot columns); the scene's (belt, workers) stay one, taken
// from the first robot. `several`: the fleet has more than one robot (the
// workers then yield to all of them, ConnectFleet).
void MergeRobot(assembly::SystemBuilder& top, assembly::SystemBuilder& b, YamlReader& r,
                bool several, RobotInfo robot, std::size_t list_item, FleetParts& fleet) {
  const std::string name = robot.name;
  const bool first = fleet.robots.empty();
  SystemSpec& one = b.spec();
  SystemSpec& all = top.spec();
  std::set<std::string> own;
  for (const auto& unit : one.units) {
    if (unit.type != "belt" && unit.type != "worker") own.insert(unit.name);
  }
  const auto unit_of = [](const std::string& column) { return column.substr(0, column.find('.')); };
  const auto scoped = [&](const std::string& column) {
    return own.count(unit_of(column)) ? name + "." + column : column;
  };
  fleet.lasers.emplace_back();
  for (auto& unit : one.units) {
    if (!own.count(unit.name)) {
      if (!top.HasUnit(unit.name)) all.units.push_back(std::move(unit));
      continue;
    }
    unit.name = name + "." + unit.name;
    if (unit.type == "laser_scanner") fleet.lasers.back().push_back(unit.name);
    all.units.push_back(std::move(unit));
  }
  for (const auto& c : one.connections) {
    // A worker yields to every robot of the fleet, not to the one robot it
    // was assembled with.
    if (several && !own.count(unit_of(c.to)) && c.to.ends_with(".robots")) continue;
    // Between the scene's units: the first robot made it.
    if (!first && !own.count(unit_of(c.from)) && !own.count(unit_of(c.to))) continue;
    all.connections.push_back({scoped(c.from), scoped(c.to), YAML::Node()});
  }
  if (one.recording && one.recording->variables) {
    for (const auto& v : *one.recording->variables) {
      const std::string column = scoped(v.text);
      if (std::find(fleet.recorded.begin(), fleet.recorded.end(), column) == fleet.recorded.end()) {
        fleet.recorded.push_back(column);
      }
    }
  }
  for (const auto& m : one.metrics) {
    if (!own.count(unit_of(m.of))) {
      if (first) all.metrics.push_back(m);  // of a scene's unit (a worker): once, unscoped
      continue;
    }
    all.metrics.push_back({name + "." + m.name, scoped(m.of), m.reduction, YAML::Node()});
  }
  for (const auto& [expanded, from] : one.origins) {
    std::string key = expanded;
    Origin origin = from;
    if (key.starts_with("units.") && own.count(unit_of(key.substr(6)))) {
      key = "units." + name + "." + key.substr(6);
    }
    if (origin.file.empty()) origin.path = r.Scoped(origin.path);
    all.origins.emplace(key, origin);
  }
  ScopeColumns(robot, scoped);
  fleet.robots.push_back(std::move(robot));
  fleet.list_index.push_back(list_item);
}

// A fleet: `robots:` is a list of robots, each expanded by the concerns as
// the one-robot shorthand is (its sections read as if they were the file's
// top-level ones), its units then scoped by its name (raw3_a.chassis).
// Belts and workers are the scene's: one unit each, shared.
SystemSpec ExpandFleet(const YAML::Node& root, YamlReader& r, RobotInfo& info) {
  r.CheckKeys(root, "",
              {"name", "description", "duration_s", "seed", "master", "robots", "scene", "line",
               "units", "connections", "recording", "metrics", "reference", "workers", "figures"});
  assembly::SystemBuilder top(root, r);
  ReadSystemHead(root, r, top.spec());
  const models::Scene scene = assembly::AddScene(top);
  FleetParts fleet;
  // The scenario's own metrics first.
  ReadMetrics(Child(root, "metrics"), r, top.spec());
  const std::vector<RobotInfo>& robots = fleet.robots;

  const YAML::Node list = Child(root, "robots");
  if (r.ExpectSequence(list, "robots") && list.size() == 0) {
    r.Error(list, "robots", "expected at least one robot {name, model, pose, task, ...}");
  }
  // Before anything is built: a fleet's memory and step time grow with the
  // robots and their pairs.
  if (list.IsSequence() && list.size() > kMaxRobots) {
    r.Error(list, "robots",
            std::to_string(list.size()) + " robots: at most " + std::to_string(kMaxRobots) + " (" +
                kMaxRobotsWhy + ")");
    return std::move(top.spec());
  }
  if (list.IsSequence() && !WorkerCountWithinLimit(root, list.size(), r)) {
    return std::move(top.spec());
  }
  for (std::size_t i = 0; list.IsSequence() && i < list.size(); ++i) {
    const YAML::Node entry = list[i];
    const std::string path = JoinPath("robots", std::to_string(i));
    if (!r.ExpectMap(entry, path)) continue;
    const std::string name = r.String(entry, path, "name", std::nullopt);
    if (name.empty()) continue;
    if (!cosim::IsIdentifier(name)) {
      r.Error(Child(entry, "name"), JoinPath(path, "name"),
              "robot name '" + name + "' is not valid: expected letters, digits and _ (it "
              "scopes the robot's units: " + name + ".chassis)");
      continue;
    }
    // The name names files (NAME_top_view.png, NAME_plots.gp) and metrics
    // (NAME.robot_OTHER_collisions, which a sweep's pictures are named
    // after): two names and the longest suffix stay within a file name's
    // 255 bytes.
    if (name.size() > kMaxRobotName) {
      r.Error(Child(entry, "name"), JoinPath(path, "name"),
              "robot name '" + name.substr(0, 40) + "...' has " + std::to_string(name.size()) +
                  " characters: at most " + std::to_string(kMaxRobotName) +
                  " (it names the robot's files, " + name.substr(0, 8) +
                  "..._top_view.png, and metrics, which a file name limits to 255 bytes)");
      continue;
    }
    if (std::any_of(robots.begin(), robots.end(),
                    [&](const RobotInfo& o) { return o.name == name; })) {
      r.Error(Child(entry, "name"), JoinPath(path, "name"),
              "robot name '" + name + "' is given twice");
      continue;
    }
    // The robot's part of the file as a one-robot scenario: its keys are
    // read at their shorthand paths and reported at robots.I's.
    YAML::Node one(YAML::NodeType::Map);
    one["robot"] = entry;
    for (const auto& key : kRobotSections) {
      if (Child(entry, key).IsDefined()) one[key] = Child(entry, key);
    }
    for (const char* key : {"scene", "line", "master", "workers"}) {
      if (Child(root, key).IsDefined()) one[key] = Child(root, key);
    }
    const YamlReader::PathScope scope(r, [path](const std::string& p) -> std::string {
      if (p == "robot") return path;
      if (p.starts_with("robot.")) return path + p.substr(5);
      for (const auto& key : kRobotSections) {
        if (p == key || p.starts_with(key + ".")) return JoinPath(path, p);
      }
      return p;
    });
    assembly::SystemBuilder b(one, r);
    RobotInfo robot;
    robot.name = name;
    std::vector<std::string> keys = {"name", "model", "pose", "payload"};
    keys.insert(keys.end(), kRobotSections.begin(), kRobotSections.end());
    AssembleRobot(b, keys, scene, robot);

    MergeRobot(top, b, r, list.size() > 1, std::move(robot), i, fleet);
  }
  CheckWorkerNames(root, robots, r);
  if (robots.size() > 1 && r.ok()) {
    ConnectFleet(top, robots, fleet.lasers, fleet.recorded);
  }
  assembly::AddRecordingSection(top, fleet.recorded);
  Passthrough(top);
  for (auto& robot : fleet.robots) ReadBody(top, robot.name + "." + assembly::kChassis, robot);
  for (std::size_t i = 0; i < robots.size(); ++i) {
    for (std::size_t j = i + 1; j < robots.size(); ++j) {
      if (BodiesOverlap(robots[i], robots[j])) {
        const YAML::Node entry = list[fleet.list_index[j]];
        const YAML::Node pose = Child(entry, "pose");
        r.Error(pose.IsDefined() ? pose : entry,
                JoinPath(JoinPath("robots", std::to_string(fleet.list_index[j])), "pose"),
                "robot '" + robots[j].name + "' would start inside robot '" + robots[i].name +
                    "' (their bodies overlap at their start poses)");
      }
    }
  }
  if (!robots.empty()) {
    info = robots.front();
    info.fleet.assign(robots.begin() + 1, robots.end());
    info.figure_bound = ReadFigureBound(root, r, info);
  }
  return std::move(top.spec());
}

}  // namespace

bool IsRobotScenario(const YAML::Node& root) {
  return root.IsMap() && (Child(root, "robot").IsDefined() || Child(root, "robots").IsDefined());
}

SystemSpec ExpandRobotScenario(const YAML::Node& root, YamlReader& r, RobotInfo& info) {
  if (Child(root, "robots").IsDefined()) {
    if (Child(root, "robot").IsDefined()) {
      r.Error(Child(root, "robot"), "robot",
              "give either robot (one robot) or robots (a list), not both");
    }
    return ExpandFleet(root, r, info);
  }
  r.CheckKeys(root, "",
              {"name",         "description", "duration_s",  "seed",      "master",  "robot",
               "scene",        "line",        "control",     "task",      "sensors", "sensing",
               "localization", "units",       "connections", "recording", "metrics", "reference",
               "workers",      "safety",      "figures"});
  assembly::SystemBuilder b(root, r);
  if (!WorkerCountWithinLimit(root, 1, r)) return std::move(b.spec());
  ReadSystemHead(root, r, b.spec());
  const models::Scene scene = assembly::AddScene(b);
  AssembleRobot(b, {"model", "pose", "payload"}, scene, info);
  Passthrough(b);
  ReadBody(b, assembly::kChassis, info);
  info.figure_bound = ReadFigureBound(root, r, info);
  return std::move(b.spec());
}

}  // namespace linesim::loader
