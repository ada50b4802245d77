#include "loader/robot_scenario.h"

#include <cmath>
#include <limits>
#include <map>
#include <numbers>

#include "cosim/time.h"
#include "cosim/variable_table.h"
#include "loader/scenario.h"
#include "loader/yaml_files.h"

namespace linesim::loader {

namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

// Names of the units a robot scenario expands into. Connections, recording,
// metrics and the plots refer to these.
constexpr const char* kBelt = "belt";
constexpr const char* kChassis = "chassis";
constexpr const char* kMotors = "motors";
constexpr const char* kWheelController = "wheel_controller";
constexpr const char* kPathFollower = "path_follower";
constexpr const char* kDeviation = "deviation";

// A number as the shortest text that reads back to it, so that the
// expansion `linesim inspect` prints shows 0.9 rather than 0.90000000000000002.
YAML::Node Num(double x) { return YAML::Node(cosim::FormatValue(x)); }

YAML::Node List(const std::vector<double>& values) {
  YAML::Node list(YAML::NodeType::Sequence);
  list.SetStyle(YAML::EmitterStyle::Flow);
  for (double v : values) list.push_back(Num(v));
  return list;
}

YAML::Node Point(double x, double y) { return List({x, y}); }

// Copies every key of `from` into `to` (both maps), the later one winning.
void MergeInto(YAML::Node to, const YAML::Node& from) {
  if (!from.IsMap()) return;
  for (const auto& kv : from) to[kv.first.Scalar()] = kv.second;
}

class Expander {
 public:
  Expander(const YAML::Node& root, YamlReader& r, RobotInfo& info)
      : root_(root), r_(r), info_(info) {}

  YAML::Node Expand() {
    r_.CheckKeys(
        root_, "",
        {"name", "description", "duration_s", "seed", "master", "robot", "line", "control", "task",
         "sensing", "localization", "units", "connections", "recording", "metrics"});
    for (const char* key : {"name", "description", "duration_s", "seed", "master"}) {
      if (Child(root_, key).IsDefined()) out_[key] = Child(root_, key);
    }
    Robot();
    Line();
    Control();
    Sensing();
    Task();
    Passthrough();
    Recording();
    Metrics();
    PlotColumns();
    // The file's own connections and metrics come first, so that a problem
    // found in them later carries the index they have in the file.
    YAML::Node connections(YAML::NodeType::Sequence);
    for (const auto& c : user_connections_) connections.push_back(c);
    for (const auto& c : connections_) connections.push_back(c);
    out_["connections"] = connections;
    r_.SetOrigins(std::move(origins_));
    return out_;
  }

 private:
  YAML::Node Unit(const char* name) { return out_["units"][name]; }
  YAML::Node Params(const char* name) { return out_["units"][name]["parameters"]; }
  void Connect(const std::string& from, const std::string& to) {
    YAML::Node c;
    c.SetStyle(YAML::EmitterStyle::Flow);
    c["from"] = from;
    c["to"] = to;
    connections_.push_back(c);
  }

  // The master step as the system loader reads it; its default if absent
  // or bad (the system loader reports a bad one at master.step_s).
  cosim::TimeNs MasterStep() const {
    YamlReader quiet(r_.file());
    return ReadMasterStep(quiet, Child(root_, "master"));
  }

  // Records that the expansion's `expanded` path holds a value derived from
  // the robot-level key `key` of `parent` (at `path`), so that a problem
  // found there is reported where the user can change it.
  void Derived(const std::string& expanded, const YAML::Node& parent, const std::string& path,
               const std::string& key) {
    const YAML::Node node = Child(parent, key);
    origins_[expanded] = {node.IsDefined() ? node : parent, JoinPath(path, key)};
  }

  // A chassis parameter as the chassis unit will get it; undefined if
  // nothing sets it.
  YAML::Node ChassisValue(const std::string& key) const {
    for (const YAML::Node& source : {user_chassis_, robot_chassis_, chassis_model_}) {
      const YAML::Node v = Child(source, key);
      if (v.IsDefined() && !v.IsNull()) return v;
    }
    return YAML::Node(YAML::NodeType::Undefined);
  }

