#include "loader/robot_file.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <utility>

#include "cosim/system.h"
#include "cosim/variable_table.h"
#include "loader/scenario.h"
#include "loader/yaml_files.h"
#include "models/angle.h"

namespace linesim::loader {

namespace {

using models::kDegToRad;
// Sizes of anything that rolls on a factory floor: a wheel of 1 mm to 2 m,
// a robot up to 10 m long and 10 t heavy.
constexpr Range kPositionM{-10.0, 10.0};
constexpr Range kSizeM{0.0, 10.0, true};
constexpr Range kWheelRadiusM{0.001, 2.0};
constexpr Range kMassKg{0.0, 1e4, true};

class Reader {
 public:
  Reader(YamlReader& r, std::string file) : r_(r), file_(std::move(file)) {}

  std::optional<RobotFile> Read(const YAML::Node& root) {
    RobotFile out;
    models::RobotDescription& robot = out.robot;
    robot.file = file_;
    if (!r_.ExpectMap(root, "")) return std::nullopt;
    root_ = root;
    out.root = root;
    r_.CheckKeys(root, "",
                 {"description", "source", "body", "wheels", "motor_groups", "controller",
                  "chassis", "motors", "path_follower", "sensor_mounts", "payload", "safety",
                  "treads"});
    robot.description = r_.String(root, "", "description", "");
    Body(Child(root, "body"), robot.body);
    MotorGroups(Child(root, "motor_groups"), robot);
    Treads(Child(root, "treads"));
    Wheels(Child(root, "wheels"), robot);
    Controller(Child(root, "controller"), out);
    SensorMounts(Child(root, "sensor_mounts"), out);
    if (const YAML::Node p = Child(root, "payload"); p.IsDefined() && !p.IsNull()) {
      robot.payload = ReadPayload(r_, p, "payload");
    }
    out.chassis_settings = Settings(root, "chassis");
    out.motor_settings = Settings(root, "motors");
    out.follower_settings = Settings(root, "path_follower");
    // The S300's field sets as configured on the vehicle: checked where a
    // scenario switches the safety function on (loader/assembly/people.cc).
    if (const YAML::Node s = Child(root, "safety"); s.IsDefined() && !s.IsNull()) {
      if (r_.ExpectMap(s, "safety")) out.safety = s;
    }
    out.motor_models = motor_models_;
    // The robot's top speed and turn rate bound every task it is given.
    for (const char* key : {"max_speed", "max_yaw_rate"}) {
      if (!Child(out.follower_settings, key).IsDefined()) {
        r_.Error(Child(root, "path_follower").IsDefined() ? Child(root, "path_follower") : root,
                 JoinPath("path_follower", key),
                 "missing required key: the robot's top speed (m/s) and yaw rate (rad/s) for its "
                 "path follower");
      }
    }
    return out;
  }

 private:
  YAML::Node Map(const YAML::Node& parent, const std::string& path, const std::string& key,
                 bool required) {
    const YAML::Node node = Child(parent, key);
    const std::string full = JoinPath(path, key);
    if (!node.IsDefined() || node.IsNull()) {
      if (required) r_.Error(parent, full, "missing required key: a map");
      return YAML::Node(YAML::NodeType::Undefined);
    }
    return r_.ExpectMap(node, full) ? node : YAML::Node(YAML::NodeType::Undefined);
  }

  YAML::Node Settings(const YAML::Node& root, const std::string& key) {
    const YAML::Node node = Map(root, "", key, false);
    return node.IsDefined() ? node : YAML::Node(YAML::NodeType::Map);
  }

  void Body(const YAML::Node& parent_node, models::BodyDescription& b) {
    const YAML::Node root = parent_node;
    if (!root.IsDefined()) {
      r_.Error(root_, "body", "missing required key: a map of the body's size and mass");
      return;
    }
    if (!r_.ExpectMap(root, "body")) return;
    r_.CheckKeys(root, "body",
                 {"length_m", "width_m", "height_m", "bottom_m", "mass_kg", "com_height_m"});
    const std::size_t before = r_.issues().size();
    b.length_m = r_.Real(root, "body", "length_m", std::nullopt, kSizeM);
    b.width_m = r_.Real(root, "body", "width_m", std::nullopt, kSizeM);
    b.height_m = r_.Real(root, "body", "height_m", std::nullopt, kSizeM);
    // The underside: on or above the floor (a body reaching below it would
    // meet every terrain piece it drives onto).
    b.bottom_m = r_.Real(root, "body", "bottom_m", std::nullopt, {0.0, 10.0});
    b.mass_kg = r_.Real(root, "body", "mass_kg", std::nullopt, kMassKg);
    b.com_height_m = r_.Real(root, "body", "com_height_m", std::nullopt, kSizeM);
    // Where the mass is and where the box is are separate facts, but the
    // body's centre of mass lies within its body.
    if (r_.issues().size() == before &&
        (b.com_height_m < b.bottom_m || b.com_height_m > b.top_m())) {
      r_.Error(Child(root, "com_height_m"), "body.com_height_m",
               "the body's centre of mass must lie within its box, from bottom_m " +
                   cosim::FormatValue(b.bottom_m) + " m to bottom_m + height_m " +
                   cosim::FormatValue(b.top_m()) + " m above the floor; got " +
                   cosim::FormatValue(b.com_height_m) + " m");
    }
  }

