#include "units/chassis/chassis_unit.h"

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>
#include <utility>

#include "models/angle.h"
#include "models/moving_solids.h"
#include "units/chassis/floor_world.h"

namespace linesim::chassis {

namespace {

constexpr double kPi = std::numbers::pi;
// Settling before time zero: 300 steps of 1 ms (0.3 s). The slowest
// vertical mode, the body on the four contact springs (default 1e6 N/m
// each, 4e6 N/m in all), is at sqrt(4e6 / m) / 2 pi: about 29 Hz for the
// Rob@Work 3 (120 kg: 0.3 s is about 9 periods) and about 45 Hz for the
// Husky (50 kg: about 13 periods); the contact damping (1e4 N.s/m per
// point) damps it within a few periods. Kept at 300 steps: the paper-1
// numbers depend on the settled state.
constexpr double kSettleStepS = 1e-3;
constexpr int kSettleSteps = 300;
// Holding torque on every joint while settling, whatever brake_torque is.
constexpr double kSettleHoldTorqueNm = 1e4;
// Reals saved per body: position 3, quaternion 4, linear and angular
// velocity 3 each.
constexpr std::size_t kRealsPerBody = 13;

// Column c of an ODE rotation matrix (3 rows of 4).
void Column(const dReal* r, int c, double out[3]) {
  out[0] = r[c];
  out[1] = r[4 + c];
  out[2] = r[8 + c];
}

double Dot(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Yaw of a rotation matrix: heading of its x axis in the map plane.
double Yaw(const dReal* r) { return std::atan2(r[4], r[0]); }

bool AllFinite(const dReal* v, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

}  // namespace

struct ChassisUnit::Ode {
  std::unique_ptr<FloorWorld> floor;
  dBodyID body = nullptr;
  // The body's collision box and the payload's (obstacles, carried objects
  // and terrain only; nullptr: none).
  dGeomID body_geom = nullptr;
  dGeomID payload_geom = nullptr;
  // base_link's origin relative to the body's origin (the centre of mass of
  // body box and payload), in the body's frame: -c with c the centre of
  // mass in base_link.
  double base_from_com[3] = {0.0, 0.0, 0.0};
  // Slope (dz/dx, dz/dy in map) of the ground plane PlaceOnTerrain put the
  // robot on; 0 on the floor.
  double ground_slope[2] = {0.0, 0.0};
  std::vector<dBodyID> wheels;
  // Per wheel: its joint to the body, hinge2 when steered, else hinge.
  std::vector<dJointID> joints;
  std::vector<bool> steered;
  // Angular motors coupling the wheels of a drive motor to its first wheel.
  std::vector<dJointID> couplings;
  std::vector<dGeomID> geoms;
  // Internal step for which the suspension ERP/CFM were set (0: not yet).
  double suspension_h_s = 0.0;

  Ode() = default;
  Ode(const Ode&) = delete;
  Ode& operator=(const Ode&) = delete;
  ~Ode() { Clear(); }

  // Geoms are not owned by the world; bodies and joints go with it.
  void Clear() {
    if (!floor) return;
    EnsureOdeForThisThread();
    floor->ClearGeoms();
    floor->SetBodyGeom(nullptr, 0.0);
    for (dGeomID g : geoms) dGeomDestroy(g);
    if (body_geom) dGeomDestroy(body_geom);
    if (payload_geom) dGeomDestroy(payload_geom);
    body_geom = nullptr;
    payload_geom = nullptr;
    geoms.clear();
    wheels.clear();
    joints.clear();
    steered.clear();
    couplings.clear();
    body = nullptr;
    floor.reset();
    suspension_h_s = 0.0;
    ground_slope[0] = ground_slope[1] = 0.0;
  }

  // Every body, the base first.
  dBodyID Body(std::size_t i) const { return i == 0 ? body : wheels[i - 1]; }
  std::size_t BodyCount() const { return wheels.size() + 1; }
};

namespace {

// Number of motors a per-wheel index list uses (largest index + 1). Only
// for lists that TopologyProblem accepted (every index < the wheel count).
int MotorCount(const std::vector<int>& motor) {
  int n = 0;
  for (int m : motor) n = std::max(n, m + 1);
  return n;
}

// Force limit of a drive coupling: far above any torque a wheel can take
// from the floor (mu m g r is about 200 N.m for a 500 kg robot on 0.2 m
// wheels), so that the coupled wheels never slip against each other.
constexpr double kCouplingMaxTorqueNm = 1e5;
// CFM of a coupling row: the relative spin it lets through is CFM x torque
// (1e-10 x 1e2 N.m = 1e-8 rad/s), where ODE's default world CFM (1e-5)
// would let 1e-3 rad/s through.
constexpr double kCouplingCfm = 1e-10;

}  // namespace

std::string ChassisUnit::TopologyProblem(const std::vector<int>& steer_motor,
                                         const std::vector<int>& drive_motor) {
  const std::size_t n = steer_motor.size();
  if (n < 1 || n > static_cast<std::size_t>(kMaxWheels)) {
    return "wheel_count: expected 1 to " + std::to_string(kMaxWheels) + " wheels, got " +
           std::to_string(n);
  }
  if (drive_motor.size() != n) {
    return "drive_motor: expected one entry per wheel (wheel_count " + std::to_string(n) +
           "), got " + std::to_string(drive_motor.size());
  }
  // The ranges first, before anything is sized by an index: a motor index
  // is below the wheel count (each motor serves at least one wheel).
  const int wheels = static_cast<int>(n);
  for (std::size_t k = 0; k < n; ++k) {
    const int s = steer_motor[k];
    if (s < -1 || s >= wheels) {
      return "steer_motor[" + std::to_string(k) + "]: expected a steering motor index in [0, " +
             std::to_string(wheels - 1) + "] (below the wheel count " + std::to_string(wheels) +
             ") or -1 (fixed wheel), got " + std::to_string(s);
    }
    const int d = drive_motor[k];
    if (d < 0 || d >= wheels) {
      return "drive_motor[" + std::to_string(k) + "]: expected a drive motor index in [0, " +
             std::to_string(wheels - 1) + "] (below the wheel count " + std::to_string(wheels) +
             "), got " + std::to_string(d);
    }
  }
  const int steer_count = MotorCount(steer_motor);
  const int drive_count = MotorCount(drive_motor);
  std::vector<int> steer_uses(static_cast<std::size_t>(steer_count), 0);
  std::vector<int> drive_first(static_cast<std::size_t>(drive_count), -1);
  for (std::size_t k = 0; k < n; ++k) {
    const int s = steer_motor[k];
    if (s >= 0 && ++steer_uses[static_cast<std::size_t>(s)] > 1) {
      return "steer_motor[" + std::to_string(k) + "]: steering motor " + std::to_string(s) +
             " already steers another wheel (one steered wheel per steering motor)";
    }
    const int d = drive_motor[k];
    int& first = drive_first[static_cast<std::size_t>(d)];
    if (first < 0) {
      first = static_cast<int>(k);
    } else if (s >= 0 || steer_motor[static_cast<std::size_t>(first)] >= 0) {
      return "drive_motor[" + std::to_string(k) + "]: wheels " + std::to_string(first) + " and " +
             std::to_string(k) + " share drive motor " + std::to_string(d) +
             ", which needs both fixed (steer_motor -1): coupled steered wheels are not modelled";
    }
  }
  for (int m = 0; m < steer_count; ++m) {
    if (steer_uses[static_cast<std::size_t>(m)] == 0) {
      return "steer_motor: steering motor " + std::to_string(m) +
             " steers no wheel (indices must be 0..M-1, each used)";
    }
  }
  for (int m = 0; m < drive_count; ++m) {
    if (drive_first[static_cast<std::size_t>(m)] < 0) {
      return "drive_motor: drive motor " + std::to_string(m) +
             " drives no wheel (indices must be 0..M-1, each used)";
    }
  }
  return {};
}

ChassisUnit::ChassisUnit(std::string name, std::vector<int> steer_motor,
                         std::vector<int> drive_motor, models::Scene scene, int moving_boxes,
                         int moving_cylinders)
    : cosim::Unit(kTypeName, std::move(name)),
      wheel_count_(static_cast<int>(steer_motor.size())),
      belt_count_(static_cast<int>(scene.belts.size())),
      steer_motor_(std::move(steer_motor)),
      drive_motor_(std::move(drive_motor)),
      scene_(std::move(scene)),
      ode_(std::make_unique<Ode>()) {
  if (const std::string bad = TopologyProblem(steer_motor_, drive_motor_); !bad.empty()) {
    throw cosim::UnitError(Where() + ": " + bad);
  }
  CheckScene();
  steer_motor_count_ = MotorCount(steer_motor_);
  drive_motor_count_ = MotorCount(drive_motor_);
  std::vector<char> motor_led(static_cast<std::size_t>(drive_motor_count_), 0);
  for (const int m : drive_motor_) {
    char& led = motor_led[static_cast<std::size_t>(m)];
    leads_drive_motor_.push_back(led ? 0 : 1);
    led = 1;
  }
  const auto w = static_cast<std::size_t>(wheel_count_);
  const auto b = static_cast<std::size_t>(belt_count_);
  const auto ms = static_cast<std::size_t>(steer_motor_count_);
  const auto md = static_cast<std::size_t>(drive_motor_count_);
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  body_length_ = body_width_ = body_height_ = body_bottom_ = kNaN;
  mass_ = module_mass_ = com_height_ = kNaN;
  steer_rotor_inertia_ = drive_rotor_inertia_ = kNaN;
  wheel_radius_.assign(w, kNaN);
  wheel_x_.assign(w, kNaN);
  wheel_y_.assign(w, kNaN);
  if (ms == 0) steer_rotor_inertia_ = 0.0;  // no steering motor to reflect
  steer_torque_.assign(ms, 0.0);
  drive_torque_.assign(md, 0.0);
  steer_torque_slope_.assign(ms, 0.0);
  steer_torque_rate_.assign(ms, 0.0);
  drive_torque_slope_.assign(md, 0.0);
  drive_torque_rate_.assign(md, 0.0);
  belt_velocity_.assign(2 * b, 0.0);
  belt_travel_.assign(b, 0.0);
  if (moving_boxes < 0 || moving_cylinders < 0) {
    throw cosim::UnitError(Where() + ": moving_boxes and moving_cylinders must be >= 0");
  }
  // Absent until connected (length 0; a cylinder far below the floor).
  moving_boxes_.assign(models::MovingBox::kValues * static_cast<std::size_t>(moving_boxes), 0.0);
  moving_cylinders_.assign(
      models::MovingCylinder::kValues * static_cast<std::size_t>(moving_cylinders), 0.0);
  for (std::size_t i = 0; i < moving_cylinders_.size(); i += models::MovingCylinder::kValues) {
    moving_cylinders_[i + models::MovingCylinder::kZBottom] = -2.0;
    moving_cylinders_[i + models::MovingCylinder::kZTop] = -1.0;
  }
  body_box_.assign(models::MovingBox::kValues, 0.0);
  steer_angle_.assign(ms, 0.0);
  steer_rate_.assign(ms, 0.0);
  drive_rate_.assign(md, 0.0);
  drive_rate_before_.assign(md, 0.0);
  drive_angle_.assign(md, 0.0);
  position_.assign(2, 0.0);
  position_3d_.assign(3, 0.0);
  orientation_.assign(4, 0.0);
  orientation_[0] = 1.0;
  velocity_3d_.assign(3, 0.0);
  angular_velocity_.assign(3, 0.0);
  linear_velocity_.assign(2, 0.0);
  body_linear_velocity_.assign(2, 0.0);
  payload_position_.assign(3, 0.0);
  payload_size_.assign(3, 0.0);
  wheel_surface_.assign(w, -1.0);
  wheel_surface_velocity_.assign(2 * w, 0.0);
  wheel_contact_.assign(2 * w, 0.0);

  DeclareParameters();
  DeclareSignals();
}

// The parameters, in the variable table's order.
void ChassisUnit::DeclareParameters() {
  const auto ms = static_cast<std::size_t>(steer_motor_count_);
  auto& v = variables();
  v.Parameter("body_length", "m", &body_length_,
              "body box length along base_link x (inertia and collision with objects)",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("body_width", "m", &body_width_,
              "body box width along base_link y (inertia and collision with objects)",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("body_height", "m", &body_height_,
              "body box height from body_bottom (inertia and collision with objects)",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("body_bottom", "m", &body_bottom_,
              "height of the body box's underside above base_link (the ground clearance; the "
              "box's position, whatever com_height is)",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("mass", "kg", &mass_, "total mass: body box plus all wheels",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("module_mass", "kg", &module_mass_,
              "mass of one wheel: a steered module (wheel, motors, housing) or a fixed wheel",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("com_height", "m", &com_height_,
              "height of the body's centre of mass above base_link (wheels excluded), within "
              "the body box; the body's inertia is a uniform box of the body's size about it",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("wheel_radius", "m", &wheel_radius_, "radius of each wheel (sphere contact geometry)",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("wheel_x", "m", &wheel_x_,
              "x in base_link of each wheel's steering axis (fixed wheel: axle centre)",
              cosim::Rule::Required());
  v.Parameter("wheel_y", "m", &wheel_y_,
              "y in base_link of each wheel's steering axis (fixed wheel: axle centre)",
              cosim::Rule::Required());
  v.Parameter("steer_rotor_inertia", "kg.m2", &steer_rotor_inertia_,
              "steer motor rotor inertia seen at the steering joint (eta N^2 J_rotor), added to "
              "each steered module's inertia about the axes perpendicular to the axle",
              // Robot-specific, unless no wheel is steered (0: nothing to reflect).
              ms > 0 ? cosim::Rule::NonNegative().NoDefault() : cosim::Rule::NonNegative());
  v.Parameter("drive_rotor_inertia", "kg.m2", &drive_rotor_inertia_,
              "drive motor rotor inertia seen at the wheel (eta N^2 J_rotor), added once per "
              "drive motor about the axle of its first wheel",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("payload_mass", "kg", &payload_mass_,
              "mass of a payload fixed rigidly on the body (an arm and its mount), on top of "
              "mass (default 0: none)",
              cosim::Rule::NonNegative());
  v.Parameter("payload_position", "m", &payload_position_,
              "x, y, z in base_link of the payload's centre of mass (default 0, 0, 0)",
              cosim::Rule::Finite());
  v.Parameter("payload_size", "m", &payload_size_,
              "length, width, height of the payload's box about its centre of mass: its "
              "inertia (a uniform box) and its collision with obstacles, carried objects and "
              "terrain (default 0, 0, 0: a point mass that collides with nothing)",
              cosim::Rule::NonNegative());
  v.Parameter("steer_friction", "N.m.s/rad", &steer_friction_,
              "viscous friction of the steering joint (default 0.01: small against the motor "
              "torques, it only damps a free joint)",
              cosim::Rule::NonNegative());
  v.Parameter("drive_friction", "N.m.s/rad", &drive_friction_,
              "viscous friction of each wheel joint (default 0.01, as steer_friction)",
              cosim::Rule::NonNegative());
  v.Parameter("body_friction", "1", &body_friction_,
              "Coulomb coefficient of the body box on obstacles and carried objects (default "
              "0.5: painted steel or plastic on steel, typically 0.3 to 0.6)",
              cosim::Rule::NonNegative());
  v.Parameter("contact_stiffness", "N/m", &contact_stiffness_,
              "normal stiffness of one wheel or body contact point (default 1e6: a tread "
              "deflecting 0.3 mm under 30 kg)",
              cosim::Rule::Positive());
  v.Parameter("contact_damping", "N.s/m", &contact_damping_,
              "normal damping of one contact point (default 1e4: well damped)",
              cosim::Rule::NonNegative());
  DeclareTreadParameters();
  v.Parameter("suspension_stiffness", "N/m", &suspension_stiffness_,
              "stiffness of a steered module along its steering axis (hinge2 suspension; "
              "default 1e7: a near-rigid mount)",
              cosim::Rule::Positive());
  v.Parameter("suspension_damping", "N.s/m", &suspension_damping_,
              "damping of a steered module along its steering axis (default 1e4)",
              cosim::Rule::NonNegative());
  v.Parameter("brake_torque", "N.m", &brake_torque_,
              "holding torque of each joint's brake when brake is true (default 30)",
              cosim::Rule::NonNegative());
  v.Parameter("substeps", &substeps_, "ODE steps per communication step",
              cosim::Rule::Range(1, 1000));
  v.Parameter("initial_x", "m", &initial_x_, "base_link x in map at the start",
              cosim::Rule::Finite());
  v.Parameter("initial_y", "m", &initial_y_, "base_link y in map at the start",
              cosim::Rule::Finite());
  v.Parameter("initial_yaw", "rad", &initial_yaw_, "base_link yaw in map at the start",
              cosim::Rule::Finite());
}

// The scene's references and sizes the chassis relies on (the loader checks
// them for a scene file; a scene built in code reaches here unchecked).
void ChassisUnit::CheckScene() const {
  const auto surface_ok = [&](int s) {
    return s >= 0 && static_cast<std::size_t>(s) < scene_.surfaces.size();
  };
  if (!surface_ok(scene_.floor.surface)) {
    throw cosim::UnitError(Where() + ": scene '" + scene_.name + "': the floor's surface " +
                           std::to_string(scene_.floor.surface) + " is not one of its " +
                           std::to_string(scene_.surfaces.size()) + " surfaces");
  }
  for (const auto& belt : scene_.belts) {
    if (!surface_ok(belt.surface)) {
      throw cosim::UnitError(Where() + ": scene '" + scene_.name + "': belt '" + belt.name +
                             "' has surface " + std::to_string(belt.surface) + ", not one of its " +
                             std::to_string(scene_.surfaces.size()) + " surfaces");
    }
  }
  for (const auto& obj : scene_.carried) {
    if (obj.belt < 0 || obj.belt >= belt_count_) {
      throw cosim::UnitError(Where() + ": scene '" + scene_.name + "': carried object '" +
                             obj.name + "' is on belt " + std::to_string(obj.belt) +
                             ", not one of its " + std::to_string(belt_count_) + " belts");
    }
    // It leaves the scene at its belt's end (FloorWorld), so it must not
    // start past it; one upstream of the belt waits there and is put on
    // the line once its footprint lies wholly on it (a line of bodies that
    // enter in turn).
    const models::Belt& belt = scene_.belts[static_cast<std::size_t>(obj.belt)];
    const models::Rect& r = belt.area;
    const auto range = CarriedTravelRange(
        {r.center_x_m, r.center_y_m, r.length_m, r.width_m, r.direction_rad, 0.0}, obj.solid);
    if (!(0.0 <= range[1] && range[0] <= range[1])) {
      throw cosim::UnitError(Where() + ": scene '" + scene_.name + "': carried object '" +
                             obj.name + "' overhangs the downstream end of belt '" + belt.name +
                             "' at time zero, or is longer than the belt (its footprint must "
                             "lie along the belt's length, or wait upstream of it)");
    }
  }
  for (const auto& piece : scene_.terrain) {
    if (!surface_ok(piece.surface)) {
      throw cosim::UnitError(Where() + ": scene '" + scene_.name + "': terrain '" + piece.name +
                             "' has surface " + std::to_string(piece.surface) +
                             ", not one of its " + std::to_string(scene_.surfaces.size()) +
                             " surfaces");
    }
    if (!(piece.length_m > 0.0 && piece.width_m > 0.0 && piece.thickness_m > 0.0)) {
      throw cosim::UnitError(Where() + ": scene '" + scene_.name + "': terrain '" + piece.name +
                             "' needs a positive length, width and thickness");
    }
  }
  if (!(scene_.floor.min_x_m < scene_.floor.max_x_m &&
        scene_.floor.min_y_m < scene_.floor.max_y_m)) {
    throw cosim::UnitError(Where() + ": scene '" + scene_.name + "': the floor's rectangle is " +
                           "empty (x " + cosim::FormatValue(scene_.floor.min_x_m) + " to " +
                           cosim::FormatValue(scene_.floor.max_x_m) + ", y " +
                           cosim::FormatValue(scene_.floor.min_y_m) + " to " +
                           cosim::FormatValue(scene_.floor.max_y_m) + ")");
  }
}

// The inputs and outputs, after the parameters, in the variable table's order.
void ChassisUnit::DeclareSignals() {
  const auto b = static_cast<std::size_t>(belt_count_);
  const auto ms = static_cast<std::size_t>(steer_motor_count_);
  auto& v = variables();
  if (ms > 0) {
    v.Input("steer_torque", "N.m", &steer_torque_,
            "torque of each steering motor about its wheel's steering axis, + counter-clockwise "
            "seen from above");
  }
  v.Input("drive_torque", "N.m", &drive_torque_,
          "torque of each drive motor about the axle of its wheels, + drives them forward");
  // The motors' torque-speed lines: a DC motor's torque falls steeply with
  // its speed (back-EMF). Applied as given over a step, that damping is
  // explicit and a light wheel on a creeping tyre oscillates out of bounds
  // at a 5 ms step; as the joint's motor row it is implicit.
  if (ms > 0) {
    v.Input("steer_torque_slope", "N.m.s/rad", &steer_torque_slope_,
            "d steer_torque / d steer_rate of each steering motor at steer_torque_rate (<= 0; "
            "0: steer_torque is applied as given over the step)");
    v.Input("steer_torque_rate", "rad/s", &steer_torque_rate_,
            "the steering rate at which steer_torque holds (with a slope: the torque follows "
            "its line through it within the step)");
  }
  v.Input("drive_torque_slope", "N.m.s/rad", &drive_torque_slope_,
          "d drive_torque / d drive_rate of each drive motor at drive_torque_rate (<= 0; 0: "
          "drive_torque is applied as given over the step)");
  v.Input("drive_torque_rate", "rad/s", &drive_torque_rate_,
          "the drive rate at which drive_torque holds (with a slope: the torque follows its "
          "line through it within the step)");
  if (b > 0) {
    v.Input("belt_velocity", "m/s", &belt_velocity_,
            "surface velocity of each scene belt in map: vx, vy per belt");
    v.Input("belt_travel", "m", &belt_travel_,
            "distance each scene belt's surface has moved since t = 0 (places carried objects)");
  }
  if (!moving_boxes_.empty()) {
    v.Parameter("own_box", &own_box_,
                "the box of moving_boxes that is this robot's own body (left out); -1: none",
                cosim::Rule::Range(-1, 10000));
    v.Input("moving_boxes", "m, rad, m/s, rad/s", &moving_boxes_,
            "per moving box (a robot's body: its chassis' body_box) [x, y, yaw, vx, vy, "
            "yaw_rate, length, width, z_bottom, z_top] in map; the body collides with them");
  }
  if (!moving_cylinders_.empty()) {
    v.Input("moving_cylinders", "m, m/s", &moving_cylinders_,
            "per moving cylinder (a worker's leg or torso) [x, y, vx, vy, radius, z_bottom, "
            "z_top] in map; the body collides with them");
  }
  v.Input("brake", &brake_, "true: every wheel joint held (velocity 0, up to brake_torque)");

  if (ms > 0) {
    v.Output("steer_angle", "rad", &steer_angle_,
             "heading of each steering motor's wheel relative to base_link x, in (-pi, pi]", {});
    v.Output("steer_rate", "rad/s", &steer_rate_,
             "steering rate of each steering motor's wheel relative to the body", {});
  }
  v.Output("drive_rate", "rad/s", &drive_rate_,
           "spin of each drive motor's wheels relative to the body, + rolling forward", {});
  v.Output("drive_angle", "rad", &drive_angle_,
           "angle each drive motor's wheels have turned relative to the body since the start "
           "(the trapezoid of drive_rate over each step): what a wheel encoder counts",
           {});
  v.Output("position", "m", &position_, "x, y of base_link in map", {});
  v.Output("yaw", "rad", &yaw_, "yaw of base_link in map, in (-pi, pi]", {});
  v.Output("linear_velocity", "m/s", &linear_velocity_, "vx, vy of base_link in map", {});
  v.Output("yaw_rate", "rad/s", &yaw_rate_, "yaw rate of base_link", {});
  v.Output("body_linear_velocity", "m/s", &body_linear_velocity_,
           "vx, vy of base_link in base_link", {});
  v.Output("position_3d", "m", &position_3d_,
           "x, y, z in map of base_link's origin: on the wheels' contact plane under the body "
           "box's centre (com_height below it along the body's z axis; on a ramp, on the "
           "ramp), the point sensor mounts refer to",
           {});
  v.Output("orientation", "1", &orientation_,
           "attitude of base_link in map as a unit quaternion w, x, y, z", {});
  v.Output("velocity_3d", "m/s", &velocity_3d_, "velocity of base_link's origin in map", {});
  v.Output("angular_velocity", "rad/s", &angular_velocity_,
           "angular velocity of the body in base_link (x roll rate, y pitch rate, z yaw rate): "
           "what a gyro on it measures",
           {});
  v.Output("wheel_surface", "1", &wheel_surface_,
           "surface under each wheel (its deepest contact point): -1 no contact, 0 floor, "
           "k + 1 scene belt k, belt count + 1 + j scene terrain piece j",
           {});
  v.Output("wheel_surface_velocity", "m/s", &wheel_surface_velocity_,
           "velocity of the surface under each wheel in base_link: vx, vy per wheel (zero on "
           "the floor or without contact)",
           {});
  v.Output("wheel_contact", "m", &wheel_contact_,
           "contact point of each wheel in map (x, y), or the wheel centre without contact", {});
  v.Output("body_box", "m, rad, m/s, rad/s", &body_box_,
           "the body box as others see it (another robot's lasers, chassis and clearance): [x, "
           "y, yaw, vx, vy, yaw_rate, length, width, z_bottom, z_top] in map (x, y: "
           "base_link's; z_bottom, z_top: the box's lowest and highest points, body_bottom and "
           "body_bottom + body_height above the floor when level)",
           {});
}

void ChassisUnit::DeclareTreadParameters() {
  const auto w = static_cast<std::size_t>(wheel_count_);
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  for (auto* values : {&tread_slip_stiffness_, &tread_cornering_stiffness_,
                       &tread_longitudinal_relaxation_, &tread_lateral_relaxation_,
                       &tread_damping_ratio_, &tread_patch_length_, &tread_patch_width_}) {
    values->assign(w, kNaN);
  }
  // Each wheel on each surface: the surface's own friction unless the
  // robot's tread material has its own pair (loader/assembly).
  for (std::size_t k = 0; k < w; ++k) {
    for (const models::Surface& s : scene_.surfaces) wheel_friction_.push_back(s.friction);
  }
  auto& v = variables();
  const auto tyre = cosim::Rule::Positive().NoDefault();
  v.Parameter("tread_slip_stiffness", "1", &tread_slip_stiffness_,
              "each wheel's longitudinal slip stiffness per unit load, C_kappa / F_z (N per "
              "unit slip per N): the creep slope of a brush tyre",
              tyre);
  v.Parameter("tread_cornering_stiffness", "1/rad", &tread_cornering_stiffness_,
              "each wheel's cornering stiffness per unit load, C_alpha / F_z", tyre);
  v.Parameter("tread_longitudinal_relaxation", "m", &tread_longitudinal_relaxation_,
              "each wheel's longitudinal relaxation length sigma_kappa: tread stiffness "
              "C_kappa / sigma_kappa at the wheel's static load",
              tyre);
  v.Parameter("tread_lateral_relaxation", "m", &tread_lateral_relaxation_,
              "each wheel's lateral relaxation length sigma_alpha", tyre);
  v.Parameter("tread_damping_ratio", "1", &tread_damping_ratio_,
              "each wheel's tangential tread damping as a ratio of critical for its static "
              "load on its tread stiffness",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("tread_patch_length", "m", &tread_patch_length_,
              "each wheel's contact patch length along its rolling direction (0: a point)",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("tread_patch_width", "m", &tread_patch_width_,
              "each wheel's contact patch width (0: a point)",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("wheel_friction", "1", &wheel_friction_,
              "Coulomb coefficient of each wheel's tread on each scene surface, wheel-major "
              "(default: each surface's friction)",
              cosim::Rule::NonNegative());
}

Tread ChassisUnit::WheelTread(std::size_t k) const {
  Tread t;
  // The static load of one wheel: the robot's weight shared by its wheels.
  const double load_n = (mass_ + payload_mass_) * kGravityMps2 / wheel_count_;
  const double c[2] = {tread_slip_stiffness_[k], tread_cornering_stiffness_[k]};
  const double sigma[2] = {tread_longitudinal_relaxation_[k], tread_lateral_relaxation_[k]};
  for (int r = 0; r < 2; ++r) {
    t.relaxation_m[r] = sigma[r];
    t.stiffness_n_per_m[r] = c[r] * load_n / sigma[r];
    t.damping_n_s_per_m[r] =
        2.0 * tread_damping_ratio_[k] * std::sqrt(t.stiffness_n_per_m[r] * load_n / kGravityMps2);
  }
  t.patch_length_m = tread_patch_length_[k];
  t.patch_width_m = tread_patch_width_[k];
  t.axle[1] = 1.0;  // the wheel body's local y
  // The floor world's surfaces: the floor, the belts, the terrain pieces.
  const std::size_t surfaces = scene_.surfaces.size();
  const auto mu = [&](int scene_surface) {
    return wheel_friction_[k * surfaces + static_cast<std::size_t>(scene_surface)];
  };
  t.mu.push_back(mu(scene_.floor.surface));
  for (const models::Belt& b : scene_.belts) t.mu.push_back(mu(b.surface));
  for (const models::TerrainPiece& p : scene_.terrain) t.mu.push_back(mu(p.surface));
  return t;
}

ChassisUnit::~ChassisUnit() = default;

std::vector<cosim::ParameterProblem> ChassisUnit::CheckParameters() const {
  // The rules of single parameters are declared with them; here only what
  // relates several: the wheels weigh less than the whole robot, and the
  // payload's box.
  auto problems = cosim::Unit::CheckParameters();
  if (mass_ > 0.0 && module_mass_ > 0.0 && !(wheel_count_ * module_mass_ < mass_)) {
    problems.push_back({"module_mass", std::nullopt,
                        "times " + std::to_string(wheel_count_) +
                            " wheels must be less than mass " + cosim::FormatValue(mass_) +
                            ", got " + cosim::FormatValue(module_mass_)});
  }
  // The body's centre of mass lies within its box.
  if (com_height_ > 0.0 && body_height_ > 0.0 && body_bottom_ >= 0.0 &&
      (com_height_ < body_bottom_ || com_height_ > body_bottom_ + body_height_)) {
    problems.push_back({"com_height", std::nullopt,
                        "must lie within the body box, from body_bottom " +
                            cosim::FormatValue(body_bottom_) + " to body_bottom + body_height " +
                            cosim::FormatValue(body_bottom_ + body_height_) + ", got " +
                            cosim::FormatValue(com_height_)});
  }
  // The payload's box: all three sizes (a box) or none (a point mass).
  const auto boxed =
      std::count_if(payload_size_.begin(), payload_size_.end(), [](double d) { return d > 0.0; });
  if (boxed != 0 && boxed != 3) {
    problems.push_back({"payload_size", std::nullopt,
                        "give all three sizes (a box) or none (a point mass), got " +
                            cosim::FormatValue(payload_size_[0]) + ", " +
                            cosim::FormatValue(payload_size_[1]) + ", " +
                            cosim::FormatValue(payload_size_[2])});
  }
  return problems;
}

// The scene in the floor world: belts, the floor's contact and profile,
// obstacles, carried objects and terrain pieces.
void ChassisUnit::AddScene(FloorWorld& f) const {
  const auto mu_of = [&](int surface) {
    return scene_.surfaces[static_cast<std::size_t>(surface)].friction;
  };
  std::vector<BeltPatch> belts;
  for (const models::Belt& belt : scene_.belts) {
    const models::Rect& r = belt.area;
    belts.push_back({r.center_x_m, r.center_y_m, r.length_m, r.width_m, r.direction_rad,
                     mu_of(belt.surface), belt.edge_gap_m});
  }
  f.SetBelts(std::move(belts));
  f.SetSurface({mu_of(scene_.floor.surface), contact_stiffness_, contact_damping_});
  const auto profile_of = [&](int surface) {
    return models::SurfaceProfile(scene_.surfaces[static_cast<std::size_t>(surface)].unevenness);
  };
  f.SetFloorProfile(profile_of(scene_.floor.surface));
  for (const models::Obstacle& obstacle : scene_.obstacles) f.AddObstacle(obstacle.solid);
  for (const models::CarriedObject& obj : scene_.carried) f.AddCarried(obj.solid, obj.belt);
  for (const models::TerrainPiece& piece : scene_.terrain) {
    f.AddTerrain(piece, mu_of(piece.surface), profile_of(piece.surface));
  }
}

void ChassisUnit::Build() {
  EnsureOdeForThisThread();
  Ode& o = *ode_;
  o.Clear();
  o.floor = std::make_unique<FloorWorld>();
  FloorWorld& f = *o.floor;
  AddScene(f);

  // Start with the contacts pressed in by equal shares of the weight, so
  // that the settle has little to do. The suspension starts unloaded (its
  // anchors coincide at creation) and settles too.
  const double n = static_cast<double>(wheel_count_);
  const double body_mass = mass_ - n * module_mass_;
  const double drop_m = mass_ * kGravityMps2 / n / contact_stiffness_;
  const double c = std::cos(initial_yaw_), s = std::sin(initial_yaw_);
  dMatrix3 rot;
  dRFromAxisAndAngle(rot, 0.0, 0.0, 1.0, initial_yaw_);

  // The body: its mass (centre at (0, 0, com_height) in base_link, the
  // inertia of a uniform box of the body's size about it) and the payload
  // as one rigid body, whose origin ODE wants at their joint centre of mass
  // c; each part's inertia moved to c by the parallel-axis theorem
  // (dMassTranslate). Without a payload c is the body's centre of mass.
  // The body box, the solid, is where body_bottom puts it, offset from c.
  o.body = dBodyCreate(f.world());
  dMass m;
  dMassSetBoxTotal(&m, body_mass, body_length_, body_width_, body_height_);
  double com[3] = {0.0, 0.0, com_height_};
  const bool payload = payload_mass_ > 0.0;
  if (payload) {
    const double total = body_mass + payload_mass_;
    for (int d = 0; d < 3; ++d) {
      const double box_d = d == 2 ? com_height_ : 0.0;
      com[d] =
          (body_mass * box_d + payload_mass_ * payload_position_[static_cast<std::size_t>(d)]) /
          total;
    }
    dMassTranslate(&m, -com[0], -com[1], com_height_ - com[2]);
    dMass mp;
    const double* size = payload_size_.data();
    const double d[3] = {payload_position_[0] - com[0], payload_position_[1] - com[1],
                         payload_position_[2] - com[2]};
    if (size[0] > 0.0 && size[1] > 0.0 && size[2] > 0.0) {
      dMassSetBoxTotal(&mp, payload_mass_, size[0], size[1], size[2]);
      dMassTranslate(&mp, d[0], d[1], d[2]);
    } else {
      // A point mass at d: about c only the parallel-axis inertia
      // m (|d|^2 1 - d d^T), which is singular (nothing about the axis
      // through it). Written directly: dMassSetParameters and
      // dMassTranslate check each part for a positive-definite inertia and
      // print ODE's "inertia must be positive definite"; the sum with the
      // body box, which dBodySetMass checks, is positive definite.
      dMassSetZero(&mp);
      mp.mass = payload_mass_;
      const double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
      for (int r = 0; r < 3; ++r) {
        mp.c[r] = d[r];
        for (int k = 0; k < 3; ++k) {
          mp.I[4 * r + k] = payload_mass_ * ((r == k ? d2 : 0.0) - d[r] * d[k]);
        }
      }
    }
    dMassAdd(&m, &mp);
    // The sum's centre is 0 up to rounding; ODE requires it exactly there.
    for (int d = 0; d < 3; ++d) m.c[d] = 0.0;
  }
  for (int d = 0; d < 3; ++d) o.base_from_com[d] = -com[d];
  dBodySetMass(o.body, &m);
  dBodySetPosition(o.body, initial_x_ + c * com[0] - s * com[1],
                   initial_y_ + s * com[0] + c * com[1], com[2] - drop_m);
  dBodySetRotation(o.body, rot);
  o.body_geom = dCreateBox(nullptr, body_length_, body_width_, body_height_);
  dGeomSetBody(o.body_geom, o.body);
  dGeomSetOffsetPosition(o.body_geom, -com[0], -com[1], body_bottom_ + 0.5 * body_height_ - com[2]);
  f.SetBodyGeom(o.body_geom, body_friction_);
  if (payload && payload_size_[0] > 0.0 && payload_size_[1] > 0.0 && payload_size_[2] > 0.0) {
    o.payload_geom = dCreateBox(nullptr, payload_size_[0], payload_size_[1], payload_size_[2]);
    dGeomSetBody(o.payload_geom, o.body);
    dGeomSetOffsetPosition(o.payload_geom, payload_position_[0] - com[0],
                           payload_position_[1] - com[1], payload_position_[2] - com[2]);
    f.AddBodyGeom(o.payload_geom);
  }

  // Wheel inertia: a thin disc of the wheel radius (axial m r^2 / 2,
  // diametral m r^2 / 4) plus the reflected rotor inertias: the steering
  // rotor on a steered module, the drive rotor on the first wheel of each
  // drive motor. The axle is the wheel body's local y axis.
  const double axle[3] = {-s, c, 0.0};
  const double up[3] = {0.0, 0.0, 1.0};
  std::vector<int> first_wheel(static_cast<std::size_t>(drive_motor_count_), -1);
  for (std::size_t k = 0; k < static_cast<std::size_t>(wheel_count_); ++k) {
    const double radius = wheel_radius_[k];
    const double r2 = radius * radius;
    const bool steered = steer_motor_[k] >= 0;
    const auto motor = static_cast<std::size_t>(drive_motor_[k]);
    const bool first = leads_drive_motor_[k] != 0;
    const double i_axle = 0.5 * module_mass_ * r2 + (first ? drive_rotor_inertia_ : 0.0);
    const double i_perp = 0.25 * module_mass_ * r2 + (steered ? steer_rotor_inertia_ : 0.0);
    const double x = initial_x_ + c * wheel_x_[k] - s * wheel_y_[k];
    const double y = initial_y_ + s * wheel_x_[k] + c * wheel_y_[k];
    const double z = radius - drop_m;
    dBodyID w = dBodyCreate(f.world());
    dMassSetParameters(&m, module_mass_, 0.0, 0.0, 0.0, i_perp, i_axle, i_perp, 0.0, 0.0, 0.0);
    dBodySetMass(w, &m);
    dBodySetPosition(w, x, y, z);
    dBodySetRotation(w, rot);
    dGeomID g = dCreateSphere(nullptr, radius);
    dGeomSetBody(g, w);
    f.AddGeom(g, WheelTread(k));
    dJointID j = nullptr;
    if (steered) {
      j = dJointCreateHinge2(f.world(), nullptr);
      dJointAttach(j, o.body, w);
      dJointSetHinge2Anchor(j, x, y, z);
      dJointSetHinge2Axes(j, up, axle);
    } else {
      j = dJointCreateHinge(f.world(), nullptr);
      dJointAttach(j, o.body, w);
      dJointSetHingeAnchor(j, x, y, z);
      dJointSetHingeAxis(j, axle[0], axle[1], axle[2]);
    }
    if (first) {
      first_wheel[motor] = static_cast<int>(k);
    } else {
      // Zero spin of this wheel relative to the motor's first wheel about
      // the axle (axis 0 fixed in the first wheel's frame: its local y).
      const dBodyID lead = o.wheels[static_cast<std::size_t>(first_wheel[motor])];
      dJointID cj = dJointCreateAMotor(f.world(), nullptr);
      dJointAttach(cj, lead, w);
      dJointSetAMotorMode(cj, dAMotorUser);
      dJointSetAMotorNumAxes(cj, 1);
      dJointSetAMotorAxis(cj, 0, 1, axle[0], axle[1], axle[2]);
      dJointSetAMotorParam(cj, dParamVel, 0.0);
      dJointSetAMotorParam(cj, dParamFMax, kCouplingMaxTorqueNm);
      dJointSetAMotorParam(cj, dParamCFM, kCouplingCfm);
      o.couplings.push_back(cj);
    }
    o.wheels.push_back(w);
    o.geoms.push_back(g);
    o.joints.push_back(j);
    o.steered.push_back(steered);
  }
}

void ChassisUnit::PlaceOnTerrain() {
  Ode& o = *ode_;
  const FloorWorld& f = *o.floor;
  if (f.terrain_count() == 0) return;
  // The ground under each wheel's contact point at the initial pose: the
  // highest terrain top face there, else the floor.
  const auto n = static_cast<std::size_t>(wheel_count_);
  const double c = std::cos(initial_yaw_), s = std::sin(initial_yaw_);
  std::vector<double> h(n);
  bool raised = false;
  for (std::size_t k = 0; k < n; ++k) {
    const double x = initial_x_ + c * wheel_x_[k] - s * wheel_y_[k];
    const double y = initial_y_ + s * wheel_x_[k] + c * wheel_y_[k];
    h[k] = std::max(0.0, f.TerrainTopAt(x, y));
    raised = raised || h[k] > 0.0;
  }
  if (!raised) return;
  // The plane z = a + b x + c y (base_link x, y) through those heights, by
  // least squares (exact for wheels on one plane); a level lift by the
  // highest one when the wheels do not span a plane.
  double a = *std::max_element(h.begin(), h.end()), b = 0.0, cy = 0.0;
  if (n >= 3) {
    double m[3][4] = {};
    for (std::size_t k = 0; k < n; ++k) {
      const double row[3] = {1.0, wheel_x_[k], wheel_y_[k]};
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) m[i][j] += row[i] * row[j];
        m[i][3] += row[i] * h[k];
      }
    }
    // Gauss-Jordan with partial pivoting on the 3 x 3 normal equations.
    bool ok = true;
    for (int col = 0; col < 3 && ok; ++col) {
      int piv = col;
      for (int i = col + 1; i < 3; ++i) {
        if (std::abs(m[i][col]) > std::abs(m[piv][col])) piv = i;
      }
      if (std::abs(m[piv][col]) < 1e-9) {
        ok = false;
        break;
      }
      for (int j = 0; j < 4; ++j) std::swap(m[col][j], m[piv][j]);
      for (int i = 0; i < 3; ++i) {
        if (i == col) continue;
        const double ratio = m[i][col] / m[col][col];
        for (int j = 0; j < 4; ++j) m[i][j] -= ratio * m[col][j];
      }
    }
    if (ok) {
      a = m[0][3] / m[0][0];
      b = m[1][3] / m[1][1];
      cy = m[2][3] / m[2][2];
    }
  }
  // The tilt in the heading frame (x forward, y left): x' along (1, 0, b),
  // y' (0, 1, cy) made orthogonal to it, z' = x' x y'; in map
  // T = Rz(yaw) [x' y' z'] Rz(-yaw). Every body moves rigidly about the
  // initial base_link origin and up by a; the joints keep their anchors in
  // the bodies' frames.
  double ex[3] = {1.0, 0.0, b};
  const double lx = std::sqrt(1.0 + b * b);
  for (double& e : ex) e /= lx;
  double ey[3] = {0.0, 1.0, cy};
  const double dot = ey[1] * ex[1] + ey[2] * ex[2];
  for (int i = 0; i < 3; ++i) ey[i] -= dot * ex[i];
  const double ly = std::sqrt(ey[0] * ey[0] + ey[1] * ey[1] + ey[2] * ey[2]);
  for (double& e : ey) e /= ly;
  const double ez[3] = {ex[1] * ey[2] - ex[2] * ey[1], ex[2] * ey[0] - ex[0] * ey[2],
                        ex[0] * ey[1] - ex[1] * ey[0]};
  // Heading-frame tilt matrix (columns ex, ey, ez), then conjugated by yaw.
  const double th[3][3] = {{ex[0], ey[0], ez[0]}, {ex[1], ey[1], ez[1]}, {ex[2], ey[2], ez[2]}};
  const double rz[3][3] = {{c, -s, 0.0}, {s, c, 0.0}, {0.0, 0.0, 1.0}};
  double tmp[3][3] = {}, t[3][3] = {};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      for (int k = 0; k < 3; ++k) tmp[i][j] += rz[i][k] * th[k][j];
    }
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      for (int k = 0; k < 3; ++k) t[i][j] += tmp[i][k] * rz[j][k];
    }
  }
  dMatrix3 tr;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) tr[4 * i + j] = t[i][j];
    tr[4 * i + 3] = 0.0;
  }
  dQuaternion qt;
  dRtoQ(tr, qt);
  // The ground's gradient in map: (b, cy) turned by the yaw.
  o.ground_slope[0] = c * b - s * cy;
  o.ground_slope[1] = s * b + c * cy;
  for (std::size_t i = 0; i < o.BodyCount(); ++i) {
    const dBodyID body = o.Body(i);
    const dReal* p = dBodyGetPosition(body);
    const double d[3] = {p[0] - initial_x_, p[1] - initial_y_, p[2]};
    double moved[3];
    for (int r = 0; r < 3; ++r) moved[r] = t[r][0] * d[0] + t[r][1] * d[1] + t[r][2] * d[2];
    dBodySetPosition(body, initial_x_ + moved[0], initial_y_ + moved[1], a + moved[2]);
    dQuaternion q;
    dQMultiply0(q, qt, dBodyGetQuaternion(body));
    dBodySetQuaternion(body, q);
  }
}

void ChassisUnit::SetSuspension(double h_s) {
  if (h_s == ode_->suspension_h_s) return;
  const auto [erp, cfm] = ErpCfm(h_s, suspension_stiffness_, suspension_damping_);
  for (std::size_t k = 0; k < ode_->joints.size(); ++k) {
    if (!ode_->steered[k]) continue;
    dJointSetHinge2Param(ode_->joints[k], dParamSuspensionERP, erp);
    dJointSetHinge2Param(ode_->joints[k], dParamSuspensionCFM, cfm);
  }
  ode_->suspension_h_s = h_s;
}

void ChassisUnit::SetJointMotors(bool hold, double max_torque_nm) {
  // Axis 0 of a joint is a steered wheel's steering axis, axis 1 its axle
  // (hinge2's axes 1 and 2; a fixed wheel's hinge has only the axle). Its
  // row: velocity `vel`, force limit `fmax` (0: no row), CFM `cfm`.
  const double world_cfm = dWorldGetCFM(ode_->floor->world());
  const auto set = [](dJointID j, bool steered, int axis, double vel, double fmax, double cfm) {
    if (steered) {
      const int group = axis == 0 ? 0 : dParamGroup;
      dJointSetHinge2Param(j, dParamVel + group, vel);
      dJointSetHinge2Param(j, dParamFMax + group, fmax);
      dJointSetHinge2Param(j, dParamCFM + group, cfm);
    } else {
      dJointSetHingeParam(j, dParamVel, vel);
      dJointSetHingeParam(j, dParamFMax, fmax);
      dJointSetHingeParam(j, dParamCFM, cfm);
    }
  };
  // A motor's torque-speed line tau(r) = tau0 + slope (r - r0), r the
  // wheel's rate relative to the body about the joint axis (the joint's own
  // rate is -r: ODE's rate is body1's - body2's, and body1 is the body),
  // as the joint's motor row: the row enforces -r = vel - cfm lambda and
  // puts -lambda on the wheel, so cfm = 1 / c and vel = -(r0 + tau0 / c)
  // with c = -slope give the wheel tau0 - c (r - r0) at the end of each
  // internal step (implicit: stable at any slope and step).
  const auto line = [&](dJointID j, bool steered, int axis, double tau0, double slope, double r0) {
    const double c = -slope;
    set(j, steered, axis, -(r0 + tau0 / c), dInfinity, 1.0 / c);
  };
  for (std::size_t k = 0; k < ode_->joints.size(); ++k) {
    const dJointID j = ode_->joints[k];
    const bool steered = ode_->steered[k];
    if (hold) {
      if (steered) set(j, true, 0, 0.0, max_torque_nm, world_cfm);
      set(j, steered, 1, 0.0, max_torque_nm, world_cfm);
      continue;
    }
    if (steered) {
      const auto sm = static_cast<std::size_t>(steer_motor_[k]);
      if (ImplicitSteer(sm)) {
        line(j, true, 0, steer_torque_[sm], steer_torque_slope_[sm], steer_torque_rate_[sm]);
      } else {
        set(j, true, 0, 0.0, 0.0, world_cfm);
      }
    }
    const auto dm = static_cast<std::size_t>(drive_motor_[k]);
    if (leads_drive_motor_[k] && ImplicitDrive(dm)) {
      line(j, steered, 1, drive_torque_[dm], drive_torque_slope_[dm], drive_torque_rate_[dm]);
    } else {
      set(j, steered, 1, 0.0, 0.0, world_cfm);
    }
  }
}

void ChassisUnit::ApplyTorques() {
  const Ode& o = *ode_;
  double up[3], axle[3];
  Column(dBodyGetRotation(o.body), 2, up);
  const dReal* wb = dBodyGetAngularVel(o.body);
  // A drive motor's torque goes to the first wheel of its group only.
  for (std::size_t k = 0; k < o.wheels.size(); ++k) {
    const dBodyID w = o.wheels[k];
    Column(dBodyGetRotation(w), 1, axle);
    const dReal* ww = dBodyGetAngularVel(w);
    const double rel[3] = {ww[0] - wb[0], ww[1] - wb[1], ww[2] - wb[2]};
    const int sm = steer_motor_[k];
    const auto dm = static_cast<unsigned>(drive_motor_[k]);
    // A motor whose torque the joint row applies (SetJointMotors) adds
    // only the joint's viscous friction here.
    double steer = 0.0;
    if (sm >= 0) {
      const auto m = static_cast<std::size_t>(sm);
      steer =
          (brake_ || !ImplicitSteer(m) ? steer_torque_[m] : 0.0) - steer_friction_ * Dot(up, rel);
    }
    double drive = -drive_friction_ * Dot(axle, rel);
    if (leads_drive_motor_[k] && (brake_ || !ImplicitDrive(dm))) drive += drive_torque_[dm];
    // The motor turns the wheel and reacts on the body: equal and opposite.
    const double t[3] = {steer * up[0] + drive * axle[0], steer * up[1] + drive * axle[1],
                         steer * up[2] + drive * axle[2]};
    dBodyAddTorque(w, t[0], t[1], t[2]);
    dBodyAddTorque(o.body, -t[0], -t[1], -t[2]);
  }
}

void ChassisUnit::Settle() {
  FloorWorld& f = *ode_->floor;
  // Built on the floor plane: a wheel deep in a terrain piece would be
  // thrown out of it.
  f.Probe();
  for (int k = 0; k < wheel_count_; ++k) {
    const GeomContact& gc = f.contact(k);
    if (gc.surface > belt_count_ && gc.depth_m > kMaxStartDepthM) {
      const auto& piece = scene_.terrain[static_cast<std::size_t>(gc.surface - belt_count_ - 1)];
      throw cosim::UnitError(Where() + ": at the initial pose, wheel " + std::to_string(k) +
                             " is " + cosim::FormatValue(gc.depth_m) +
                             " m deep in terrain piece '" + piece.name +
                             "' (the robot starts on the floor plane: start it clear of the "
                             "terrain)");
    }
  }
  for (int k = 0; k < f.belt_count(); ++k) f.SetBeltVelocity(k, 0.0, 0.0);
  SetSuspension(kSettleStepS);
  SetJointMotors(true, kSettleHoldTorqueNm);
  for (int i = 0; i < kSettleSteps; ++i) {
    if (!f.Step(kSettleStepS))
      throw cosim::UnitError(Where() + ": dWorldStep failed while settling");
  }
  if (const std::string bad = NonFiniteState(); !bad.empty()) {
    throw cosim::UnitError(Where() + ": ODE state went non-finite while settling: " + bad);
  }
  // Move every body rigidly so that base_link is exactly at the initial
  // pose, and stop everything.
  // base_link's origin: the body's origin plus base_from_com in its frame.
  double origin[3];
  dBodyGetRelPointPos(ode_->body, ode_->base_from_com[0], ode_->base_from_com[1],
                      ode_->base_from_com[2], origin);
  const double bx = origin[0], by = origin[1];
  // On terrain the ground rises along its slope: moved back to the initial
  // x, y, the robot moves up or down with it (0 on the floor).
  const double lift =
      ode_->ground_slope[0] * (initial_x_ - bx) + ode_->ground_slope[1] * (initial_y_ - by);
  const double turn = initial_yaw_ - Yaw(dBodyGetRotation(ode_->body));
  const double c = std::cos(turn), s = std::sin(turn);
  dQuaternion q_turn;
  dQFromAxisAndAngle(q_turn, 0.0, 0.0, 1.0, turn);
  for (std::size_t i = 0; i < ode_->BodyCount(); ++i) {
    const dBodyID b = ode_->Body(i);
    const dReal* p = dBodyGetPosition(b);
    const double dx = p[0] - bx, dy = p[1] - by;
    dBodySetPosition(b, initial_x_ + c * dx - s * dy, initial_y_ + s * dx + c * dy, p[2] + lift);
    dQuaternion q;
    dQMultiply0(q, q_turn, dBodyGetQuaternion(b));
    dBodySetQuaternion(b, q);
    dBodySetLinearVel(b, 0.0, 0.0, 0.0);
    dBodySetAngularVel(b, 0.0, 0.0, 0.0);
  }
  // At rest at time zero: the treads unloaded of what settling left.
  f.ResetTreads();
  // The contacts at the moved positions, for the outputs and the first step.
  f.Probe();
  if (const std::string bad = OffFloorWheel(); !bad.empty()) {
    throw cosim::UnitError(Where() + ": at the initial pose, " + bad);
  }
}

void ChassisUnit::Initialize() {
  std::vector<cosim::Value> parameters;
  for (const auto& info : variables().infos()) {
    if (info.causality == cosim::Causality::kParameter) {
      parameters.push_back(variables().GetValue(info.ref));
    }
  }
  // Settling uses only the parameters (belts still, joints held), so an
  // unchanged, unstepped world is already what a rebuild would give.
  if (!initialized_ || stepped_since_settle_ || parameters != settled_parameters_) {
    ThrowIfBadParameters();
    initialized_ = false;
    Build();
    PlaceOnTerrain();
    Settle();
    settled_parameters_ = std::move(parameters);
    stepped_since_settle_ = false;
  }
  SetBeltInputs();
  ComputeOutputs();
  std::fill(drive_angle_.begin(), drive_angle_.end(), 0.0);
  initialized_ = true;
}

void ChassisUnit::SetBeltInputs() {
  FloorWorld& f = *ode_->floor;
  for (int k = 0; k < f.belt_count(); ++k) {
    const auto kk = static_cast<std::size_t>(k);
    f.SetBeltVelocity(k, belt_velocity_[2 * kk], belt_velocity_[2 * kk + 1]);
    f.SetBeltTravel(k, belt_travel_[kk]);
  }
  if (!moving_boxes_.empty() || !moving_cylinders_.empty()) {
    f.SetMovingSolids(moving_boxes_, moving_cylinders_, static_cast<int>(own_box_));
  }
}

double ChassisUnit::WheelRate(int k) const {
  if (!ode_->body || k < 0 || k >= wheel_count_) return std::numeric_limits<double>::quiet_NaN();
  const dBodyID w = ode_->wheels[static_cast<std::size_t>(k)];
  double axle[3];
  Column(dBodyGetRotation(w), 1, axle);
  const dReal* ww = dBodyGetAngularVel(w);
  const dReal* wb = dBodyGetAngularVel(ode_->body);
  const double rel[3] = {ww[0] - wb[0], ww[1] - wb[1], ww[2] - wb[2]};
  return Dot(axle, rel);
}

std::string ChassisUnit::NonFiniteState() const {
  // Runs every step: the names are built only for a body that failed.
  const auto who = [this](std::size_t i) {
    if (i == 0) {
      return std::string(
          "the body (outputs position, yaw, linear_velocity, yaw_rate, body_linear_velocity)");
    }
    const std::size_t k = i - 1;
    const int sm = steer_motor_[k];
    const std::string d = std::to_string(drive_motor_[k]);
    return "wheel " + std::to_string(k) + " (outputs " +
           (sm >= 0 ? "steer_angle[" + std::to_string(sm) + "], steer_rate[" + std::to_string(sm) +
                          "], "
                    : std::string()) +
           "drive_rate[" + d + "], wheel_contact[" + std::to_string(2 * k) + "])";
  };
  for (std::size_t i = 0; i < ode_->BodyCount(); ++i) {
    const dBodyID b = ode_->Body(i);
    if (!AllFinite(dBodyGetPosition(b), 3)) return "position of " + who(i);
    if (!AllFinite(dBodyGetQuaternion(b), 4)) return "orientation of " + who(i);
    if (!AllFinite(dBodyGetLinearVel(b), 3)) return "linear velocity of " + who(i);
    if (!AllFinite(dBodyGetAngularVel(b), 3)) return "angular velocity of " + who(i);
  }
  return {};
}

std::string ChassisUnit::OffFloorWheel() const {
  const models::Floor& fl = scene_.floor;
  for (int k = 0; k < wheel_count_; ++k) {
    const GeomContact& gc = ode_->floor->contact(k);
    if (fl.min_x_m <= gc.x_m && gc.x_m <= fl.max_x_m && fl.min_y_m <= gc.y_m &&
        gc.y_m <= fl.max_y_m) {
      continue;
    }
    return "wheel " + std::to_string(k) + "'s contact (" + cosim::FormatValue(gc.x_m) + ", " +
           cosim::FormatValue(gc.y_m) + ") m is off the floor of scene '" + scene_.name + "' (x " +
           cosim::FormatValue(fl.min_x_m) + " to " + cosim::FormatValue(fl.max_x_m) + ", y " +
           cosim::FormatValue(fl.min_y_m) + " to " + cosim::FormatValue(fl.max_y_m) +
           " m): the robot ran off the scene's floor";
  }
  return {};
}

void ChassisUnit::ComputeOutputs() {
  const Ode& o = *ode_;
  const dReal* rb = dBodyGetRotation(o.body);
  const dReal* pb = dBodyGetPosition(o.body);
  const dReal* vb = dBodyGetLinearVel(o.body);
  const dReal* wb = dBodyGetAngularVel(o.body);
  const double yaw = Yaw(rb);
  const double c = std::cos(yaw), s = std::sin(yaw);
  yaw_ = models::WrapAngle(yaw);
  yaw_rate_ = wb[2];

  double ex[3], ey[3], ez[3], axle[3];
  Column(rb, 0, ex);
  Column(rb, 1, ey);
  Column(rb, 2, ez);
  // base_link's origin: the body's origin (the centre of mass) plus
  // r = R base_from_com (without a payload -com_height ez); its velocity
  // v + w x r.
  const dReal* q = dBodyGetQuaternion(o.body);
  const double* bc = o.base_from_com;
  double r[3];
  for (int i = 0; i < 3; ++i) r[i] = bc[0] * ex[i] + bc[1] * ey[i] + bc[2] * ez[i];
  for (int i = 0; i < 3; ++i) position_3d_[i] = pb[i] + r[i];
  for (int i = 0; i < 4; ++i) orientation_[i] = q[i];
  const double wxr[3] = {wb[1] * r[2] - wb[2] * r[1], wb[2] * r[0] - wb[0] * r[2],
                         wb[0] * r[1] - wb[1] * r[0]};
  for (int i = 0; i < 3; ++i) velocity_3d_[i] = vb[i] + wxr[i];
  position_[0] = position_3d_[0];
  position_[1] = position_3d_[1];
  linear_velocity_[0] = velocity_3d_[0];
  linear_velocity_[1] = velocity_3d_[1];
  body_linear_velocity_[0] = c * velocity_3d_[0] + s * velocity_3d_[1];
  body_linear_velocity_[1] = -s * velocity_3d_[0] + c * velocity_3d_[1];
  angular_velocity_[0] = Dot(ex, wb);
  angular_velocity_[1] = Dot(ey, wb);
  angular_velocity_[2] = Dot(ez, wb);
  // drive_rate is the first wheel's of each motor (the others are coupled to
  // it).
  for (std::size_t k = 0; k < o.wheels.size(); ++k) {
    const dBodyID w = o.wheels[k];
    Column(dBodyGetRotation(w), 1, axle);
    const dReal* ww = dBodyGetAngularVel(w);
    const double rel[3] = {ww[0] - wb[0], ww[1] - wb[1], ww[2] - wb[2]};
    if (const int sm = steer_motor_[k]; sm >= 0) {
      const auto m = static_cast<std::size_t>(sm);
      // Heading = axle x up; in base_link: (ax_y, -ax_x) of the axle there.
      steer_angle_[m] = models::WrapAngle(std::atan2(-Dot(axle, ex), Dot(axle, ey)));
      steer_rate_[m] = Dot(ez, rel);
    }
    if (leads_drive_motor_[k]) {
      drive_rate_[static_cast<std::size_t>(drive_motor_[k])] = Dot(axle, rel);
    }
    const GeomContact& gc = o.floor->contact(static_cast<int>(k));
    wheel_surface_[k] = gc.surface;
    double vx = 0.0, vy = 0.0;
    o.floor->PatchVelocity(static_cast<int>(k), &vx, &vy);
    wheel_surface_velocity_[2 * k] = c * vx + s * vy;
    wheel_surface_velocity_[2 * k + 1] = -s * vx + c * vy;
    wheel_contact_[2 * k] = gc.x_m;
    wheel_contact_[2 * k + 1] = gc.y_m;
  }
  using models::MovingBox;
  dReal bounds[6];
  dGeomGetAABB(o.body_geom, bounds);
  body_box_[MovingBox::kX] = position_3d_[0];
  body_box_[MovingBox::kY] = position_3d_[1];
  body_box_[MovingBox::kYaw] = yaw_;
  body_box_[MovingBox::kVx] = velocity_3d_[0];
  body_box_[MovingBox::kVy] = velocity_3d_[1];
  body_box_[MovingBox::kYawRate] = yaw_rate_;
  body_box_[MovingBox::kLength] = body_length_;
  body_box_[MovingBox::kWidth] = body_width_;
  body_box_[MovingBox::kZBottom] = bounds[4];
  body_box_[MovingBox::kZTop] = bounds[5];
}

cosim::StepResult ChassisUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  const auto at = [&]() { return " at t = " + cosim::FormatSeconds(t) + " s"; };
  // The master initialises every unit before stepping it, but after a failed
  // step the ODE world may be inconsistent (initialized_ is cleared there),
  // and it is not rebuilt until Initialize or RestoreState: refuse to step it.
  if (!initialized_) {
    return Fail(Where() + ": the ODE world needs Initialize or RestoreState (after a failed " +
                "step, or never initialised)" + at());
  }
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  EnsureOdeForThisThread();
  stepped_since_settle_ = true;
  FloorWorld& f = *ode_->floor;
  SetBeltInputs();
  const double h_s = cosim::NsToSeconds(dt) / static_cast<double>(substeps_);
  SetSuspension(h_s);
  SetJointMotors(brake_, brake_torque_);
  try {
    for (std::int64_t i = 0; i < substeps_; ++i) {
      ApplyTorques();
      if (!f.Step(h_s)) return Fail(Where() + ": dWorldStep failed (out of memory)" + at());
    }
  } catch (const OdeError& e) {
    // The world may be inconsistent: only Initialize or RestoreState again.
    initialized_ = false;
    const std::string bad = NonFiniteState();
    return Fail(Where() + ": " + e.what() + at() +
                (bad.empty() ? std::string() : "; ODE state went non-finite: " + bad));
  }
  if (const std::string bad = NonFiniteState(); !bad.empty()) {
    initialized_ = false;
    return Fail(Where() + ": ODE state went non-finite" + at() + ": " + bad);
  }
  // FloorWorld::Step collided at the new positions already.
  drive_rate_before_ = drive_rate_;  // sized alike in the constructor: no allocation
  ComputeOutputs();
  const double dt_s = cosim::NsToSeconds(dt);
  for (std::size_t m = 0; m < drive_angle_.size(); ++m) {
    drive_angle_[m] += 0.5 * (drive_rate_before_[m] + drive_rate_[m]) * dt_s;
  }
  // Nothing is simulated off the floor: stop there (the world stays
  // consistent, the outputs show where the robot went).
  if (const std::string bad = OffFloorWheel(); !bad.empty()) {
    return Fail(Where() + ": at the end of the step at t = " + cosim::FormatSeconds(t) + " s, " +
                bad);
  }
  return cosim::StepResult::kOk;
}

void ChassisUnit::SaveInternal(cosim::UnitState& state) const {
  state.integers = {initialized_ ? 1 : 0};
  state.reals.clear();
  if (!initialized_) return;
  state.reals.reserve(ode_->BodyCount() * kRealsPerBody);
  for (std::size_t i = 0; i < ode_->BodyCount(); ++i) {
    const dBodyID b = ode_->Body(i);
    for (const auto& [v, n] : {std::pair{dBodyGetPosition(b), 3},
                               {dBodyGetQuaternion(b), 4},
                               {dBodyGetLinearVel(b), 3},
                               {dBodyGetAngularVel(b), 3}}) {
      state.reals.insert(state.reals.end(), v, v + n);
    }
  }
  const std::vector<double> treads = ode_->floor->TreadStates();
  state.reals.insert(state.reals.end(), treads.begin(), treads.end());
}

void ChassisUnit::RestoreInternal(const cosim::UnitState& state) {
  stepped_since_settle_ = true;
  const std::size_t bodies = static_cast<std::size_t>(wheel_count_) + 1;
  // Couplings are velocity rows and carried objects follow the inputs:
  // neither holds state of its own.
  const bool init = state.integers.size() == 1 && state.integers[0] != 0;
  const std::size_t reals =
      init ? bodies * (kRealsPerBody + kTreadStateReals) - kTreadStateReals : 0;
  if (state.integers.size() != 1 || state.reals.size() != reals) {
    throw cosim::UnitError(Where() + ": saved state has " + std::to_string(state.reals.size()) +
                           " reals and " + std::to_string(state.integers.size()) +
                           " integers, expected " + std::to_string(reals) + " and 1");
  }
  initialized_ = false;
  if (!init) return;
  // Parameters came back with the variables: the same build as Initialize,
  // then every body state exactly as saved.
  ThrowIfBadParameters();
  Build();
  const double* r = state.reals.data();
  for (std::size_t i = 0; i < bodies; ++i, r += kRealsPerBody) {
    const dBodyID b = ode_->Body(i);
    dBodySetPosition(b, r[0], r[1], r[2]);
    // dBodySetQuaternion renormalises, which may change the last bit; the
    // saved quaternion is already the normalised one ODE steps with, so it
    // and the rotation matrix derived from it (as dWorldStep derives it) are
    // written back unchanged. The pointers are ODE's own storage.
    dBodySetQuaternion(b, r + 3);
    auto* q = const_cast<dReal*>(dBodyGetQuaternion(b));
    for (int d = 0; d < 4; ++d) q[d] = r[3 + d];
    dQtoR(q, const_cast<dReal*>(dBodyGetRotation(b)));
    dBodySetLinearVel(b, r[7], r[8], r[9]);
    dBodySetAngularVel(b, r[10], r[11], r[12]);
  }
  ode_->floor->SetTreadStates(std::span<const double>(r, kTreadStateReals * (bodies - 1)));
  // The contacts at the restored positions, for the next step.
  ode_->floor->Probe();
  initialized_ = true;
}

}  // namespace linesim::chassis