  // A chassis parameter that is a positive finite number; nothing otherwise.
  std::optional<double> PositiveChassisValue(const std::string& key) const {
    const YAML::Node n = ChassisValue(key);
    double value = 0.0;
    if (n.IsScalar() && YAML::convert<double>::decode(n, value) && std::isfinite(value) &&
        value > 0.0) {
      return value;
    }
    return std::nullopt;
  }

  // A section that must be a map if present; an empty map if absent.
  YAML::Node Section(const YAML::Node& parent, const std::string& path, const std::string& key,
                     const std::vector<std::string>& keys) {
    const YAML::Node node = Child(parent, key);
    const std::string full = JoinPath(path, key);
    if (!node.IsDefined() || node.IsNull()) return YAML::Node(YAML::NodeType::Map);
    if (!r_.ExpectMap(node, full)) return YAML::Node(YAML::NodeType::Map);
    r_.CheckKeys(node, full, keys);
    return node;
  }

  void Robot() {
    const YAML::Node robot = Section(root_, "", "robot", {"model", "pose"});
    const std::string model = r_.String(robot, "robot", "model", "raw3");
    const YAML::Node pose = Section(robot, "robot", "pose", {"x_m", "y_m", "yaw_deg"});
    x_m_ = r_.Real(pose, "robot.pose", "x_m", 0.0, {-1e6, 1e6});
    y_m_ = r_.Real(pose, "robot.pose", "y_m", 0.0, {-1e6, 1e6});
    yaw_rad_ = r_.Real(pose, "robot.pose", "yaw_deg", 0.0, {-360.0, 360.0}) * kDegToRad;

    // The robot model file names the models of each unit and their settings.
    const YAML::Node robot_model =
        LoadModel(r_, Child(robot, "model"), "robot.model", "robot model", model, "robots",
                  r_.file(), &robot_file_);
    if (!robot_model.IsDefined()) return;
    {
      // A misspelled key in the model file would otherwise go unread.
      YamlReader::InFile in_model(r_, robot_file_);
      r_.CheckKeys(robot_model, "",
                   {"description", "source", "steer_motor_model", "drive_motor_model", "units"});
    }
    const YAML::Node units = Child(robot_model, "units");

    // The chassis as it will be built: the file's own units.chassis, the
    // robot model's chassis settings, the chassis model file they name.
    user_chassis_ = Child(Child(Child(root_, "units"), kChassis), "parameters");
    robot_chassis_ = Child(units, kChassis);
    const YAML::Node chassis_model = ChassisValue("model");
    if (chassis_model.IsScalar()) {
      // The chassis unit reports a bad model file itself, once.
      YamlReader quiet(r_.file());
      chassis_model_ = LoadModel(quiet, chassis_model, "", "model", chassis_model.Scalar(),
                                 "chassis", r_.file());
    }
    std::int64_t wheels = 4;  // the chassis unit's default
    if (const YAML::Node n = ChassisValue("wheel_count");
        n.IsScalar() && YAML::convert<std::int64_t>::decode(n, wheels) && wheels >= 1 &&
        wheels <= 16) {
      info_.wheel_count = static_cast<int>(wheels);
    } else {
      info_.wheel_count = 4;  // a bad count is the chassis unit's to report
    }
    // The plots draw the body the chassis simulates; a bad size is the
    // chassis unit's to report.
    info_.body_length_m = PositiveChassisValue("body_length");
    info_.body_width_m = PositiveChassisValue("body_width");

    Unit(kChassis)["type"] = "chassis";
    MergeInto(Params(kChassis), Child(units, kChassis));
    Params(kChassis)["initial_x"] = Num(x_m_);
    Params(kChassis)["initial_y"] = Num(y_m_);
    Params(kChassis)["initial_yaw"] = Num(yaw_rad_);
    Derived("units.chassis.parameters.initial_x", pose, "robot.pose", "x_m");
    Derived("units.chassis.parameters.initial_y", pose, "robot.pose", "y_m");
    Derived("units.chassis.parameters.initial_yaw", pose, "robot.pose", "yaw_deg");
    Motors(robot_model, Child(units, kMotors));
    controller_defaults_ = Child(units, kWheelController);
    follower_defaults_ = Child(units, kPathFollower);
  }

