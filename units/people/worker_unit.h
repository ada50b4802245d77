#pragma once

#include <array>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"
#include "models/person.h"

namespace linesim::people {

/// A person walking on the line: along waypoints, stopping at each, with a
/// trapezoidal speed profile, pauses, and a gait whose legs a scanner at
/// ankle height sees (docs/references.md, "Workers").
///
/// Schedule (closed form in time, no integration): the worker stands at
/// waypoint 0 until start_time, then walks each segment k -> k + 1 from rest
/// to rest: accelerating at `acceleration` to `walking_speed`, walking, decelerating
/// at `acceleration` (a triangle when the segment is shorter than
/// walking_speed^2 / acceleration), and stands pause_s[k + 1] at waypoint k + 1. The
/// heading is the segment's direction (it turns on the spot while it
/// stands). After the last waypoint it stands there.
///
/// Gait: the phase (strides) is the distance walked / stride_length, so a
/// stance foot stays fixed on the floor at any speed. Each leg spends the
/// fraction stance_fraction of a stride on the floor, where, relative to the
/// body, it moves back by stance_fraction * stride_length at the walking
/// speed (from +f/2 to -f/2 stride lengths along the heading, f the stance
/// fraction); in swing it returns forward along a half cosine. The right
/// leg is half a stride behind the left. The offsets scale with speed /
/// the segment's cruise speed: while cruising a stance foot stays fixed on
/// the floor; the steps shorten as the worker slows, and standing the feet
/// are side by side (the stance foot slides a little over the 1 s ramps: a
/// simplification). Legs are vertical cylinders of
/// leg_radius (the section at a scanner's height) from the floor to
/// crotch_height, leg_spacing apart across the heading; the torso is a
/// cylinder of torso_radius from crotch_height to stature.
///
/// Yielding to robots (`robots` > 0: the input `robots`, the robots' bodies
/// as models::MovingBox values): the walk above runs on the worker's own
/// clock, which stops while a moving robot (faster than 0.05 m/s) is in
/// the way: the next step would bring the torso closer to its body than
/// `stop_distance` and closer than it is now. The worker then stands (speed
/// 0, the gait held) until the robot has passed or stopped, and walks on
/// where the plan left off; `waiting` says it, `time_waited` sums it.
/// stop_distance 0 (the default): the worker never yields (a person who
/// does not look: the worst case a safety function must handle).
///
/// Outputs: the pose, velocity, speed, the legs' positions and velocities,
/// and `cylinders`: per cylinder (left leg, right leg, torso)
/// [x, y, vx, vy, radius, z_bottom, z_top]: the shapes a laser scanner and
/// the clearance unit read (a scanner extrapolates each to a beam's time
/// with its velocity).
class WorkerUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "worker";
  /// Cylinders of `cylinders` and their numbers each.
  static constexpr int kCylinders = 3;
  static constexpr int kCylinderValues = 7;

  /// At least one waypoint (one: a person standing there); `robots` robots'
  /// bodies to yield to.
  WorkerUnit(std::string name, std::vector<std::array<double, 2>> waypoints_m, int robots = 0);

  std::vector<cosim::ParameterProblem> CheckParameters() const override;
  void Setup(cosim::TimeNs start, cosim::TimeNs stop) override;
  void Initialize() override;
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

  /// Where the walk is at time t (s after the start), for the outputs and
  /// the tests: distance walked (m), speed (m/s), the segment whose
  /// direction the heading is, and the position.
  struct State {
    double distance_m = 0.0, speed_mps = 0.0;
    double acceleration_mps2 = 0.0;  // of the speed profile (0 cruising or standing)
    double cruise_mps = 0.0;         // the segment's top speed
    std::size_t segment = 0;
    double x_m = 0.0, y_m = 0.0;
  };
  State At(double t_s) const;
  /// A leg's offset along the heading from the body centre (m) and its rate
  /// per metre walked, at gait phase `phase` (strides).
  void LegOffset(double phase, double& offset_m, double& rate) const;
  /// The time (s after the start) at which segment k starts and ends its walk.
  double SegmentStart(std::size_t k) const { return plan_[k].start_s; }
  double SegmentEnd(std::size_t k) const { return plan_[k].start_s + plan_[k].duration_s; }

 private:
  struct Segment {
    double start_s, duration_s, length_m, cruise_mps, ramp_s, cum_m;
    double ux, uy;
  };
  void Plan();
  void Evaluate(double t_s);
  /// Whether walking on from walk time t0 to t1 (s) brings the worker
  /// closer than stop_distance to a moving robot, and closer than now.
  bool Blocked(double t0_s, double t1_s) const;

 protected:
  /// The state is the time waited (the worker's own clock is the time less
  /// it); the plan is derived again from the restored parameters.
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:

  std::vector<std::array<double, 2>> waypoints_;
  std::vector<Segment> plan_;
  cosim::TimeNs start_ = 0;

  // Parameters.
  std::vector<double> pause_s_;
  double start_time_s_ = 0.0;
  double speed_ = 1.37, acceleration_ = 1.0, stride_length_ = 1.41, stance_fraction_ = 0.6,
         initial_phase_ = 0.0, initial_yaw_deg_ = 0.0;
  // The body (models/person.h has the sources).
  double leg_radius_ = models::PersonBody{}.leg_radius_m,
         leg_spacing_ = models::PersonBody{}.leg_spacing_m,
         crotch_height_ = models::PersonBody{}.crotch_height_m,
         torso_radius_ = models::PersonBody{}.torso_radius_m,
         stature_ = models::PersonBody{}.stature_m;

  double stop_distance_ = 0.0;
  // Inputs: the robots' bodies (empty without robots).
  std::vector<double> robots_;
  // State: the time spent waiting (ns, exact: without waiting the walk's
  // clock is the time itself, to the bit).
  cosim::TimeNs waited_ = 0;

  // Outputs.
  std::vector<double> pose_, velocity_, legs_, leg_velocities_, cylinders_;
  bool waiting_ = false;
  double waited_s_ = 0.0;
  double speed_out_ = 0.0, distance_out_ = 0.0, phase_out_ = 0.0;
};

}  // namespace linesim::people
