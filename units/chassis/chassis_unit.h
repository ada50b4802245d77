#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"
#include "models/scene.h"

namespace linesim::chassis {

struct Tread;      // units/chassis/floor_world.h
class FloorWorld;  // units/chassis/floor_world.h

/// A wheeled robot base on a factory floor with conveyor-belt patches,
/// obstacles and belt-carried objects, simulated with ODE (dWorldStep). One
/// code for any wheel topology: a swerve base (Rob@Work 3: every wheel with
/// its own steering and drive motor) and a skid-steer base (Husky A200: four
/// fixed wheels, the two of a side on one drive motor through a belt).
///
/// Topology (structural): wheel k is steered by steering motor
/// steer_motor[k] (-1: a fixed wheel) and driven by drive motor
/// drive_motor[k]; wheels with the same drive motor are coupled.
///
/// Model: a body box and one body per wheel (a steered module's mass lumped
/// into its wheel). A steered wheel hangs on an ODE hinge2: axis 1 the
/// steering axis (vertical, on the body, soft along it: the suspension),
/// axis 2 the wheel axle. A fixed wheel turns on a plain hinge about its
/// axle, mounted rigidly (the soft contacts make four rigid wheels
/// determinate). Wheels sharing a drive motor are coupled by an ODE angular
/// motor between them (zero relative spin about the axle, a force limit far
/// above any wheel torque): a real constraint, like the belt it models; the
/// motor's torque acts on the first wheel of its group (reaction on the
/// body) and the coupling carries its share to the others. Wheels are
/// spheres of their radius (one contact point each, directly below the
/// steering axis or axle centre). Each wheel contact takes the surface
/// velocity and friction of the belt patch under it, else the floor's (or,
/// on a terrain piece, the piece's surface friction, still), with Coulomb
/// friction while it slides (units/chassis/floor_world.h). The body's solid
/// and its mass are separate facts: the body box (body_length x body_width
/// on base_link's x and y, from body_bottom to body_bottom + body_height
/// above base_link) collides with the scene's obstacles, carried objects and
/// terrain pieces, never with the floor; the body's mass (mass less the
/// wheels) has its centre com_height above base_link and the inertia of a
/// uniform box of the body's size about that centre (an idealisation: the
/// mass spread over the body's size, centred where the robot's data put
/// its centre of mass, e.g. low batteries). A payload (payload_mass at
/// payload_position in base_link, a box of payload_size) is part of the
/// body: one rigid body whose origin ODE puts at the centre of mass of body
/// and payload (ODE requires it there), with their combined inertia about
/// it (parallel axes), and the body and payload boxes as geoms offset from
/// it; no joint, so no constraint rows. Input torques act between wheel
/// and body (dBodyAddTorque in equal and opposite pairs about the body's
/// vertical and the wheel's axle), with the viscous joint friction, every
/// internal step; the brake is an ODE joint motor (target velocity 0, force
/// limit brake_torque) on every wheel joint axis.
///
/// Frames: map (x, y, z up) and base_link (x forward, y left, z up from the
/// wheels' contact plane), whose origin is the planform centre of the body
/// box on the contact plane (under the body's centre of mass, which is
/// com_height above it), the point wheel_x and wheel_y refer to. position,
/// position_3d, linear_velocity and velocity_3d are of that origin (on a
/// ramp it lies on the ramp, and a payload moves the centre of mass, not
/// it). Wheel heading
/// (steer angle) 0 is base_link +x, positive counter-clockwise seen from
/// above; fixed wheels head along +x. A positive drive torque or drive rate
/// rolls the wheel forward along its heading.
///
/// Scene: the flat floor (bounded by its rectangle: a step that ends with a
/// wheel contact outside it fails), its belts, obstacles, carried objects
/// and terrain pieces (rigid tilted boxes the wheels drive on with the
/// friction of the piece's surface, and the body and payload boxes collide
/// with; units/chassis/floor_world.h). The robot is built on the floor
/// plane, or, when a terrain top face lies under a wheel at the initial
/// pose, tilted and lifted onto the plane through the ground heights under
/// its wheels (PlaceOnTerrain); Initialize refuses an initial pose whose
/// wheels would still start sunk into a terrain piece (more than
/// kMaxStartDepthM: against its side).
///
/// Initialize builds the robot at the initial pose with every wheel
/// pressed in by its share of the weight, then settles it for 0.3 s with
/// the joints held and every belt still, and finally moves it rigidly back
/// to exactly (initial_x, initial_y, initial_yaw) with all velocities set
/// to zero (height, roll and pitch keep their settled values), so that it
/// is at rest on the floor at time zero.
class ChassisUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "chassis";
  /// Most wheels a chassis may have (wheel_count 1 to kMaxWheels).
  static constexpr int kMaxWheels = 64;
  /// Deepest a wheel may start in a terrain piece (the robot is built on
  /// the floor plane; a wheel deeper in a piece would be thrown out of it).
  static constexpr double kMaxStartDepthM = 0.01;