  // The 2 W motors (steering 0..W-1, drive W..2W-1) are one dc_motor unit:
  // one CVODE system restarted once per controller cycle instead of two,
  // which halves the integrator's fixed cost per step. Each motor takes its
  // parameters from its own model file (models/motors), as element arrays.
  void Motors(const YAML::Node& robot_model, const YAML::Node& settings) {
    const int w = info_.wheel_count;
    Unit(kMotors)["type"] = "dc_motor";
    YAML::Node p = Params(kMotors);
    p["count"] = 2 * w;
    // The chassis owns the mechanics; the motors get its joint rates.
    p["mode"] = "current_only";
    std::map<std::string, std::vector<double>> arrays;
    const char* keys[2] = {"steer_motor_model", "drive_motor_model"};
    for (int group = 0; group < 2; ++group) {
      const std::string name = Child(robot_model, keys[group]).as<std::string>("");
      std::string file;
      const YAML::Node model = LoadModel(r_, Child(root_, "robot"), "robot.model",
                                         "the robot model's " + std::string(keys[group]), name,
                                         "motors", robot_file_, &file);
      if (!model.IsDefined()) return;
      for (const auto& kv : model) {
        const std::string key = kv.first.Scalar();
        if (key == "source" || key == "description") continue;
        auto& values = arrays[key];
        values.resize(static_cast<std::size_t>(2 * w), std::numeric_limits<double>::quiet_NaN());
        double value = 0.0;
        if (!kv.second.IsScalar() || !YAML::convert<double>::decode(kv.second, value)) {
          r_.Error(Child(root_, "robot"), "robot.model",
                   "motor model " + file + ", key '" + key + "': expected a number, got " +
                       Describe(kv.second));
          return;
        }
        for (int k = 0; k < w; ++k) values[static_cast<std::size_t>(group * w + k)] = value;
      }
    }
    for (const auto& [key, values] : arrays) {
      for (double v : values) {
        if (std::isnan(v)) {
          r_.Error(Child(root_, "robot"), "robot.model",
                   "the steering and drive motor models must set the same keys; '" + key +
                       "' is in only one");
          return;
        }
      }
      p[key] = List(values);
    }
    // What the chassis and the controller need to know of the motors, from
    // the same model files: the rotor inertia seen at the joint through the
    // gear, eta N^2 J_rotor (the dc_motor full mode's J_eff = J_rotor +
    // J_load / (eta N^2), seen from the load), and the back-EMF at the joint,
    // k_e N = k_t N (SI units), the voltage that holds a joint rate unloaded.
    const auto group_value = [&](const char* key, int group) {
      const auto it = arrays.find(key);
      return it == arrays.end() ? std::numeric_limits<double>::quiet_NaN()
                                : it->second[static_cast<std::size_t>(group * w)];
    };
    const char* joints[2] = {"steer", "drive"};
    for (int group = 0; group < 2; ++group) {
      const double j = group_value("rotor_inertia", group);
      const double n = group_value("gear_ratio", group);
      const double eta = group_value("gear_efficiency", group);
      const double k_t = group_value("torque_constant", group);
      const std::string joint = joints[group];
      if (std::isfinite(eta * n * n * j)) {
        Params(kChassis)[joint + "_rotor_inertia"] = Num(eta * n * n * j);
      }
      if (std::isfinite(k_t * n)) feedforward_[joint + "_feedforward"] = Num(k_t * n);
    }
    MergeInto(p, settings);
    for (int k = 0; k < w; ++k) {
      const std::string s = "[" + std::to_string(k) + "]";
      const std::string d = "[" + std::to_string(w + k) + "]";
      Connect("motors.torque" + s, "chassis.steer_torque" + s);
      Connect("motors.torque" + d, "chassis.drive_torque" + s);
      Connect("chassis.steer_rate" + s, "motors.shaft_speed" + s);
      Connect("chassis.drive_rate" + s, "motors.shaft_speed" + d);
    }
  }