  void MotorGroups(const YAML::Node& list, models::RobotDescription& robot) {
    const std::string path = "motor_groups";
    if (!list.IsDefined()) {
      r_.Error(root_, path, "missing required key: a list of motor groups");
      return;
    }
    if (!r_.ExpectSequence(list, path)) return;
    std::set<std::string> names;
    for (std::size_t g = 0; g < list.size(); ++g) {
      const std::string gp = JoinPath(path, std::to_string(g));
      const YAML::Node node = list[g];
      if (!r_.ExpectMap(node, gp)) continue;
      r_.CheckKeys(node, gp, {"name", "model", "gear_ratio", "gear_efficiency", "motors"});
      models::MotorGroup group;
      group.name = r_.String(node, gp, "name", std::nullopt);
      // A gear turns the motor at most 1000 times per output turn; its
      // efficiency is a fraction.
      group.gear_ratio = r_.Real(node, gp, "gear_ratio", std::nullopt, {0.0, 1000.0, true});
      group.gear_efficiency = r_.Real(node, gp, "gear_efficiency", std::nullopt, {0.0, 1.0, true});
      const std::string model = r_.String(node, gp, "model", std::nullopt);
      YAML::Node motor;
      if (!model.empty()) {
        motor = LoadModel(r_, Child(node, "model"), JoinPath(gp, "model"), "motor model", model,
                          "motors", file_, &group.model_file);
        if (motor.IsDefined()) Motor(motor, group);
      }
      motor_models_.push_back(motor);
      group.motor["gear_ratio"] = group.gear_ratio;
      group.motor["gear_efficiency"] = group.gear_efficiency;
      const YAML::Node motors = Child(node, "motors");
      const std::string mp = JoinPath(gp, "motors");
      if (!motors.IsDefined()) {
        r_.Error(node, mp, "missing required key: a list of motor names");
      } else if (r_.ExpectSequence(motors, mp)) {
        for (std::size_t k = 0; k < motors.size(); ++k) {
          const std::string kp = JoinPath(mp, std::to_string(k));
          const auto name = r_.AsString(motors[k], kp);
          if (!name) continue;
          if (!motor_names_.insert(*name).second) {
            r_.Error(motors[k], kp, "motor '" + *name + "' is named twice");
          }
          motor_at_[*name] = {motors[k], kp, ""};
          group.motors.push_back(*name);
        }
        if (motors.size() == 0) r_.Error(motors, mp, "expected at least one motor");
      }
      if (!group.name.empty() && !names.insert(group.name).second) {
        r_.Error(Child(node, "name"), JoinPath(gp, "name"),
                 "motor group '" + group.name + "' is named twice");
      }
      robot.motor_groups.push_back(std::move(group));
    }
    // The groups form one dc_motor unit, whose parameters are element
    // arrays: every model gives the same keys.
    for (std::size_t g = 1; g < robot.motor_groups.size(); ++g) {
      for (const auto* pair : {&robot.motor_groups[0], &robot.motor_groups[g]}) {
        const auto& other = pair == &robot.motor_groups[0] ? robot.motor_groups[g]
                                                           : robot.motor_groups[0];
        for (const auto& [key, value] : pair->motor) {
          if (!other.motor.contains(key)) {
            const std::string gp = JoinPath(path, std::to_string(g));
            r_.Error(Child(list[g], "model"), JoinPath(gp, "model"),
                     "the motor models of one robot must set the same keys: '" + key +
                         "' is in " + pair->model_file + " but not in " + other.model_file);
          }
        }
      }
    }
  }