  /// Checks a topology (steer_motor and drive_motor per wheel, as in the
  /// class comment): empty when usable, else what is wrong, naming the key.
  /// 1 to kMaxWheels wheels; every motor index in [0, wheel count), or -1
  /// for a fixed wheel's steer_motor; checked before anything is sized by
  /// an index.
  static std::string TopologyProblem(const std::vector<int>& steer_motor,
                                     const std::vector<int>& drive_motor);

  /// `steer_motor` and `drive_motor` give the topology (one entry per
  /// wheel); `scene` the belts (one belt_velocity and belt_travel input
  /// each), the floor's and the belts' friction, the obstacles and carried
  /// objects and terrain pieces. Throws cosim::UnitError for a bad
  /// topology or scene: a surface index out of range, a terrain piece
  /// without a positive size, or a carried object not lying along its belt's
  /// length at zero travel.
  /// `moving_boxes` and `moving_cylinders` other things that move in the
  /// scene (other robots' bodies, workers' legs and torsos) add the inputs
  /// of those names; the body collides with them (FloorWorld::SetMovingSolids).
  ChassisUnit(std::string name, std::vector<int> steer_motor, std::vector<int> drive_motor,
              models::Scene scene, int moving_boxes = 0, int moving_cylinders = 0);
  ~ChassisUnit() override;

  /// The declared rules, and: the wheels (wheel_count x module_mass) weigh
  /// less than mass.
  std::vector<cosim::ParameterProblem> CheckParameters() const override;
  /// Validates the parameters (throws cosim::UnitError listing every bad
  /// value), builds and settles the robot, computes the outputs. Throws
  /// cosim::UnitError when a settled wheel contact is off the scene's floor.
  void Initialize() override;
  /// Fails (kError, naming the wheel, its contact point and the time) when
  /// a wheel contact ends the step outside the floor's rectangle
  /// (models::Scene::floor): the robot ran off the scene's floor, where
  /// nothing is simulated. The world stays consistent.
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

  int wheel_count() const { return wheel_count_; }
  int belt_count() const { return belt_count_; }
  int steer_motor_count() const { return steer_motor_count_; }
  int drive_motor_count() const { return drive_motor_count_; }
  /// Spin rate of wheel k about its axle relative to the body (rad/s), as
  /// drive_rate reports it for the first wheel of each drive motor; for
  /// tests and diagnostics of coupled wheels.
  double WheelRate(int k) const;

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  // The ODE objects; defined in the .cc so that ODE stays private.
  struct Ode;

  /// Declares the tread and wheel_friction parameters (sized by the wheel
  /// and surface counts).
  void DeclareTreadParameters();
  /// Throws cosim::UnitError for a scene reference or size the chassis
  /// cannot build (a surface index out of range, an empty floor, ...).
  void CheckScene() const;
  /// Declares the parameters (the tread's among them).
  void DeclareParameters();
  /// Declares the inputs and outputs (after the parameters).
  void DeclareSignals();
  /// Wheel k's tread for the floor world: stiffness and damping at its
  /// static load, its patch, its friction on the floor world's surfaces.
  Tread WheelTread(std::size_t k) const;
  /// Creates a fresh world with the robot at the initial pose (no settle).
  void Build();
  /// Before settling: when terrain lies under a wheel at the initial pose,
  /// tilts and lifts the robot (rigidly, about base_link's origin) onto the
  /// plane through the ground heights under its wheels.
  void PlaceOnTerrain();
  /// The scene's belts, floor, obstacles, carried objects and terrain into f.
  void AddScene(FloorWorld& f) const;
  void Settle();
  /// Suspension ERP/CFM for internal step h_s (only when h_s changes).
  void SetSuspension(double h_s);
  /// hold: every joint motor at velocity 0 up to max_torque_nm (the brake,
  /// or holding while settling); else each motor with a torque-speed slope
  /// is its joint's motor row (implicit), the others none.
  void SetJointMotors(bool hold, double max_torque_nm);
  bool ImplicitSteer(std::size_t m) const { return steer_torque_slope_[m] < 0.0; }
  bool ImplicitDrive(std::size_t m) const { return drive_torque_slope_[m] < 0.0; }
  void ApplyTorques();
  /// Hands belt_velocity and belt_travel to the floor world.
  void SetBeltInputs();
  /// Empty when every body state is finite, else what is not.
  std::string NonFiniteState() const;
  /// Empty when every wheel contact (as last collided) is on the scene's
  /// floor rectangle, else which wheel is off it and where.
  std::string OffFloorWheel() const;
  void ComputeOutputs();

