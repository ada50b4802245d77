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
/// Differential base: velocity_command = [v, 0]; the yaw rate steers the
/// heading psi onto an aim direction, and v drives along it.
///
///   path: the robot follows one committed segment at a time, the ACTIVE
///         segment i (state; at Initialize the nearest one). With t_i its
///         unit tangent, n_i its left normal and e_i the signed distance
///         from its line (+ left), the aim is
///           a = sgn(r) t_i speed - n_i k_cross e_i,
///         r the distance left along the path to the goal (nearest point,
///         as above; on the last segment, from the projection on it), and
///         on the last segment, once k_cross |r| < speed (k_cross > 0),
///           a = t_i k_cross r - n_i k_cross e_i = k_cross (goal - p):
///         the robot aims AT the goal (continuous at k_cross |r| = speed;
///         the ratio e / r then stays constant: a straight line to the
///         goal), so a sideways offset at the goal's perpendicular is
///         driven out too. The aim points towards the goal (past it,
///         backwards along the path): the robot turns round and drives
///         forwards along it, never backwards.
///         The aim vanishes only at the goal (done has latched there:
///         goal_tolerance > 0), and its direction depends on the active
///         segment only, not on which segment is nearest: no flipping when
///         the commanded speed is small (at the start, at a corner), and at
///         a corner the robot turns onto the next tangent, not across it.
///         At cruise the heading error is atan(k_cross e / speed) and the
///         cross-track error obeys e'' + k_yaw e' + k_yaw k_cross e = 0
///         (linearised; slower at lower speed, never less damped); with
///         k_yaw >= 4 k_cross it is not oscillatory.
///         Along-track speed: the ramp and the goal as above (on the last
///         segment d is the straight-line distance to the goal, never 0
///         outside goal_tolerance: no stall beside the goal), and, for a
///         SHARP corner (an interior waypoint whose heading change exceeds
///         turn_in_place_angle, where the robot must turn in place),
///           |v_along| <= sqrt(2 acceleration D),
///         D the distance along the path from the projection on the active
///         segment to the next sharp corner: the robot stops AT the corner
///         (in finite time; sampled at period T it passes it by at most
///         acceleration T^2 / 2) instead of arriving at full speed. Gentle
///         corners (heading change <= turn_in_place_angle) are driven
///         through without slowing (cos h >= cos turn_in_place_angle).
///         Segment switch (a rule on progress, committed in DoStep): the
///         next segment becomes active when the distance left along the
///         active one is <= acceleration T^2 (the robot has reached its
///         end: where the sqrt profile ends) or the nearest path point lies
///         beyond its end; never back.
///   hold: d = -k_position (p - p_ref), driven forward or backward,
///         whichever heading is nearer (so a small correction never turns
///         the robot round); zero within goal_tolerance; the aim is d.
/// With h = wrap(atan2(aim) - psi) (hold backward: wrap(atan2(-d) - psi)):
///   |h| > turn_in_place_angle: v = 0 (turn in place: at the start and at
///                              sharp corners),
///   otherwise:                 path v = |v_along| cos h (forwards:
///                              the aim already points to the goal),
///                              hold v = +-|d| cos h,
///   yaw rate = k_yaw h, clamped to max_yaw_rate; |v| clamped to max_speed.
/// The along-track ramp continues from |v_along| cos h (0 while turning in
/// place), so the robot accelerates gently out of every corner. At a sharp
/// corner the robot stops, turns in place with a yaw rate of one sign
/// (h decays as (1 - k_yaw T)^k, no overshoot for k_yaw T < 1) and drives
/// on. The `heading` parameter is unused.
class PathFollowerUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "path_follower";

  enum class Mode { kPath, kHold };
  /// What the base can do: translate in any direction and turn
  /// independently, or only drive along its heading and turn.
  enum class Base { kOmnidirectional, kDifferential };

  /// kPath needs at least two waypoints without zero-length segments, kHold
  /// at least one (extra ones are ignored); CheckParameters reports them.
  /// The differential base adds the parameter turn_in_place_angle, in
  /// (0, pi/2), and requires k_yaw and max_yaw_rate > 0 (it turns only by
  /// the yaw rate; the omnidirectional base may switch them off with 0).
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
  /// The differential base in hold mode: steers the heading onto the
  /// direction of the hold velocity in s, forwards or backwards, and sets
  /// the forward speed (see the class comment).
  void SteerHold(Sample& s) const;
  /// The differential base in path mode (see the class comment).
  Sample EvaluateDifferentialPath(const models::PolylinePoint& n) const;
  /// Differential path: the robot's projection on segment i, as the
  /// distance left to its end and the signed distance from its line.
  struct OnSegment {
    double to_end_m = 0.0, cross_track_m = 0.0;
  };
  OnSegment ProjectOnSegment(std::size_t i) const;
  /// Differential path: the distance along the path from the projection on
  /// the active segment to the next sharp corner (infinity: none ahead),
  /// from the table sharp_corner_after_m_.
  double ToSharpCorner(const OnSegment& on) const;
  /// Differential path: fills sharp_corner_after_m_ from the waypoints and
  /// turn_in_place_angle (at construction, Initialize and restore: not per
  /// step; the parameters are locked after Initialize).
  void FindSharpCorners();
  /// Whether interior waypoint k turns the path by more than
  /// turn_in_place_angle (the robot must stop there and turn in place).
  bool SharpCorner(std::size_t k) const;
  /// Whether the saved state holds the active segment (differential path).
  bool SavesSegment() const;
  void ComputeOutputs(const models::PolylinePoint& n);

  Mode mode_;
  Base base_;
  std::vector<std::array<double, 2>> waypoints_m_;
  // Path length at each waypoint (path mode), once for the search.
  std::vector<double> cumulative_m_;
  // Differential path: per segment, the distance along the path from its
  // end to the next sharp corner (infinity: none ahead). Empty otherwise.
  std::vector<double> sharp_corner_after_m_;

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

  // State: the along-track speed the ramp allows at this sample, and done;
  // differential path: the active segment (saved only for that base, so
  // the omnidirectional state is unchanged).
  double ramp_mps_ = 0.0;
  bool done_latched_ = false;
  std::size_t active_segment_ = 0;
};

}  // namespace linesim::control