  // The motor model file's numbers (dc_motor parameter names); a gear in it
  // is the bare motor's (1) and is replaced by the group's.
  void Motor(const YAML::Node& motor, models::MotorGroup& group) {
    YamlReader::InFile in(r_, group.model_file);
    if (!r_.ExpectMap(motor, "")) return;
    // The keys are the dc_motor unit's Real parameters.
    const auto unit = CreateDefaultUnit("dc_motor");
    std::vector<std::string> names;
    for (const auto& info : unit->variables().infos()) {
      if (info.causality == cosim::Causality::kParameter &&
          (info.type == cosim::VarType::kReal || info.type == cosim::VarType::kRealArray)) {
        names.push_back(info.name);
      }
    }
    for (const auto& kv : motor) {
      const std::string key = kv.first.Scalar();
      if (key == "source" || key == "description") continue;
      if (std::find(names.begin(), names.end(), key) == names.end()) {
        r_.UnknownPath(kv.first, key,
                       "not a number parameter of a dc_motor unit" +
                           ClosestPathsHint("", key, names));
        continue;
      }
      if (const auto v = r_.AsReal(kv.second, key)) group.motor[key] = *v;
    }
    for (const char* key : {"resistance", "torque_constant", "rotor_inertia"}) {
      if (!group.motor.contains(key)) {
        r_.Error(motor, key, "missing required key: the controllers' feedforwards need it");
      }
    }
  }

  // The tread types by name: a transient brush tyre each (every value with
  // its source in the robot file).
  void Treads(const YAML::Node& map) {
    const std::string path = "treads";
    if (!map.IsDefined() || map.IsNull()) {
      r_.Error(root_, path, "missing required key: a map of tread types by name");
      return;
    }
    if (!r_.ExpectMap(map, path)) return;
    for (const auto& kv : map) {
      models::TreadDescription t;
      t.name = kv.first.Scalar();
      const std::string tp = JoinPath(path, t.name);
      const YAML::Node node = kv.second;
      if (!r_.ExpectMap(node, tp)) continue;
      r_.CheckKeys(node, tp,
                   {"material", "slip_stiffness", "cornering_stiffness",
                    "longitudinal_relaxation_m", "lateral_relaxation_m", "damping_ratio",
                    "patch_length_m", "patch_width_m", "source"});
      t.material = r_.String(node, tp, "material", std::nullopt);
      // Slip stiffness per unit load: car tyres 10-30, small solid wheels
      // more; 1000 leaves room without admitting nonsense.
      constexpr Range kPerLoad{0.0, 1000.0, true};
      t.slip_stiffness = r_.Real(node, tp, "slip_stiffness", std::nullopt, kPerLoad);
      t.cornering_stiffness = r_.Real(node, tp, "cornering_stiffness", std::nullopt, kPerLoad);
      constexpr Range kRelaxationM{0.0, 10.0, true};
      t.longitudinal_relaxation_m =
          r_.Real(node, tp, "longitudinal_relaxation_m", std::nullopt, kRelaxationM);
      t.lateral_relaxation_m = r_.Real(node, tp, "lateral_relaxation_m", std::nullopt, kRelaxationM);
      t.damping_ratio = r_.Real(node, tp, "damping_ratio", std::nullopt, {0.0, 10.0});
      t.patch_length_m = r_.Real(node, tp, "patch_length_m", std::nullopt, {0.0, 2.0});
      t.patch_width_m = r_.Real(node, tp, "patch_width_m", std::nullopt, {0.0, 2.0});
      treads_[t.name] = {t, node};
    }
  }