  void Line() {
    const YAML::Node line = Section(root_, "", "line", {"belts"});
    const YAML::Node belts = Child(line, "belts");
    std::vector<double> cx, cy, length, width, direction, speed, variation, period, accel, on0;
    YAML::Node schedules(YAML::NodeType::Sequence);
    if (belts.IsDefined() && !belts.IsNull() && r_.ExpectSequence(belts, "line.belts")) {
      for (std::size_t i = 0; i < belts.size(); ++i) {
        const std::string path = JoinPath("line.belts", std::to_string(i));
        const YAML::Node b = belts[i];
        if (!r_.ExpectMap(b, path)) continue;
        r_.CheckKeys(
            b, path,
            {"center_x_m", "center_y_m", "length_m", "width_m", "direction_deg", "speed_mps",
             "speed_variation", "variation_period_s", "acceleration_mps2", "schedule"});
        RobotInfo::Belt belt{};
        belt.center_x_m = r_.Real(b, path, "center_x_m", std::nullopt, {-1e6, 1e6});
        belt.center_y_m = r_.Real(b, path, "center_y_m", std::nullopt, {-1e6, 1e6});
        belt.length_m = r_.Real(b, path, "length_m", std::nullopt, {0.0, 1e4, true});
        belt.width_m = r_.Real(b, path, "width_m", std::nullopt, {0.0, 1e3, true});
        belt.direction_rad = r_.Real(b, path, "direction_deg", 0.0, {-360, 360}) * kDegToRad;
        info_.belts.push_back(belt);
        const std::string index = "." + std::to_string(i);
        for (const auto& [unit, parameter, key] : std::vector<std::array<std::string, 3>>{
                 {"belt", "direction", "direction_deg"},
                 {"belt", "nominal_speed", "speed_mps"},
                 {"belt", "speed_variation", "speed_variation"},
                 {"belt", "variation_period", "variation_period_s"},
                 {"belt", "acceleration", "acceleration_mps2"},
                 {"belt", "initially_on", "schedule"},
                 {"chassis", "belt_center_x", "center_x_m"},
                 {"chassis", "belt_center_y", "center_y_m"},
                 {"chassis", "belt_length", "length_m"},
                 {"chassis", "belt_width", "width_m"},
                 {"chassis", "belt_direction", "direction_deg"}}) {
          Derived("units." + unit + ".parameters." + parameter + index, b, path, key);
        }
        cx.push_back(belt.center_x_m);
        cy.push_back(belt.center_y_m);
        length.push_back(belt.length_m);
        width.push_back(belt.width_m);
        direction.push_back(belt.direction_rad);
        // Paper 1: lines run below 0.2 m/s; 2 m/s leaves room for studies.
        speed.push_back(r_.Real(b, path, "speed_mps", std::nullopt, {0.0, 2.0, true}));
        // Paper 1: "almost constant velocity (+-10 % variation)".
        variation.push_back(r_.Real(b, path, "speed_variation", 0.1, {0.0, 0.5}));
        period.push_back(r_.Real(b, path, "variation_period_s", 20.0, {0.0, 1e6, true}));
        accel.push_back(r_.Real(b, path, "acceleration_mps2", 0.5, {0.0, 100.0, true}));
        // The schedule: [{time_s, on}], in increasing time; on at t = 0
        // unless the first entry (at 0) says otherwise.
        YAML::Node switches(YAML::NodeType::Sequence);
        bool initially_on = true;
        const YAML::Node schedule = Child(b, "schedule");
        const std::string schedule_path = JoinPath(path, "schedule");
        if (schedule.IsDefined() && !schedule.IsNull() &&
            r_.ExpectSequence(schedule, schedule_path)) {
          cosim::TimeNs last = -1;
          for (std::size_t k = 0; k < schedule.size(); ++k) {
            const std::string item_path = JoinPath(schedule_path, std::to_string(k));
            if (!r_.ExpectMap(schedule[k], item_path)) continue;
            r_.CheckKeys(schedule[k], item_path, {"time_s", "on"});
            const cosim::TimeNs t =
                r_.Time(schedule[k], item_path, "time_s", std::nullopt, {0.0, 1e7});
            const bool on = r_.Boolean(schedule[k], item_path, "on", std::nullopt);
            if (t <= last) {
              r_.Error(Child(schedule[k], "time_s"), JoinPath(item_path, "time_s"),
                       "switching times must increase");
            }
            last = t;
            if (t == 0) {
              initially_on = on;
              continue;
            }
            YAML::Node s;
            s["time_s"] = Num(cosim::NsToSeconds(t));
            s["on"] = on;
            switches.push_back(s);
          }
        }
        on0.push_back(initially_on ? 1.0 : 0.0);
        schedules.push_back(switches);
      }
    }
    const auto count = static_cast<int>(info_.belts.size());
    Params(kChassis)["belt_count"] = count;
    if (count == 0) return;
    Unit(kBelt)["type"] = "belt";
    YAML::Node p = Params(kBelt);
    p["count"] = count;
    p["schedules"] = schedules;
    p["direction"] = List(direction);
    p["nominal_speed"] = List(speed);
    p["speed_variation"] = List(variation);
    p["variation_period"] = List(period);
    p["acceleration"] = List(accel);
    p["initially_on"] = List(on0);
    YAML::Node c = Params(kChassis);
    c["belt_center_x"] = List(cx);
    c["belt_center_y"] = List(cy);
    c["belt_length"] = List(length);
    c["belt_width"] = List(width);
    c["belt_direction"] = List(direction);
    Connect("belt.velocity", "chassis.belt_velocity");
  }