  int wheel_count_;
  int belt_count_;
  std::vector<int> steer_motor_, drive_motor_;
  // Per wheel: 1 if it is the first wheel of its drive motor, the one the
  // motor's torque goes to and whose spin is the motor's drive_rate (the
  // others are coupled to it).
  std::vector<char> leads_drive_motor_;
  int steer_motor_count_ = 0;
  int drive_motor_count_ = 0;
  models::Scene scene_;

  // Parameters, each declared with its rule. Robot-specific ones start NaN
  // (Rule::NoDefault): Initialize refuses them until they are set.
  double body_length_;
  double body_width_;
  double body_height_;
  double body_bottom_;
  double mass_;
  double module_mass_;
  double com_height_;
  std::vector<double> wheel_radius_, wheel_x_, wheel_y_;
  // Rotor inertias reflected through the gears (eta N^2 J_rotor): robot-specific.
  double steer_rotor_inertia_;
  double drive_rotor_inertia_;
  // A payload fixed on the body (none by default).
  double payload_mass_ = 0.0;
  std::vector<double> payload_position_, payload_size_;
  // Generic values, with the reasons in the parameter descriptions.
  double steer_friction_ = 0.01;
  double drive_friction_ = 0.01;
  double body_friction_ = 0.5;
  double contact_stiffness_ = 1e6;
  double contact_damping_ = 1e4;
  // Per wheel: its tread (a transient brush tyre, units/chassis/floor_world.h)
  // and its Coulomb coefficient on each scene surface (wheel-major).
  std::vector<double> tread_slip_stiffness_, tread_cornering_stiffness_;
  std::vector<double> tread_longitudinal_relaxation_, tread_lateral_relaxation_;
  std::vector<double> tread_damping_ratio_, tread_patch_length_, tread_patch_width_;
  std::vector<double> wheel_friction_;
  double suspension_stiffness_ = 1e7;
  double suspension_damping_ = 1e4;
  double brake_torque_ = 30.0;
  std::int64_t substeps_ = 1;
  double initial_x_ = 0.0;
  double initial_y_ = 0.0;
  double initial_yaw_ = 0.0;

  // Inputs.
  std::vector<double> steer_torque_, drive_torque_, belt_velocity_, belt_travel_;
  std::vector<double> steer_torque_slope_, steer_torque_rate_, drive_torque_slope_,
      drive_torque_rate_;
  std::vector<double> moving_boxes_, moving_cylinders_;
  std::int64_t own_box_ = -1;
  bool brake_ = false;

  // Outputs.
  std::vector<double> steer_angle_, steer_rate_, drive_rate_, drive_angle_;
  std::vector<double> position_, linear_velocity_, body_linear_velocity_;
  std::vector<double> position_3d_, orientation_, velocity_3d_, angular_velocity_;
  // drive_rate_ at the start of the step (drive_angle_'s trapezoid).
  std::vector<double> drive_rate_before_;
  double yaw_ = 0.0;
  double yaw_rate_ = 0.0;
  std::vector<double> wheel_surface_, wheel_surface_velocity_, wheel_contact_;
  std::vector<double> body_box_;

  bool initialized_ = false;
  // The parameter values the world was last built and settled with, and
  // whether it has stepped since: the master may call Initialize several
  // times while it propagates initial values, and settling (300 ODE steps)
  // need not be repeated when nothing it depends on changed.
  std::vector<cosim::Value> settled_parameters_;
  bool stepped_since_settle_ = true;
  std::unique_ptr<Ode> ode_;
};

}  // namespace linesim::chassis
