#pragma once

#include <array>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"
#include "models/polyline.h"

namespace linesim::control {

/// Turns a position and heading (map frame) into a body velocity and yaw
/// rate command, as a sampled-data controller (run it at the wheel
/// controller's rate). Two bases:
///  - omnidirectional (default): the robot keeps the `heading` while it
///    translates (the law below);
///  - differential (skid-steer, differential drive): the robot cannot move
///    sideways; see "Differential base" below.
///
/// kPath follows the polyline of the waypoints: map-frame velocity
///   t * v_along(s) + n * (-k_cross e),
/// with t the unit tangent of the nearest segment, n its left normal, e the
/// signed cross-track error (+ left of the path) and s the progress. v_along
/// ramps up at `acceleration` from the start (a committed state), stays at
/// `speed`, and comes down as min(sqrt(2 a d), k_position d) with d the
/// distance left along the path (signed: past the goal it backs up). When
/// the robot is within goal_tolerance of the last waypoint, done latches and
/// the command is zero from then on.
///
/// kHold holds the first waypoint: velocity -k_position (p - p_ref); done
/// says whether it is within goal_tolerance (it never latches).
///
/// Omnidirectional base, in both modes: the velocity is clamped to
/// max_speed, the yaw rate is k_yaw wrap(heading - yaw) clamped to
/// max_yaw_rate, and the velocity is rotated into base_link by -yaw (the
/// measured heading input).
///
/// Differential base: velocity_command = [v, 0], and the yaw rate steers
/// the heading psi onto the direction of a desired map velocity d:
///   path: d = t * v_along - n * k_cross e (as above, before clamping),
///         always driven forward; where d = 0 short of the goal (the ramp
///         at 0 at the start, on the path) the direction of t towards the
///         goal is aimed at instead, so the robot turns before it starts;
///   hold: d = -k_position (p - p_ref), driven forward or backward,
///         whichever heading is nearer (so a small correction never turns
///         the robot round); zero within goal_tolerance.
/// With h = wrap(atan2(d) - psi) (backward: wrap(atan2(-d) - psi)):
///   |h| > turn_in_place_angle: v = 0 (turn in place: at the start and at
///                              sharp waypoint corners),
///   otherwise:                 v = +-|d| cos h,
///   yaw rate = k_yaw h, clamped to max_yaw_rate; |v| clamped to max_speed.
/// The along-track ramp continues from v_along cos h (0 while turning in
/// place), so the robot accelerates gently out of every corner. The
/// `heading` parameter is unused. At |h| <= turn_in_place_angle < pi/2 the robot
/// heads towards the path; near it the cross-track error obeys
/// e'' + k_yaw e' + k_yaw k_cross e = 0 (linearised, v_along > 0).
class PathFollowerUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "path_follower";

  enum class Mode { kPath, kHold };
  /// What the base can do: translate in any direction and turn
  /// independently, or only drive along its heading and turn.
  enum class Base { kOmnidirectional, kDifferential };

  /// kPath needs at least two waypoints without zero-length segments, kHold
  /// at least one (extra ones are ignored); CheckParameters reports them.
  /// The differential base adds the parameter turn_in_place_angle.
  PathFollowerUnit(std::string name, Mode mode, std::vector<std::array<double, 2>> waypoints_m,
                   Base base = Base::kOmnidirectional);

  std::vector<cosim::ParameterProblem> CheckParameters() const override;
  /// Validates (throws cosim::UnitError listing every problem), resets the
  /// speed ramp and done, and computes the outputs. Idempotent.
  void Initialize() override;
  /// The outputs for the current position and heading; the state is not changed.
  void UpdateOutputs() override { ComputeOutputs(FindNearest()); }
  /// Commits the sample taken at t (speed ramp, done) and recomputes.
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

  Mode mode() const { return mode_; }
  Base base() const { return base_; }
  /// Length of the path (0 in hold mode).
  double length_m() const { return cumulative_m_.empty() ? 0.0 : cumulative_m_.back(); }

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  struct Sample {
    double vx_map_mps = 0.0, vy_map_mps = 0.0, yaw_rate_rad_s = 0.0;
    // Differential base: the forward speed command (the body velocity is
    // [forward, 0]); the omnidirectional base rotates the map velocity.
    double forward_mps = 0.0;
    // Path mode: the path direction towards the goal, the heading to aim
    // for when the desired velocity is zero (at the start: ramp at 0).
    double toward_goal_x = 0.0, toward_goal_y = 0.0;
    double along_mps = 0.0;  // path mode: the along-track speed used
    double cross_track_m = 0.0, progress_m = 0.0;
    bool at_goal = false;
  };
  /// Whether the segment into waypoint k (> 0, both ends finite) has no
  /// length.
  bool ZeroSegment(std::size_t k) const;
  // Path mode: the nearest path point to the position, the end segments
  // extended (found is false in hold mode, or when no distance compares
  // below infinity).
  models::PolylinePoint FindNearest() const;
  /// The command for the position whose nearest path point is n, from the state.
  Sample Evaluate(const models::PolylinePoint& n) const;
  /// The differential base's steering of the heading onto the direction of
  /// the desired map velocity in s (see the class comment).
  void SteerDifferential(Sample& s) const;
  void ComputeOutputs(const models::PolylinePoint& n);

  Mode mode_;
  Base base_;
  std::vector<std::array<double, 2>> waypoints_m_;
  // Path length at each waypoint (path mode), once for the search.
  std::vector<double> cumulative_m_;

  // Parameters.
  double speed_ = 0.3;
  double acceleration_ = 0.3;
  double yaw_ = 0.0;  // the `heading` parameter
  double k_cross_ = 1.0;
  double k_position_ = 1.0;
  double k_yaw_ = 1.0;
  double max_speed_ = 0.5;
  double max_yaw_rate_ = 0.5;
  double goal_tolerance_ = 0.02;
  // Differential base: heading error beyond which the robot stops and
  // turns in place. 0.5 rad (29 deg): cos h >= 0.88 while driving, so the
  // robot never drives far off the direction it wants.
  double turn_in_place_angle_ = 0.5;

  // Inputs.
  std::vector<double> position_;
  double yaw_measured_ = 0.0;
  // Outputs.
  std::vector<double> velocity_command_;
  double yaw_rate_command_ = 0.0;
  double cross_track_error_ = 0.0;
  double progress_ = 0.0;
  bool done_ = false;

  // State: the along-track speed the ramp allows at this sample, and done.
  double ramp_mps_ = 0.0;
  bool done_latched_ = false;
};

}  // namespace linesim::control