  void Control() {
    const YAML::Node control = Section(root_, "", "control", {"compensation", "period_s"});
    const bool compensation = r_.Boolean(control, "control", "compensation", true);
    // FACTS.md: the Rob@Work 3 control cycle is 20 ms.
    const cosim::TimeNs period = r_.Time(control, "control", "period_s", 0.02, {0.0, 10.0, true});
    // The master checks the controllers' step against its own; its
    // problems are reported here, where the step comes from.
    for (const char* name : {kWheelController, kPathFollower}) {
      Unit(name)["step_s"] = Num(cosim::NsToSeconds(period));
      Derived(JoinPath(JoinPath("units", name), "step_s"), control, "control", "period_s");
    }
    Unit(kWheelController)["type"] = "wheel_controller";
    YAML::Node controller = Params(kWheelController);
    controller["wheel_count"] = info_.wheel_count;
    // The controller's robot is the chassis's: the same geometry, from the
    // same model file and settings.
    for (const char* key : {"wheel_x", "wheel_y", "wheel_radius"}) {
      const YAML::Node value = ChassisValue(key);
      if (!value.IsDefined()) continue;
      controller[key] = YAML::Clone(value);
      if (Child(user_chassis_, key).IsDefined()) {
        const std::string from = JoinPath("units.chassis.parameters", key);
        origins_[JoinPath("units.wheel_controller.parameters", key)] = {value, from};
      }
    }
    MergeInto(controller, feedforward_);
    MergeInto(controller, controller_defaults_);
    Params(kWheelController)["compensation"] = compensation;
    for (int k = 0; k < info_.wheel_count; ++k) {
      const std::string s = "[" + std::to_string(k) + "]";
      const std::string d = "[" + std::to_string(info_.wheel_count + k) + "]";
      Connect("wheel_controller.steer_voltage" + s, "motors.voltage" + s);
      Connect("wheel_controller.drive_voltage" + s, "motors.voltage" + d);
    }
    Connect("chassis.steer_angle", "wheel_controller.steer_angle");
    Connect("chassis.steer_rate", "wheel_controller.steer_rate");
    Connect("chassis.drive_rate", "wheel_controller.drive_rate");
    Connect("path_follower.twist_command", "wheel_controller.twist_command");
  }

  void Sensing() {
    // Later capabilities add sensors and estimators here; the names are
    // reserved now so that sweeps can vary them without changes.
    const YAML::Node sensing = Section(root_, "", "sensing", {"surface_velocity"});
    const std::string surface =
        r_.String(sensing, "sensing", "surface_velocity", "ground_truth", {"ground_truth"});
    if (surface == "ground_truth") {
      Connect("chassis.wheel_surface_velocity", "wheel_controller.surface_velocity");
    }
    const YAML::Node localization = Section(root_, "", "localization", {"source"});
    const std::string source =
        r_.String(localization, "localization", "source", "ground_truth", {"ground_truth"});
    if (source == "ground_truth") Connect("chassis.pose", "path_follower.pose");
  }

