#include <algorithm>
#include <map>
#include <set>

#include "cosim/time.h"
#include "loader/assembly/concerns.h"

namespace linesim::loader::assembly {

namespace {

// How a mount of each kind is built: the parameters its pose becomes, the
// chassis outputs it reads, the belt outputs it reads (when the scene has
// belts), and its default step (0: the master's).
struct KindWiring {
  std::vector<std::pair<std::string, std::string>> chassis_inputs;  // chassis output -> input
  std::vector<std::pair<std::string, std::string>> belt_inputs;     // belt output -> input
  cosim::TimeNs default_step = 0;
};

const std::map<std::string, KindWiring>& Wiring() {
  static const std::map<std::string, KindWiring> wiring = {
      // The PX4Flow steps with the physics and computes the camera frames
      // that fall in each step (about 400 per second).
      {"px4flow",
       {{{"position", "position"},
         {"yaw", "yaw"},
         {"linear_velocity", "linear_velocity"},
         {"yaw_rate", "yaw_rate"},
         {"angular_velocity", "angular_velocity"}},
        {{"velocity", "belt_velocity"}},
        0}},
      // A laser steps with the physics and casts the beams whose time falls
      // in each step (the mirror turns while the robot and the cars move).
      {"laser_scanner",
       {{{"position_3d", "position_3d"},
         {"orientation", "orientation"},
         {"velocity_3d", "velocity_3d"},
         {"angular_velocity", "angular_velocity"}},
        {{"travel", "belt_travel"}, {"speed", "belt_speed"}},
        0}},
      // 100 Hz (a typical output rate of a robot base's IMU driver), as a
      // whole number of master steps.
      {"imu",
       {{{"orientation", "orientation"},
         {"velocity_3d", "velocity_3d"},
         {"angular_velocity", "base_angular_velocity"}},
        {},
        cosim::kNsPerSecond / 100}},
      // Sampled at the control period (set below).
      {"wheel_encoder", {{}, {}, 0}},
  };
  return wiring;
}

// `period` rounded up to a whole number of master steps (at least one).
cosim::TimeNs WholeMasterSteps(cosim::TimeNs period, cosim::TimeNs master_step) {
  if (master_step <= 0) return period;
  return std::max<cosim::TimeNs>(1, (period + master_step - 1) / master_step) * master_step;
}

// The mount's pose as the sensor unit's parameters, each reported at the
// robot file's key it comes from (mount `index` of sensor_mounts) when a
// problem is found in it.
void SetMountParameters(SystemBuilder& b, const RobotFile& file, std::size_t index) {
  const models::SensorMount& m = file.robot.sensor_mounts[index];
  Parameters& params = b.Params(m.name);
  const std::string prefix = JoinPath(JoinPath("units", m.name), "parameters");
  const std::string mount = JoinPath("sensor_mounts", std::to_string(index));
  const auto set = [&](const char* param, double value, const char* key) {
    params[param] = value;
    b.Origin(JoinPath(prefix, param), file.At(JoinPath(mount, key)));
  };
  set("mount_x", m.x_m, "x_m");
  set("mount_y", m.y_m, "y_m");
  if (m.kind == "px4flow") {
    // Looks straight down: only its place on the planform, its height and
    // its heading about the vertical matter.
    set("mount_height", m.z_m, "z_m");
    set("mount_yaw", m.yaw_rad, "yaw_deg");
    return;
  }
  set("mount_z", m.z_m, "z_m");
  set("mount_roll", m.roll_rad, "roll_deg");
  set("mount_pitch", m.pitch_rad, "pitch_deg");
  set("mount_yaw", m.yaw_rad, "yaw_deg");
}

// A wheel encoder reads every steering joint, then every drive joint, of
// the chassis: its channels in that order.
void WireEncoder(SystemBuilder& b, const std::string& name, const Signals& s) {
  const std::size_t steer = s.steer_motor_element.size();
  const std::size_t drive = s.drive_motor_element.size();
  b.Params(name)["channels"] = static_cast<int>(steer + drive);
  for (std::size_t j = 0; j < steer; ++j) {
    b.Connect(Element(kChassis, "steer_angle", j), Element(name, "angle", j));
  }
  for (std::size_t j = 0; j < drive; ++j) {
    b.Connect(Element(kChassis, "drive_angle", j), Element(name, "angle", steer + j));
  }
}

}  // namespace

void AddSensors(SystemBuilder& b, const RobotFile& file, Signals& s) {
  YamlReader& r = b.reader();
  const models::RobotDescription& robot = file.robot;
  std::vector<std::string> keys = {"default", kBeltGroundTruth};
  for (const auto& m : robot.sensor_mounts) keys.push_back(m.name);
  const YAML::Node section = b.Section(b.root(), "", "sensors", keys);
  const bool by_default = r.Boolean(section, "sensors", "default", true);

  // A sensor's entry: true/false, or a map of step_s, model and parameters.
  struct Choice {
    bool on = false;
    YAML::Node node;  // the map, if one was given
  };
  // A map's keys are checked whether the sensor ends up on or off.
  const auto choice = [&](const std::string& name, const std::vector<std::string>& extra_keys) {
    Choice c{by_default, YAML::Node()};
    const YAML::Node entry = Child(section, name);
    const std::string path = JoinPath("sensors", name);
    if (!entry.IsDefined() || entry.IsNull()) return c;
    if (entry.IsScalar()) {
      if (const auto on = r.AsBoolean(entry, path)) c.on = *on;
      return c;
    }
    if (!r.ExpectMap(entry, path)) return c;
    std::vector<std::string> allowed = {"enabled", "step_s", "model", "parameters"};
    allowed.insert(allowed.end(), extra_keys.begin(), extra_keys.end());
    r.CheckKeys(entry, path, allowed);
    c.on = r.Boolean(entry, path, "enabled", true);
    c.node = entry;
    return c;
  };
  // The scenario's step_s, model and parameters on top of the mount's.
  const auto apply = [&](const std::string& name, const Choice& c, cosim::TimeNs step,
                         const std::set<std::string>& derived) {
    const std::string path = JoinPath("sensors", name);
    if (c.node.IsMap()) {
      if (Child(c.node, "model").IsDefined()) {
        b.Params(name)["model"] = ParameterValue(Child(c.node, "model"));
        b.Derived(JoinPath(JoinPath(JoinPath("units", name), "parameters"), "model"), c.node, path,
                  "model");
      }
      if (Child(c.node, "step_s").IsDefined()) {
        step = r.Time(c.node, path, "step_s", 0.0, {0.0, 10.0, true});
        b.Derived(JoinPath(JoinPath("units", name), "step_s"), c.node, path, "step_s");
      }
      const YAML::Node params = Child(c.node, "parameters");
      if (params.IsDefined() && !params.IsNull() &&
          r.ExpectMap(params, JoinPath(path, "parameters"))) {
        // The scenario may override what the robot file says, but not what
        // the assembly derives (the mount's pose, channels, connections).
        Parameters& merged = b.Params(name);
        const std::string prefix = JoinPath(JoinPath("units", name), "parameters");
        for (const auto& kv : params) {
          const std::string key = kv.first.Scalar();
          if (derived.count(key) != 0) {
            r.Error(kv.second, JoinPath(JoinPath(path, "parameters"), key),
                    "the assembly derives '" + key + "' from the robot's sensor mount (pose, "
                    "joints): change the mount in " + file.robot.file + " instead");
            continue;
          }
          merged[key] = ParameterValue(kv.second);
          b.Origin(JoinPath(prefix, key), {kv.second, JoinPath(JoinPath(path, "parameters"), key),
                                           ""});
        }
      }
    }
    if (step > 0) b.SetStep(name, step);
  };

  const cosim::TimeNs control_period = b.ControlPeriod();
  for (std::size_t i = 0; i < robot.sensor_mounts.size(); ++i) {
    const models::SensorMount& m = robot.sensor_mounts[i];
    const bool laser = m.kind == "laser_scanner";
    const Choice c = choice(m.name, laser ? std::vector<std::string>{"snapshot_s"}
                                          : std::vector<std::string>{});
    if (!c.on) continue;
    if (b.HasUnit(m.name)) {
      r.Error(Child(section, m.name).IsDefined() ? Child(section, m.name) : section,
              JoinPath("sensors", m.name),
              "the robot's sensor mount '" + m.name + "' is named like another unit of the "
              "scenario: rename the mount in " + robot.file);
      continue;
    }
    const auto wiring = Wiring().find(m.kind);
    if (wiring == Wiring().end()) continue;  // the robot file checked the kind
    b.Unit(m.name, m.kind);
    Parameters& params = b.Params(m.name);
    const std::string mount_path = JoinPath("sensor_mounts", std::to_string(i));
    if (!m.model.empty()) {
      params["model"] = m.model;
      b.Origin(JoinPath(JoinPath(JoinPath("units", m.name), "parameters"), "model"),
               {YAML::Node(), JoinPath(mount_path, "model"), robot.file});
    }
    if (m.kind == "wheel_encoder") {
      WireEncoder(b, m.name, s);
    } else {
      SetMountParameters(b, file, i);
    }
    std::set<std::string> derived;
    for (const auto& [key, value] : params) {
      if (key != "model") derived.insert(key);
    }
    b.MergeSettings(m.name, file.sensor_settings[i], robot.file,
                    JoinPath(mount_path, "parameters"));
    for (const auto& [from, to] : wiring->second.chassis_inputs) {
      b.Connect(Signal(kChassis, from), Signal(m.name, to));
    }
    if (s.belt_count > 0) {
      for (const auto& [from, to] : wiring->second.belt_inputs) {
        b.Connect(Signal(kBelt, from), Signal(m.name, to));
      }
    }
    // The step and where it comes from (a master-step problem with it is
    // reported there): the mount's step_s, the control period (encoders),
    // the kind's rate as a whole number of master steps, or the master's.
    const std::string step_key = JoinPath(JoinPath("units", m.name), "step_s");
    cosim::TimeNs step = 0;
    if (m.step_ns > 0) {
      step = m.step_ns;
      b.Origin(step_key, {YAML::Node(), JoinPath(mount_path, "step_s"), robot.file});
    } else if (m.kind == "wheel_encoder") {
      step = control_period;
      b.Derived(step_key, Child(b.root(), "control"), "control", "period_s");
    } else if (wiring->second.default_step > 0) {
      step = WholeMasterSteps(wiring->second.default_step, b.MasterStep());
      b.Origin(step_key, {section, JoinPath(JoinPath("sensors", m.name), "step_s"), ""});
    }
    apply(m.name, c, step, derived);
    if (laser && c.node.IsMap() && Child(c.node, "snapshot_s").IsDefined()) {
      // The scan it has completed at this time is drawn (scan.png): its
      // ranges are recorded with the rest.
      s.scan_unit = m.name;
      s.scan_time_s =
          r.Real(c.node, JoinPath("sensors", m.name), "snapshot_s", std::nullopt, {0.0, 1e9});
      s.recorded.push_back(Signal(m.name, "scan_time"));
      s.recorded.push_back(Signal(m.name, "ranges"));
    }
    s.sensors.push_back(m);
  }

  // Paper 1's ground truth of the line: a free wheel with a quadrature
  // encoder on the belt, mounted off the robot.
  const Choice gt = choice(kBeltGroundTruth, {"belt"});
  if (gt.on && s.belt_count > 0) {
    const std::string path = JoinPath("sensors", kBeltGroundTruth);
    const std::int64_t belt =
        gt.node.IsMap()
            ? r.Integer(gt.node, path, "belt", 0, 0, static_cast<std::int64_t>(s.belt_count) - 1)
            : 0;
    b.Unit(kBeltGroundTruth, "belt_encoder");
    b.Params(kBeltGroundTruth)["model"] = "belt_ground_truth_encoder";
    b.Connect(Element(kBelt, "travel", static_cast<std::size_t>(belt)),
              Signal(kBeltGroundTruth, "travel"));
    // Sampled at the control period (ASSUMPTION: paper 1 gives no rate for
    // its Arduino; the controllers' 50 Hz shows a belt start of ~1 s well).
    b.Derived(JoinPath(JoinPath("units", kBeltGroundTruth), "step_s"), Child(b.root(), "control"),
              "control", "period_s");
    apply(kBeltGroundTruth, gt, control_period, {});
    s.recorded.push_back(Signal(kBeltGroundTruth, "speed"));
    s.belt_ground_truth = Signal(kBeltGroundTruth, "speed");
    s.belt_ground_truth_belt = static_cast<int>(belt);
  } else if (const YAML::Node asked = Child(section, kBeltGroundTruth);
             asked.IsDefined() && !asked.IsNull() && gt.on && s.belt_count == 0) {
    r.Error(asked, JoinPath("sensors", kBeltGroundTruth),
            "the scene has no belts for the belt's ground-truth sensor to measure");
  }
}

}  // namespace linesim::loader::assembly