  void Wheels(const YAML::Node& list, models::RobotDescription& robot) {
    const std::string path = "wheels";
    if (!list.IsDefined()) {
      r_.Error(root_, path, "missing required key: a list of wheels");
      return;
    }
    if (!r_.ExpectSequence(list, path)) return;
    if (list.size() == 0) r_.Error(list, path, "expected at least one wheel");
    std::set<std::string> used, names;
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string wp = JoinPath(path, std::to_string(i));
      const YAML::Node node = list[i];
      if (!r_.ExpectMap(node, wp)) continue;
      r_.CheckKeys(node, wp,
                   {"name", "x_m", "y_m", "radius_m", "width_m", "mass_kg", "steer_inertia_kgm2",
                    "steer_motor", "drive_motor", "tread"});
      models::WheelDescription w;
      w.name = r_.String(node, wp, "name", std::nullopt);
      // Messages, columns and the plots name a wheel: one name, one wheel.
      if (!w.name.empty() && !names.insert(w.name).second) {
        r_.Error(Child(node, "name"), JoinPath(wp, "name"),
                 "wheel '" + w.name + "' is named twice: expected a name of its own");
      }
      w.x_m = r_.Real(node, wp, "x_m", std::nullopt, kPositionM);
      w.y_m = r_.Real(node, wp, "y_m", std::nullopt, kPositionM);
      w.radius_m = r_.Real(node, wp, "radius_m", std::nullopt, kWheelRadiusM);
      w.width_m = r_.Real(node, wp, "width_m", std::nullopt, kSizeM);
      w.mass_kg = r_.Real(node, wp, "mass_kg", std::nullopt, kMassKg);
      w.drive_motor = MotorName(node, wp, "drive_motor", true).value_or("");
      if (const auto tread = r_.String(node, wp, "tread", std::nullopt); !tread.empty()) {
        if (const auto it = treads_.find(tread); it != treads_.end()) {
          w.tread = it->second.first;
        } else {
          std::vector<std::string> names;
          for (const auto& [name, t] : treads_) names.push_back(name);
          r_.Error(Child(node, "tread"), JoinPath(wp, "tread"),
                   "no tread '" + tread + "' in treads; treads: " + JoinNames(names));
        }
      }
      w.steer_motor = MotorName(node, wp, "steer_motor", false);
      w.steer_inertia_kgm2 =
          r_.Real(node, wp, "steer_inertia_kgm2", w.steer_motor ? std::nullopt : std::optional(0.0),
                  {0.0, 100.0});
      for (const auto& m : {std::optional(w.drive_motor), w.steer_motor}) {
        if (m && !m->empty()) used.insert(*m);
      }
      if (w.steer_motor && *w.steer_motor == w.drive_motor) {
        r_.Error(Child(node, "steer_motor"), JoinPath(wp, "steer_motor"),
                 "a wheel cannot be steered and driven by the same motor '" + w.drive_motor + "'");
      }
      if (!robot.wheels.empty() && w.mass_kg != robot.wheels.front().mass_kg &&
          Child(node, "mass_kg").IsDefined()) {
        r_.Error(Child(node, "mass_kg"), JoinPath(wp, "mass_kg"),
                 "every wheel must have the mass of the first (" +
                     cosim::FormatValue(robot.wheels.front().mass_kg) +
                     " kg): the chassis lumps one module mass into each wheel");
      }
      robot.wheels.push_back(std::move(w));
    }
    // A motor that moves no wheel is a description error, not a spare.
    for (const auto& group : robot.motor_groups) {
      for (const auto& m : group.motors) {
        if (!used.contains(m)) {
          const Origin& at = motor_at_.at(m);
          r_.Error(at.node, at.path, "motor '" + m + "' moves no wheel");
        }
      }
    }
  }

  std::optional<std::string> MotorName(const YAML::Node& wheel, const std::string& path,
                                       const std::string& key, bool required) {
    const YAML::Node node = Child(wheel, key);
    const std::string full = JoinPath(path, key);
    if (!node.IsDefined() || node.IsNull()) {
      if (required) r_.Error(wheel, full, "missing required key: the name of a motor");
      return std::nullopt;
    }
    const auto name = r_.AsString(node, full);
    if (name && !motor_names_.contains(*name)) {
      r_.Error(node, full,
               "no motor '" + *name + "' in motor_groups; motors: " +
                   JoinNames({motor_names_.begin(), motor_names_.end()}));
    }
    return name;
  }