  void Task() {
    const YAML::Node task =
        Section(root_, "", "task",
                {"type", "waypoints", "point", "speed_mps", "acceleration_mps2", "yaw_deg"});
    info_.task = r_.String(task, "task", "type", std::nullopt, {"path", "hold"});
    Unit(kPathFollower)["type"] = "path_follower";
    YAML::Node p = Params(kPathFollower);
    MergeInto(p, follower_defaults_);
    if (info_.task == "path") {
      const YAML::Node waypoints = Child(task, "waypoints");
      if (!waypoints.IsDefined()) {
        r_.Error(task, "task.waypoints", "missing required key: a list of points [x, y] (m)");
      } else if (r_.ExpectSequence(waypoints, "task.waypoints")) {
        if (waypoints.size() < 2) {
          r_.Error(waypoints, "task.waypoints", "expected at least two points [x, y]");
        }
        for (std::size_t i = 0; i < waypoints.size(); ++i) {
          if (auto pt = r_.AsPoint(waypoints[i], JoinPath("task.waypoints", std::to_string(i)),
                                   {-1e6, 1e6})) {
            info_.path.push_back(*pt);
          }
        }
      }
      p["mode"] = "path";
      p["speed"] = Num(r_.Real(task, "task", "speed_mps", 0.3, {0.0, 1.2, true}));  // Table I max
    } else if (info_.task == "hold") {
      std::array<double, 2> point{x_m_, y_m_};
      if (Child(task, "point").IsDefined()) {
        if (auto pt = r_.AsPoint(Child(task, "point"), "task.point", {-1e6, 1e6})) point = *pt;
      }
      info_.path.push_back(point);
      p["mode"] = "hold";
    }
    if (Child(task, "acceleration_mps2").IsDefined()) {
      p["acceleration"] = Num(r_.Real(task, "task", "acceleration_mps2", 0.3, {0.0, 10.0, true}));
    }
    // The robot is omnidirectional: it keeps this heading while it moves.
    p["yaw"] = Num(Child(task, "yaw_deg").IsDefined()
                       ? r_.Real(task, "task", "yaw_deg", 0.0, {-360.0, 360.0}) * kDegToRad
                       : yaw_rad_);
    YAML::Node waypoints(YAML::NodeType::Sequence);
    waypoints.SetStyle(YAML::EmitterStyle::Flow);
    for (const auto& pt : info_.path) waypoints.push_back(Point(pt[0], pt[1]));
    p["waypoints"] = waypoints;

    Unit(kDeviation)["type"] = "path_deviation";
    Params(kDeviation)["path"] = YAML::Clone(waypoints);
    Connect("chassis.pose", "deviation.pose");
  }

  // `units:` in a robot scenario adds to or overrides the expanded units,
  // in the system-level shape: units.NAME.{type, step_s, parameters}.
  void Passthrough() {
    const YAML::Node units = Child(root_, "units");
    if (units.IsDefined() && !units.IsNull() && r_.ExpectMap(units, "units")) {
      for (const auto& kv : units) {
        const std::string name = kv.first.Scalar();
        const std::string path = JoinPath("units", name);
        // What the file sets here is no longer derived from robot-level keys.
        if (kv.second.IsMap()) {
          for (const auto& item : kv.second) {
            const std::string key = JoinPath(path, item.first.Scalar());
            std::vector<std::string> written = {key};
            if (item.first.Scalar() == "parameters" && item.second.IsMap()) {
              written.clear();
              for (const auto& p : item.second) written.push_back(JoinPath(key, p.first.Scalar()));
            }
            for (const auto& w : written) {
              std::erase_if(origins_, [&](const auto& o) {
                return o.first == w || o.first.starts_with(w + ".");
              });
            }
          }
        }
        YAML::Node target = out_["units"][name];
        if (!kv.second.IsMap()) {
          r_.ExpectMap(kv.second, path);
          continue;
        }
        for (const auto& item : kv.second) {
          const std::string key = item.first.Scalar();
          if (key == "parameters" && item.second.IsMap()) {
            MergeInto(target["parameters"], item.second);
          } else {
            target[key] = item.second;
          }
        }
      }
    }
    const YAML::Node connections = Child(root_, "connections");
    if (connections.IsDefined() && !connections.IsNull() &&
        r_.ExpectSequence(connections, "connections")) {
      for (const auto& c : connections) user_connections_.push_back(c);
    }
  }

