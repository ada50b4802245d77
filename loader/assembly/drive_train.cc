#include <limits>
#include <map>

#include "loader/assembly/concerns.h"

namespace linesim::loader::assembly {

namespace {

// The motors of every group as one dc_motor unit: one CVODE system
// restarted once per controller cycle instead of once per group. Each
// element takes its group's motor model (the gear included) as element
// arrays.
void AddMotors(SystemBuilder& b, const RobotFile& file) {
  const models::RobotDescription& robot = file.robot;
  const auto motors = robot.Motors();
  b.Unit(kMotors, "dc_motor");
  Parameters& p = b.Params(kMotors);
  p["count"] = motors.size();
  // The chassis owns the mechanics; the motors get its joint rates.
  p["mode"] = "current_only";
  std::map<std::string, std::vector<double>> arrays;
  for (std::size_t e = 0; e < motors.size(); ++e) {
    for (const auto& [key, value] : robot.motor_groups[motors[e].first].motor) {
      auto& values = arrays[key];
      values.resize(motors.size(), std::numeric_limits<double>::quiet_NaN());
      values[e] = value;
    }
  }
  // The robot file checked that every group's model sets the same keys.
  // Each element's value is reported, when a problem is found in it, at its
  // group's model file (the gear at the group in the robot file).
  const std::string prefix = "units.motors.parameters";
  for (const auto& [key, values] : arrays) {
    p[key] = values;
    b.Origin(JoinPath(prefix, key), key == "gear_ratio" || key == "gear_efficiency"
                                        ? file.At(JoinPath("motor_groups.0", key))
                                        : file.MotorAt(0, key));
    for (std::size_t e = 0; e < motors.size(); ++e) {
      const std::size_t g = motors[e].first;
      const std::string expanded = JoinPath(JoinPath(prefix, key), std::to_string(e));
      if (key == "gear_ratio" || key == "gear_efficiency") {
        b.Origin(expanded, file.At(JoinPath(JoinPath("motor_groups", std::to_string(g)), key)));
      } else {
        b.Origin(expanded, file.MotorAt(g, key));
      }
    }
  }
  b.MergeSettings(kMotors, file.motor_settings, robot.file, "motors");
}

// Each wheel's tread (the robot file's treads entry it names) and its
// friction on every scene surface: the surface's pair for the tread's
// material, else the surface's own friction.
void AddTreads(SystemBuilder& b, const RobotFile& file, const models::Scene& scene) {
  const models::RobotDescription& robot = file.robot;
  Parameters& c = b.Params(kChassis);
  const std::string cp = "units.chassis.parameters";
  const std::pair<const char*, double models::TreadDescription::*> fields[] = {
      {"slip_stiffness", &models::TreadDescription::slip_stiffness},
      {"cornering_stiffness", &models::TreadDescription::cornering_stiffness},
      {"longitudinal_relaxation", &models::TreadDescription::longitudinal_relaxation_m},
      {"lateral_relaxation", &models::TreadDescription::lateral_relaxation_m},
      {"damping_ratio", &models::TreadDescription::damping_ratio},
      {"patch_length", &models::TreadDescription::patch_length_m},
      {"patch_width", &models::TreadDescription::patch_width_m}};
  const char* keys[] = {"slip_stiffness",       "cornering_stiffness", "longitudinal_relaxation_m",
                        "lateral_relaxation_m", "damping_ratio",       "patch_length_m",
                        "patch_width_m"};
  for (std::size_t f = 0; f < std::size(fields); ++f) {
    const std::string param = std::string("tread_") + fields[f].first;
    std::vector<double> values;
    for (std::size_t k = 0; k < robot.wheels.size(); ++k) {
      const models::WheelDescription& w = robot.wheels[k];
      values.push_back(w.tread.*fields[f].second);
      b.Origin(JoinPath(JoinPath(cp, param), std::to_string(k)),
               file.At(JoinPath(JoinPath("treads", w.tread.name), keys[f])));
    }
    c[param] = values;
    b.Origin(JoinPath(cp, param), file.At("treads"));
  }
  std::vector<double> friction;
  for (const models::WheelDescription& w : robot.wheels) {
    for (const models::Surface& s : scene.surfaces)
      friction.push_back(s.FrictionFor(w.tread.material));
  }
  c["wheel_friction"] = friction;
}

}  // namespace

Signals AddDriveTrain(SystemBuilder& b, const RobotFile& file, const StartPose& start,
                      const models::Scene& scene, RobotInfo& info) {
  const models::RobotDescription& robot = file.robot;
  Signals s;
  const auto motors = robot.Motors();
  std::map<std::string, std::size_t> element;
  for (std::size_t e = 0; e < motors.size(); ++e) element[motors[e].second] = e;

  // The chassis's joints in motor order: steering joint k is the k-th motor
  // that steers a wheel, drive joint k the k-th that drives one.
  std::map<std::string, int> steer_joint, drive_joint;
  for (const auto& [group, name] : motors) {
    for (const auto& w : robot.wheels) {
      if (w.steer_motor == name && !steer_joint.contains(name)) {
        steer_joint[name] = static_cast<int>(s.steer_motor_element.size());
        s.steer_motor_element.push_back(element.at(name));
      }
      if (w.drive_motor == name && !drive_joint.contains(name)) {
        drive_joint[name] = static_cast<int>(s.drive_motor_element.size());
        s.drive_motor_element.push_back(element.at(name));
      }
    }
  }
  std::vector<double> x, y, radius;
  for (const auto& w : robot.wheels) {
    s.wheel_steer_joint.push_back(w.steer_motor ? steer_joint.at(*w.steer_motor) : -1);
    s.wheel_drive_joint.push_back(drive_joint.at(w.drive_motor));
    x.push_back(w.x_m);
    y.push_back(w.y_m);
    radius.push_back(w.radius_m);
  }

  b.Unit(kChassis, "chassis");
  Parameters& c = b.Params(kChassis);
  c["wheel_count"] = robot.wheels.size();
  c["steer_motor"] = IntList(s.wheel_steer_joint);
  c["drive_motor"] = IntList(s.wheel_drive_joint);
  c["body_length"] = robot.body.length_m;
  c["body_width"] = robot.body.width_m;
  c["body_height"] = robot.body.height_m;
  c["body_bottom"] = robot.body.bottom_m;
  c["mass"] = robot.body.mass_kg;
  c["com_height"] = robot.body.com_height_m;
  // One mass for every wheel module (the robot file checked that the wheels
  // agree): the chassis lumps it into each wheel.
  c["module_mass"] = robot.wheels.front().mass_kg;
  c["wheel_x"] = x;
  c["wheel_y"] = y;
  c["wheel_radius"] = radius;
  // The rotor inertia each joint sees through its gear (eta N^2 J).
  for (const auto& [joint, joints] :
       {std::pair{"steer", &s.steer_motor_element}, std::pair{"drive", &s.drive_motor_element}}) {
    if (joints->empty()) continue;
    const auto& group = robot.motor_groups[motors[joints->front()].first];
    c[std::string(joint) + "_rotor_inertia"] = group.Joint().reflected_inertia_kgm2;
  }
  // A payload on the body (the robot file's, or the scenario's
  // robot.payload in its place).
  if (const auto& p = robot.payload; p && p->mass_kg > 0.0) {
    c["payload_mass"] = p->mass_kg;
    c["payload_position"] = std::vector<double>{p->x_m, p->y_m, p->z_m};
    c["payload_size"] = std::vector<double>{p->length_m, p->width_m, p->height_m};
  }
  // Each value at the robot file's key it comes from.
  const std::string cp = "units.chassis.parameters";
  for (const auto& [param, key] :
       {std::pair{"body_length", "body.length_m"}, std::pair{"body_width", "body.width_m"},
        std::pair{"body_height", "body.height_m"}, std::pair{"body_bottom", "body.bottom_m"},
        std::pair{"mass", "body.mass_kg"}, std::pair{"com_height", "body.com_height_m"},
        std::pair{"module_mass", "wheels.0.mass_kg"}}) {
    b.Origin(JoinPath(cp, param), file.At(key));
  }
  for (const char* param : {"wheel_x", "wheel_y", "wheel_radius"}) {
    b.Origin(JoinPath(cp, param), file.At("wheels"));
  }
  for (std::size_t k = 0; k < robot.wheels.size(); ++k) {
    const std::string wheel = JoinPath("wheels", std::to_string(k));
    for (const auto& [param, key] : {std::pair{"wheel_x", "x_m"}, std::pair{"wheel_y", "y_m"},
                                     std::pair{"wheel_radius", "radius_m"}}) {
      b.Origin(JoinPath(JoinPath(cp, param), std::to_string(k)), file.At(JoinPath(wheel, key)));
    }
  }
  if (robot.payload && robot.payload->mass_kg > 0.0) {
    // The scenario's robot.payload, or else the robot file's payload.
    const YAML::Node scenario = Child(Child(b.root(), "robot"), "payload");
    const auto at = [&](const std::string& key) {
      if (!scenario.IsDefined()) return file.At(JoinPath("payload", key));
      const YAML::Node node = Child(scenario, key);
      return loader::Origin{node.IsDefined() ? node : scenario, JoinPath("robot.payload", key), ""};
    };
    b.Origin(JoinPath(cp, "payload_mass"), at("mass_kg"));
    const char* position[] = {"x_m", "y_m", "z_m"};
    const char* size[] = {"length_m", "width_m", "height_m"};
    for (std::size_t d = 0; d < 3; ++d) {
      b.Origin(JoinPath(JoinPath(cp, "payload_position"), std::to_string(d)), at(position[d]));
      b.Origin(JoinPath(JoinPath(cp, "payload_size"), std::to_string(d)), at(size[d]));
    }
    b.Origin(JoinPath(cp, "payload_position"), at("x_m"));
    b.Origin(JoinPath(cp, "payload_size"), at("length_m"));
  }
  AddTreads(b, file, scene);
  c["initial_x"] = start.x_m;
  c["initial_y"] = start.y_m;
  c["initial_yaw"] = start.yaw_rad;
  b.MergeSettings(kChassis, file.chassis_settings, robot.file, "chassis");
  const YAML::Node pose = Child(Child(b.root(), "robot"), "pose");
  b.Derived("units.chassis.parameters.initial_x", pose, "robot.pose", "x_m");
  b.Derived("units.chassis.parameters.initial_y", pose, "robot.pose", "y_m");
  b.Derived("units.chassis.parameters.initial_yaw", pose, "robot.pose", "yaw_deg");

  AddMotors(b, file);
  const auto wire = [&](const char* joint, const std::vector<std::size_t>& elements) {
    // The torque-speed line, which the chassis applies implicitly (its
    // joint motor rows): stable at any master step with tyres that creep.
    for (std::size_t k = 0; k < elements.size(); ++k) {
      b.Connect(Element(kMotors, "line_torque", elements[k]),
                Element(kChassis, std::string(joint) + "_torque", k));
      b.Connect(Element(kMotors, "line_slope", elements[k]),
                Element(kChassis, std::string(joint) + "_torque_slope", k));
      b.Connect(Element(kMotors, "line_rate", elements[k]),
                Element(kChassis, std::string(joint) + "_torque_rate", k));
      b.Connect(Element(kChassis, std::string(joint) + "_rate", k),
                Element(kMotors, "shaft_speed", elements[k]));
    }
  };
  wire("steer", s.steer_motor_element);
  wire("drive", s.drive_motor_element);

  s.true_position = Signal(kChassis, "position");
  s.true_yaw = Signal(kChassis, "yaw");
  s.true_surface_velocity = Signal(kChassis, "wheel_surface_velocity");
  for (const char* v : {"position", "yaw", "linear_velocity", "yaw_rate"}) {
    s.recorded.push_back(Signal(kChassis, v));
  }
  if (!s.steer_motor_element.empty()) s.recorded.push_back(Signal(kChassis, "steer_angle"));
  for (const char* v : {"drive_rate", "wheel_surface", "wheel_contact"}) {
    s.recorded.push_back(Signal(kChassis, v));
  }
  s.recorded.push_back(Signal(kMotors, "current"));

  info.wheel_count = static_cast<int>(robot.wheels.size());
  return s;
}

}  // namespace linesim::loader::assembly