  void Controller(const YAML::Node& node, RobotFile& out) {
    const std::string path = "controller";
    models::RobotDescription& robot = out.robot;
    out.controller_settings = YAML::Node(YAML::NodeType::Map);
    if (!node.IsDefined()) {
      r_.Error(root_, path, "missing required key: a map with kind (swerve or differential)");
      return;
    }
    if (!r_.ExpectMap(node, path)) return;
    const std::string kind = r_.String(node, path, "kind", std::nullopt, {"swerve", "differential"});
    // A kind that is not one of them is reported once, above; its topology
    // is not checked against a kind the file did not ask for.
    if (!Child(node, "kind").IsScalar() || Child(node, "kind").Scalar() != kind) return;
    for (const auto& kv : node) {
      if (kv.first.Scalar() != "kind") out.controller_settings[kv.first.Scalar()] = kv.second;
    }
    const auto error = [&](const std::string& message) {
      r_.Error(Child(node, "kind"), JoinPath(path, "kind"), message);
    };
    // Both controllers take one wheel radius for every wheel.
    for (std::size_t i = 1; i < robot.wheels.size(); ++i) {
      if (robot.wheels[i].radius_m != robot.wheels[0].radius_m) {
        error("the " + kind + " controller takes one wheel radius for every wheel; wheel '" +
              robot.wheels[i].name + "' has " + cosim::FormatValue(robot.wheels[i].radius_m) +
              " m, wheel '" + robot.wheels[0].name + "' " +
              cosim::FormatValue(robot.wheels[0].radius_m) + " m");
        break;
      }
    }
    if (kind == "swerve") {
      robot.controller = models::ControllerKind::kSwerve;
      // Each wheel its own steering and drive motor: a swerve base.
      std::set<std::string> drive, steer;
      for (const auto& w : robot.wheels) {
        if (!w.steer_motor) {
          error("a swerve controller steers every wheel; wheel '" + w.name + "' has no steer_motor");
        }
        if (!drive.insert(w.drive_motor).second ||
            (w.steer_motor && !steer.insert(*w.steer_motor).second)) {
          error("a swerve controller needs a steer and a drive motor of its own for each wheel; "
                "wheel '" + w.name + "' shares one");
        }
      }
    } else if (kind == "differential") {
      robot.controller = models::ControllerKind::kDifferential;
      // Fixed wheels, one drive motor per side: left (y > 0), right (y < 0).
      std::set<std::string> left, right;
      for (const auto& w : robot.wheels) {
        if (w.steer_motor) error("a differential base has no steered wheel; '" + w.name + "' is");
        (w.y_m > 0.0 ? left : right).insert(w.drive_motor);
        if (w.y_m == 0.0) error("wheel '" + w.name + "' is on neither side (y_m = 0)");
      }
      if (left.size() != 1 || right.size() != 1 || left == right) {
        error("a differential base has one drive motor for the left wheels (y > 0) and another "
              "for the right ones");
      }
    }
  }

  void SensorMounts(const YAML::Node& list, RobotFile& out) {
    models::RobotDescription& robot = out.robot;
    const std::string path = "sensor_mounts";
    if (!list.IsDefined() || list.IsNull() || !r_.ExpectSequence(list, path)) return;
    std::set<std::string> names;
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string sp = JoinPath(path, std::to_string(i));
      const YAML::Node node = list[i];
      if (!r_.ExpectMap(node, sp)) continue;
      models::SensorMount m;
      m.kind = r_.String(node, sp, "kind", std::nullopt, models::SensorKinds());
      const bool posed = models::SensorKindHasPose(m.kind);
      std::vector<std::string> keys = {"name", "kind", "model", "step_s", "parameters", "source"};
      // A PX4Flow looks straight down: only its heading about the vertical
      // is free (a roll or pitch there would be silently dropped).
      const bool downward = m.kind == "px4flow";
      if (posed) keys.insert(keys.end(), {"x_m", "y_m", "z_m", "yaw_deg"});
      if (posed && !downward) keys.insert(keys.end(), {"roll_deg", "pitch_deg"});
      r_.CheckKeys(node, sp, keys);
      m.name = r_.String(node, sp, "name", std::nullopt);
      if (!m.name.empty() && !cosim::IsIdentifier(m.name)) {
        r_.Error(Child(node, "name"), JoinPath(sp, "name"),
                 "mount name '" + m.name + "' is not valid: expected letters, digits and _ (it "
                 "names the sensor's unit)");
      }
      m.model = r_.String(node, sp, "model", "");
      m.step_ns = r_.Time(node, sp, "step_s", 0.0, {0.0, 10.0});
      if (posed) {
        m.x_m = r_.Real(node, sp, "x_m", std::nullopt, kPositionM);
        m.y_m = r_.Real(node, sp, "y_m", std::nullopt, kPositionM);
        m.z_m = r_.Real(node, sp, "z_m", std::nullopt, {0.0, 10.0});
        m.roll_rad = r_.Real(node, sp, "roll_deg", 0.0, {-360.0, 360.0}) * kDegToRad;
        m.pitch_rad = r_.Real(node, sp, "pitch_deg", 0.0, {-360.0, 360.0}) * kDegToRad;
        m.yaw_rad = r_.Real(node, sp, "yaw_deg", 0.0, {-360.0, 360.0}) * kDegToRad;
      }
      if (!m.name.empty() && !names.insert(m.name).second) {
        r_.Error(Child(node, "name"), JoinPath(sp, "name"), "mount '" + m.name + "' is named twice");
      }
      const YAML::Node params = Child(node, "parameters");
      YAML::Node settings(YAML::NodeType::Map);
      if (params.IsDefined() && !params.IsNull() &&
          r_.ExpectMap(params, JoinPath(sp, "parameters"))) {
        settings = params;
      }
      robot.sensor_mounts.push_back(std::move(m));
      out.sensor_settings.push_back(settings);
    }
  }

