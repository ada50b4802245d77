#include "loader/assembly/concerns.h"

namespace linesim::loader::assembly {

namespace {

// What a controller's feedforward needs of a motor group: the back-EMF at
// the joint (k_e N), and the voltage per unit of joint acceleration for a
// load of inertia `load_kgm2` at the joint, (J_load + eta N^2 J_rotor) /
// (eta N k_t / R), the stall torque per volt.
struct Feedforward {
  double rate_v_per_rad_s;
  double acceleration_v_per_rad_s2;
};

Feedforward JointFeedforward(const models::MotorGroup& g, double load_kgm2) {
  const models::JointDrive d = g.Joint();
  const double torque_per_volt = d.torque_per_amp_nm / g.Value("resistance");
  return {d.back_emf_v_per_rad_s, (load_kgm2 + d.reflected_inertia_kgm2) / torque_per_volt};
}

const models::MotorGroup& GroupOf(const models::RobotDescription& robot, const std::string& motor) {
  for (const auto& g : robot.motor_groups) {
    for (const auto& m : g.motors) {
      if (m == motor) return g;
    }
  }
  return robot.motor_groups.front();  // the robot file checked every name
}

// Wires the controller's per-wheel joint inputs to the chassis: whole
// arrays when the controller's wheel order is the chassis's joint order,
// element by element otherwise.
void ConnectJoints(SystemBuilder& b, const std::string& variable, const std::vector<int>& joints) {
  bool identity = true;
  for (std::size_t i = 0; i < joints.size(); ++i) identity &= joints[i] == static_cast<int>(i);
  if (identity) {
    b.Connect(Signal(kChassis, variable), Signal(kWheelController, variable));
    return;
  }
  for (std::size_t i = 0; i < joints.size(); ++i) {
    b.Connect(Element(kChassis, variable, static_cast<std::size_t>(joints[i])),
              Element(kWheelController, variable, i));
  }
}

void AddSwerve(SystemBuilder& b, const RobotFile& file, bool compensation, Signals& s) {
  const models::RobotDescription& robot = file.robot;
  b.Unit(kWheelController, "wheel_controller");
  Parameters& p = b.Params(kWheelController);
  const std::size_t n = robot.wheels.size();
  p["wheel_count"] = n;
  SetWheelPositions(p, robot);
  const models::WheelDescription& w0 = robot.wheels.front();
  p["wheel_radius"] = w0.radius_m;
  b.Origin(JoinPath(JoinPath(JoinPath("units", kWheelController), "parameters"), "wheel_radius"),
           file.At("wheels.0.radius_m"));
  // Feedforwards from the motor files: the steering module's own inertia,
  // and for a drive wheel its share of the robot's mass at the rim.
  const Feedforward steer =
      JointFeedforward(GroupOf(robot, *w0.steer_motor), w0.steer_inertia_kgm2);
  const double share_kg = robot.body.mass_kg / static_cast<double>(n);
  const Feedforward drive =
      JointFeedforward(GroupOf(robot, w0.drive_motor), share_kg * w0.radius_m * w0.radius_m);
  p["steer_feedforward"] = steer.rate_v_per_rad_s;
  p["steer_acceleration_feedforward"] = steer.acceleration_v_per_rad_s2;
  p["drive_feedforward"] = drive.rate_v_per_rad_s;
  p["drive_acceleration_feedforward"] = drive.acceleration_v_per_rad_s2;
  p["compensation"] = compensation;
  b.MergeSettings(kWheelController, file.controller_settings, robot.file, "controller");
  b.RequireParameters(kWheelController, file.controller_settings, robot.file, "controller");
  for (std::size_t i = 0; i < n; ++i) {
    const auto steer_joint = static_cast<std::size_t>(s.wheel_steer_joint[i]);
    const auto drive_joint = static_cast<std::size_t>(s.wheel_drive_joint[i]);
    b.Connect(Element(kWheelController, "steer_voltage", i),
              Element(kMotors, "voltage", s.steer_motor_element[steer_joint]));
    b.Connect(Element(kWheelController, "drive_voltage", i),
              Element(kMotors, "voltage", s.drive_motor_element[drive_joint]));
  }
  ConnectJoints(b, "steer_angle", s.wheel_steer_joint);
  ConnectJoints(b, "steer_rate", s.wheel_steer_joint);
  ConnectJoints(b, "drive_rate", s.wheel_drive_joint);
  // sensing.surface_velocity: none gives the controllers no surface
  // velocity: the input stays 0 (the nominal system).
  if (!s.surface_velocity.empty()) {
    b.Connect(s.surface_velocity, Signal(kWheelController, "surface_velocity"));
  }
  for (const char* v : {"steer_voltage", "drive_voltage"}) {
    s.recorded.push_back(Signal(kWheelController, v));
  }
}

void AddDifferential(SystemBuilder& b, const RobotFile& file, const YAML::Node& control,
                     bool compensation, Signals& s) {
  const models::RobotDescription& robot = file.robot;
  if (compensation) {
    b.reader().Error(Child(control, "compensation"), "control.compensation",
                     "robot '" + robot.name +
                         "' is a differential base: its fixed wheels cannot "
                         "cancel the surface's cross velocity (Algorithm 1 needs steered wheels); "
                         "set control.compensation: false");
  }
  b.Unit(kWheelController, "diff_drive_controller");
  Parameters& p = b.Params(kWheelController);
  // Left (y > 0) and right drive joints; the robot file checked one each.
  std::vector<int> joints(2, 0);
  const models::WheelDescription* left = nullptr;
  std::size_t left_index = 0;
  for (std::size_t i = 0; i < robot.wheels.size(); ++i) {
    const bool is_left = robot.wheels[i].y_m > 0.0;
    joints[is_left ? 0 : 1] = s.wheel_drive_joint[i];
    if (is_left) {
      left = &robot.wheels[i];
      left_index = i;
    }
  }
  p["wheel_radius"] = left->radius_m;
  b.Origin(JoinPath(JoinPath(JoinPath("units", kWheelController), "parameters"), "wheel_radius"),
           file.At(JoinPath(JoinPath("wheels", std::to_string(left_index)), "radius_m")));
  // Each side's motor moves half the robot (its wheels' share at the rim).
  const Feedforward drive =
      JointFeedforward(GroupOf(robot, left->drive_motor),
                       0.5 * robot.body.mass_kg * left->radius_m * left->radius_m);
  p["drive_feedforward"] = drive.rate_v_per_rad_s;
  p["drive_acceleration_feedforward"] = drive.acceleration_v_per_rad_s2;
  b.MergeSettings(kWheelController, file.controller_settings, robot.file, "controller");
  b.RequireParameters(kWheelController, file.controller_settings, robot.file, "controller");
  for (std::size_t side = 0; side < 2; ++side) {
    const auto joint = static_cast<std::size_t>(joints[side]);
    b.Connect(Element(kWheelController, "drive_voltage", side),
              Element(kMotors, "voltage", s.drive_motor_element[joint]));
  }
  ConnectJoints(b, "drive_rate", joints);
  s.recorded.push_back(Signal(kWheelController, "drive_voltage"));
}

}  // namespace

void AddControl(SystemBuilder& b, const RobotFile& file, Signals& s) {
  const YAML::Node control = b.Section(b.root(), "", "control", {"compensation", "period_s"});
  YamlReader& r = b.reader();
  // Algorithm 1 needs steered wheels: on by default where the robot has
  // them, off for a differential base (which refuses it when asked).
  const bool steered = file.robot.controller == models::ControllerKind::kSwerve;
  const bool compensation = r.Boolean(control, "control", "compensation", steered);
  // The Rob@Work 3 control cycle is 20 ms (IPA cob_control configuration).
  const cosim::TimeNs period =
      r.Time(control, "control", "period_s", cosim::NsToSeconds(kControlPeriod), {0.0, 10.0, true});
  // The master checks the controllers' step against its own; its problems
  // are reported here, where the step comes from.
  for (const char* name : {kWheelController, kPathFollower}) {
    b.SetStep(name, period);
    b.Derived(JoinPath(JoinPath("units", name), "step_s"), control, "control", "period_s");
  }
  if (compensation && s.surface_velocity.empty()) {
    r.Error(Child(control, "compensation").IsDefined() ? Child(control, "compensation") : control,
            "control.compensation",
            "Algorithm 1 needs the surface velocity, and sensing.surface_velocity: none gives "
            "the controllers none (the nominal system): set control.compensation: false");
  }
  if (steered) {
    AddSwerve(b, file, compensation, s);
  } else {
    AddDifferential(b, file, control, compensation, s);
  }
  s.velocity_command_input = Signal(kWheelController, "velocity_command");
  s.yaw_rate_command_input = Signal(kWheelController, "yaw_rate_command");
}

}  // namespace linesim::loader::assembly
