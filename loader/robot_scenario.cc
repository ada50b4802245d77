#include "loader/robot_scenario.h"

#include <cmath>
#include <numbers>

#include "cosim/variable_table.h"
#include "loader/assembly/concerns.h"
#include "loader/assembly/people.h"
#include "loader/robot_file.h"
#include "models/angle.h"

namespace linesim::loader {

namespace {

using models::kDegToRad;

// `units:` in a robot scenario adds to or overrides the expanded units, in
// the system-level shape units.NAME.{type, step_s, parameters}; its
// connections come before the expansion's, so that a problem found in them
// keeps the index it has in the file.
void Passthrough(assembly::SystemBuilder& b) {
  YamlReader& r = b.reader();
  const YAML::Node units = Child(b.root(), "units");
  if (units.IsDefined() && !units.IsNull() && r.ExpectMap(units, "units")) {
    for (const auto& kv : units) {
      const std::string name = kv.first.Scalar();
      const std::string path = JoinPath("units", name);
      if (!kv.second.IsMap()) {
        r.ExpectMap(kv.second, path);
        continue;
      }
      YAML::Node target = b.out()["units"][name];
      for (const auto& item : kv.second) {
        const std::string key = item.first.Scalar();
        // What the file sets here is no longer derived from robot-level keys.
        std::vector<std::string> written = {JoinPath(path, key)};
        if (key == "parameters" && item.second.IsMap()) {
          written.clear();
          for (const auto& p : item.second) {
            written.push_back(JoinPath(JoinPath(path, key), p.first.Scalar()));
          }
          assembly::MergeInto(target["parameters"], item.second);
        } else {
          target[key] = item.second;
        }
        for (const auto& w : written) {
          std::erase_if(b.origins(), [&](const auto& o) {
            return o.first == w || o.first.starts_with(w + ".");
          });
        }
      }
    }
  }
  const YAML::Node own = Child(b.root(), "connections");
  YAML::Node connections(YAML::NodeType::Sequence);
  if (own.IsDefined() && !own.IsNull() && r.ExpectSequence(own, "connections")) {
    for (const auto& c : own) connections.push_back(c);
  }
  for (const auto& c : b.connections()) connections.push_back(c);
  b.out()["connections"] = connections;
}

// A positive number the chassis will get, for the plots; nothing otherwise
// (the chassis unit reports a bad one).
std::optional<double> PositiveChassisValue(assembly::SystemBuilder& b, const std::string& key) {
  const YAML::Node n =
      Child(Child(Child(Child(b.out(), "units"), assembly::kChassis), "parameters"), key);
  const auto value = YamlReader::DecodeReal(n);
  if (value && std::isfinite(*value) && *value > 0.0) return value;
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

}  // namespace

bool IsRobotScenario(const YAML::Node& root) {
  return root.IsMap() && Child(root, "robot").IsDefined();
}

YAML::Node ExpandRobotScenario(const YAML::Node& root, YamlReader& r, RobotInfo& info) {
  r.CheckKeys(root, "",
              {"name", "description", "duration_s", "seed", "master", "robot", "scene", "line",
               "control", "task", "sensors", "sensing", "localization", "units", "connections",
               "recording", "metrics", "reference", "workers", "safety"});
  assembly::SystemBuilder b(root, r);
  for (const char* key : {"name", "description", "duration_s", "seed", "master", "reference"}) {
    if (Child(root, key).IsDefined()) b.out()[key] = Child(root, key);
  }

  const YAML::Node robot = b.Section(root, "", "robot", {"model", "pose", "payload"});
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

  const models::Scene scene = assembly::AddScene(b);
  CheckStartPose(b, scene, start);
  if (file) {
    assembly::Signals s = assembly::AddDriveTrain(b, *file, start, info);
    assembly::AddLine(b, scene, s);
    assembly::AddSensors(b, *file, s);
    assembly::AddSensing(b, *file, start, scene, s);
    assembly::AddControl(b, *file, s);
    assembly::AddSafetyFields(b, *file, s);
    assembly::AddTask(b, *file, start, s, info);
    assembly::ConnectMapSwitch(b, s);
    assembly::AddBeaconGroundTruth(b, *file, start, scene, s);
    assembly::AddEvaluation(b, file->robot, s, info);
    assembly::AddWorkers(b, *file, s, info);
    assembly::AddRecording(b, s, info);
  }
  Passthrough(b);
  info.body_length_m = PositiveChassisValue(b, "body_length");
  info.body_width_m = PositiveChassisValue(b, "body_width");
  r.SetOrigins(std::move(b.origins()));
  return b.out();
}

}  // namespace linesim::loader