  YamlReader& r_;
  std::string file_;
  std::set<std::string> motor_names_;
  std::map<std::string, Origin> motor_at_;
  std::map<std::string, std::pair<models::TreadDescription, YAML::Node>> treads_;
  std::vector<YAML::Node> motor_models_;
  YAML::Node root_;
};

// The node at `path` below `root` (map keys and list indices), or the
// nearest one above it that exists. (reset() rebinds a node; assigning one
// would overwrite the tree's value.)
YAML::Node NodeAt(const YAML::Node& root, const std::string& path) {
  YAML::Node node;
  node.reset(root);
  std::size_t begin = 0;
  while (!path.empty() && begin <= path.size()) {
    const std::size_t dot = std::min(path.find('.', begin), path.size());
    const std::string key = path.substr(begin, dot - begin);
    const bool index = node.IsSequence() && !key.empty() && key.size() < 10 &&
                       key.find_first_not_of("0123456789") == std::string::npos &&
                       std::stoul(key) < node.size();
    const YAML::Node next = node.IsMap() ? Child(node, key)
                            : index      ? std::as_const(node)[std::stoul(key)]
                                         : YAML::Node(YAML::NodeType::Undefined);
    if (!next.IsDefined() || next.IsNull()) break;
    node.reset(next);
    begin = dot + 1;
  }
  return node;
}

}  // namespace

Origin RobotFile::At(const std::string& path) const {
  return {NodeAt(root, path), path, robot.file};
}

Origin RobotFile::MotorAt(std::size_t group, const std::string& key) const {
  if (group >= motor_models.size() || group >= robot.motor_groups.size()) {
    return At(JoinPath(JoinPath("motor_groups", std::to_string(group)), "model"));
  }
  return {NodeAt(motor_models[group], key), key, robot.motor_groups[group].model_file};
}

std::optional<models::PayloadDescription> ReadPayload(YamlReader& r, const YAML::Node& node,
                                                      const std::string& path) {
  if (!r.ExpectMap(node, path)) return std::nullopt;
  r.CheckKeys(node, path, {"mass_kg", "x_m", "y_m", "z_m", "length_m", "width_m", "height_m"});
  const std::size_t before = r.issues().size();
  models::PayloadDescription p;
  p.mass_kg = r.Real(node, path, "mass_kg", std::nullopt, {0.0, 1e4});
  p.x_m = r.Real(node, path, "x_m", std::nullopt, kPositionM);
  p.y_m = r.Real(node, path, "y_m", std::nullopt, kPositionM);
  p.z_m = r.Real(node, path, "z_m", std::nullopt, kPositionM);
  // The box is optional: without it a point mass.
  constexpr Range kBoxM{0.0, 10.0};
  p.length_m = r.Real(node, path, "length_m", 0.0, kBoxM);
  p.width_m = r.Real(node, path, "width_m", 0.0, kBoxM);
  p.height_m = r.Real(node, path, "height_m", 0.0, kBoxM);
  const bool some = p.length_m > 0.0 || p.width_m > 0.0 || p.height_m > 0.0;
  const bool all = p.length_m > 0.0 && p.width_m > 0.0 && p.height_m > 0.0;
  if (some && !all) {
    r.Error(node, path,
            "length_m, width_m and height_m: give all three (a box) or none (a point mass)");
  }
  if (r.issues().size() != before) return std::nullopt;
  return p;
}

std::optional<RobotFile> ReadRobotFile(YamlReader& r, const YAML::Node& at,
                                       const std::string& path, const std::string& model,
                                       const std::string& relative_to) {
  std::string file;
  const YAML::Node root = LoadModel(r, at, path, "robot model", model, "robots", relative_to, &file);
  if (!root.IsDefined()) return std::nullopt;
  YamlReader::InFile in(r, file);
  const std::size_t before = r.issues().size();
  Reader reader(r, file);
  auto out = reader.Read(root);
  if (r.issues().size() != before) return std::nullopt;
  if (out) out->robot.name = model;
  return out;
}

}  // namespace linesim::loader
