#pragma once

#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "models/drive_train.h"

/// The typed description of a robot (models/robots/*.yaml): its body, its
/// wheels and which motors steer and drive them, the motor groups, the kind
/// of wheel controller, and the frames where sensors are mounted. Read by
/// the loader (loader/robot_file.h); the robot scenario's assembly turns it
/// into the parameters of the chassis, motor and controller units, which
/// take no robot-specific default of their own. base_link: x forward, y
/// left, z up, origin at the planform centre on the floor.
namespace linesim::models {

/// The body: where its solid parts are (a box on the planform centre, from
/// its underside bottom_m above the floor to bottom_m + height_m: what the
/// scene, the other robots' lasers and chassis and the clearances meet) and
/// where its mass is (mass_kg, com_height_m), two separate facts: a robot
/// whose batteries sit low has its centre of mass well below the middle of
/// its box.
struct BodyDescription {
  double length_m = 0.0;  // along base_link x
  double width_m = 0.0;
  double height_m = 0.0;
  /// The box's underside above the floor (base_link z): the ground
  /// clearance under the body.
  double bottom_m = 0.0;
  /// The whole robot, wheels included.
  double mass_kg = 0.0;
  /// Height of the body's centre of mass (wheels excluded) above the floor;
  /// within the box.
  double com_height_m = 0.0;

  double top_m() const { return bottom_m + height_m; }
};

/// A load fixed rigidly on the body (paper 2's Husky carries a UR10 arm on a
/// mount plate): the chassis adds it to the body's mass and inertia.
struct PayloadDescription {
  double mass_kg = 0.0;
  /// Its centre of mass in base_link.
  double x_m = 0.0, y_m = 0.0, z_m = 0.0;
  /// A box about its centre of mass (its inertia, and what it collides with
  /// in the scene); all 0: a point mass that collides with nothing.
  double length_m = 0.0, width_m = 0.0, height_m = 0.0;
};

/// A wheel's tread: a transient brush tyre (units/chassis/floor_world.h).
/// Slip stiffnesses are per unit of the wheel's static load (C / F_z), so a
/// tread keeps its creep slope under another payload.
struct TreadDescription {
  std::string name;
  /// Its material, which pairs with a scene surface's tread_friction.
  std::string material;
  double slip_stiffness = 0.0;           // C_kappa / F_z, per unit slip
  double cornering_stiffness = 0.0;      // C_alpha / F_z, 1/rad
  double longitudinal_relaxation_m = 0.0;
  double lateral_relaxation_m = 0.0;
  double damping_ratio = 0.0;
  double patch_length_m = 0.0;           // along the rolling direction
  double patch_width_m = 0.0;
};

struct WheelDescription {
  std::string name;
  /// Contact point below the wheel centre (the steering axis of a
  /// steerable wheel) in base_link.
  double x_m = 0.0;
  double y_m = 0.0;
  double radius_m = 0.0;
  double width_m = 0.0;
  /// Everything that turns with the wheel or its steering module, lumped
  /// into the wheel.
  double mass_kg = 0.0;
  /// A steerable wheel's module inertia about its steering axis (the
  /// controller's steering feedforward); 0 for a fixed wheel.
  double steer_inertia_kgm2 = 0.0;
  /// Names of motors in the motor groups; no steer motor: a fixed wheel.
  /// Wheels naming the same drive motor share it (belt or chain).
  std::optional<std::string> steer_motor;
  std::string drive_motor;
  /// Its tread (the robot file's treads entry it names).
  TreadDescription tread;
};

/// Motors of one model behind one kind of gear.
struct MotorGroup {
  std::string name;
  /// The motor's model file (models/motors) as read: dc_motor parameter
  /// name to value, the gear of this group included.
  std::map<std::string, double> motor;
  std::string model_file;
  double gear_ratio = 1.0;
  double gear_efficiency = 1.0;
  std::vector<std::string> motors;

  /// A value of the motor model (NaN when the file does not give it).
  double Value(const std::string& key) const {
    const auto it = motor.find(key);
    return it == motor.end() ? std::numeric_limits<double>::quiet_NaN() : it->second;
  }
  /// What a joint sees of one of these motors through the group's gear.
  JointDrive Joint() const {
    return ReflectThroughGear(Value("rotor_inertia"), Value("torque_constant"), gear_ratio,
                              gear_efficiency);
  }
};

/// A frame on the robot where a sensor is mounted (its type is the
/// sensor's own description).
struct SensorMount {
  std::string name;
  /// The sensor unit type: px4flow, laser_scanner, imu, wheel_encoder.
  std::string kind;
  /// The device's model file in models/sensors (sick_s300), or empty.
  std::string model;
  /// The sensor's communication step (ns, as BeltSwitch times); 0: the
  /// kind's default.
  std::int64_t step_ns = 0;
  /// Pose in base_link (a wheel encoder has none: it reads the joints).
  double x_m = 0.0, y_m = 0.0, z_m = 0.0;
  double roll_rad = 0.0, pitch_rad = 0.0, yaw_rad = 0.0;
};

/// The sensor kinds a robot description may mount, and whether a mount of
/// that kind has a pose on the body.
inline bool SensorKindHasPose(const std::string& kind) { return kind != "wheel_encoder"; }
inline const std::vector<std::string>& SensorKinds() {
  static const std::vector<std::string> kinds = {"px4flow", "laser_scanner", "imu",
                                                 "wheel_encoder"};
  return kinds;
}

enum class ControllerKind { kSwerve, kDifferential };

struct RobotDescription {
  std::string name;
  std::string description;
  std::string file;
  BodyDescription body;
  std::vector<WheelDescription> wheels;
  std::vector<MotorGroup> motor_groups;
  ControllerKind controller = ControllerKind::kSwerve;
  std::vector<SensorMount> sensor_mounts;
  /// None unless the robot file's `payload` or the robot scenario's
  /// `robot.payload` gives one.
  std::optional<PayloadDescription> payload;

  /// Every motor of every group, in group order: the elements of the one
  /// dc_motor unit that simulates them. Each entry: group index, motor name.
  std::vector<std::pair<std::size_t, std::string>> Motors() const {
    std::vector<std::pair<std::size_t, std::string>> all;
    for (std::size_t g = 0; g < motor_groups.size(); ++g) {
      for (const auto& m : motor_groups[g].motors) all.emplace_back(g, m);
    }
    return all;
  }
};

}  // namespace linesim::models