  void Recording() {
    if (Child(root_, "recording").IsDefined()) {
      out_["recording"] = Child(root_, "recording");
      return;
    }
    YAML::Node vars(YAML::NodeType::Sequence);
    vars.SetStyle(YAML::EmitterStyle::Flow);
    for (const char* v :
         {"chassis.pose", "chassis.velocity", "chassis.steer_angle", "chassis.drive_rate",
          "chassis.wheel_surface", "chassis.wheel_contact", "path_follower.twist_command",
          "wheel_controller.steer_voltage", "wheel_controller.drive_voltage", "motors.current",
          "deviation.deviation"}) {
      vars.push_back(v);
    }
    if (!info_.belts.empty()) {
      vars.push_back("belt.speed");
      vars.push_back("belt.on");
    }
    out_["recording"]["variables"] = vars;
    // About 100 Hz is enough for the plots and keeps signals.csv small; it
    // must be a whole number of master steps (the master refuses bad steps).
    constexpr cosim::TimeNs kInterval = cosim::kNsPerSecond / 100;
    const cosim::TimeNs step = MasterStep();
    const cosim::TimeNs interval = step < kInterval ? (kInterval + step - 1) / step * step : step;
    out_["recording"]["interval_s"] = Num(cosim::NsToSeconds(interval));
  }

  void Metrics() {
    YAML::Node metrics(YAML::NodeType::Sequence);
    const YAML::Node extra = Child(root_, "metrics");
    if (extra.IsDefined() && !extra.IsNull() && r_.ExpectSequence(extra, "metrics")) {
      for (const auto& m : extra) metrics.push_back(m);
    }
    const auto add = [&](const char* name, const char* of, const char* reduce) {
      YAML::Node m;
      m["name"] = name;
      m["of"] = of;
      m["reduce"] = reduce;
      metrics.push_back(m);
    };
    if (info_.task == "path") {
      add("max_path_deviation_m", "deviation.deviation", "max");
      add("final_path_deviation_m", "deviation.deviation", "final");
      add("final_progress_m", "deviation.progress", "final");
    } else {
      add("max_position_drift_m", "deviation.deviation", "max");
      add("final_position_drift_m", "deviation.deviation", "final");
    }
    add("final_yaw_rad", "chassis.pose[2]", "final");
    out_["metrics"] = metrics;
  }

  // The columns the recorder gives the variables the plots read.
  void PlotColumns() {
    const auto column = [](const char* unit, const std::string& variable) {
      return std::string(unit) + "." + variable;
    };
    const auto element = [&](const char* unit, const std::string& variable, std::size_t k) {
      return column(unit, variable + "[" + std::to_string(k) + "]");
    };
    info_.x_column = element(kChassis, "pose", 0);
    info_.y_column = element(kChassis, "pose", 1);
    info_.yaw_column = element(kChassis, "pose", 2);
    for (std::size_t w = 0; w < static_cast<std::size_t>(info_.wheel_count); ++w) {
      info_.wheel_columns.emplace_back(element(kChassis, "wheel_contact", 2 * w),
                                       element(kChassis, "wheel_contact", 2 * w + 1));
    }
    info_.error_column = column(kDeviation, "deviation");
    for (std::size_t b = 0; b < info_.belts.size(); ++b) {
      info_.belt_speed_columns.push_back(element(kBelt, "speed", b));
      info_.belt_on_columns.push_back(element(kBelt, "on", b));
    }
  }

  const YAML::Node& root_;
  YamlReader& r_;
  RobotInfo& info_;
  YAML::Node out_{YAML::NodeType::Map};
  std::vector<YAML::Node> user_connections_, connections_;
  YAML::Node controller_defaults_, follower_defaults_;
  YAML::Node user_chassis_, robot_chassis_, chassis_model_;
  YAML::Node feedforward_{YAML::NodeType::Map};
  double x_m_ = 0, y_m_ = 0, yaw_rad_ = 0;
  std::string robot_file_;
  std::map<std::string, Origin> origins_;
};

}  // namespace

bool IsRobotScenario(const YAML::Node& root) {
  return root.IsMap() && Child(root, "robot").IsDefined();
}

YAML::Node ExpandRobotScenario(const YAML::Node& root, YamlReader& reader, RobotInfo& info) {
  return Expander(root, reader, info).Expand();
}

}  // namespace linesim::loader
