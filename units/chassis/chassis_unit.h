#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"
#include "models/dc_motor_params.h"
#include "models/raw3.h"

namespace linesim::chassis {

/// A Rob@Work 3 style robot with steer+drive wheel modules on a floor with
/// conveyor-belt patches, simulated with ODE (dWorldStep).
///
/// Model: a body box (no collision) and one body per module (the module
/// mass lumped into its wheel), joined by one ODE hinge2 per module: axis 1
/// the steering axis (vertical, on the body, soft along it: the suspension),
/// axis 2 the wheel axle. Wheels are spheres of the wheel radius (one
/// contact point each, directly below the steering axis: no scrub torque
/// when steering in place). Each wheel contact takes the surface velocity of
/// the belt patch under it, with Coulomb friction while it slides
/// (units/chassis/floor_world.h). Input torques act between module and body
/// (dBodyAddTorque in equal and opposite pairs about the body's vertical and
/// the wheel's axle), with the viscous joint friction, every internal step;
/// the brake is an ODE joint motor (target velocity 0, force limit
/// brake_torque) on both hinge2 axes.
///
/// Frames: map (x, y, z up) and base_link (x forward, y left), whose origin
/// in x and y is the planform centre of the body, which is also its centre of
/// mass and the point wheel_x and wheel_y refer to. Wheel heading
/// (steer angle) 0 is base_link +x, positive counter-clockwise seen from
/// above. A positive drive torque or drive rate rolls the wheel forward
/// along its heading.
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

  /// wheel_count >= 1 modules and belt_count >= 0 belt patches (structural:
  /// they size the arrays; with no belts there are no belt parameters and no
  /// belt_velocity input). Throws cosim::UnitError otherwise.
  ChassisUnit(std::string name, int wheel_count, int belt_count);
  ~ChassisUnit() override;

  std::vector<cosim::ParameterProblem> CheckParameters() const override;
  /// Validates the parameters (throws cosim::UnitError listing every bad
  /// value), builds and settles the robot, computes the outputs.
  void Initialize() override;
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

  int wheel_count() const { return wheel_count_; }
  int belt_count() const { return belt_count_; }

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  // The ODE objects; defined in the .cc so that ODE stays private.
  struct Ode;

  /// Creates a fresh world with the robot at the initial pose (no settle).
  void Build();
  void Settle();
  /// Suspension ERP/CFM for internal step h_s (only when h_s changes).
  void SetSuspension(double h_s);
  void SetJointMotors(bool hold, double max_torque_nm);
  void ApplyTorques();
  /// Empty when every body state is finite, else what is not.
  std::string NonFiniteState() const;
  void ComputeOutputs();

  int wheel_count_;
  int belt_count_;

  // Parameters.
  double body_length_ = 1.03;
  double body_width_ = 0.57;
  double body_height_ = 0.40;
  double mass_ = models::raw3::kMassKg;
  double module_mass_ = 5.0;
  double com_height_ = 0.13;
  double wheel_radius_ = models::raw3::kWheelRadiusM;
  std::vector<double> wheel_x_, wheel_y_;
  // The RE 40 rotor (models::DcMotorParams) through the Rob@Work 3 steer
  // belt and drive gear, as eta N^2 J_rotor: the rotor as the dc_motor
  // unit's full-mode equations see it from the output (J_eff = J + J_load /
  // (eta N^2)).
  double steer_rotor_inertia_ = models::raw3::kSteerGearEfficiency * models::raw3::kSteerGearRatio *
                                models::raw3::kSteerGearRatio *
                                models::DcMotorParams{}.rotor_inertia_kgm2;
  double drive_rotor_inertia_ = models::raw3::kDriveGearEfficiency * models::raw3::kDriveGearRatio *
                                models::raw3::kDriveGearRatio *
                                models::DcMotorParams{}.rotor_inertia_kgm2;
  double steer_friction_ = 0.01;
  double drive_friction_ = 0.01;
  double friction_ = 0.8;
  double contact_stiffness_ = 1e6;
  double contact_damping_ = 1e4;
  double slip_damping_ = 1e5;
  double suspension_stiffness_ = 1e7;
  double suspension_damping_ = 1e4;
  double brake_torque_ = 30.0;
  std::int64_t substeps_ = 1;
  double initial_x_ = 0.0;
  double initial_y_ = 0.0;
  double initial_yaw_ = 0.0;
  std::vector<double> belt_center_x_, belt_center_y_, belt_length_, belt_width_, belt_direction_;

  // Inputs.
  std::vector<double> steer_torque_, drive_torque_, belt_velocity_;
  bool brake_ = false;

  // Outputs.
  std::vector<double> steer_angle_, steer_rate_, drive_rate_;
  std::vector<double> pose_, velocity_, body_velocity_;
  std::vector<double> wheel_surface_, wheel_surface_velocity_, wheel_contact_;

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
