#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"
#include "models/polynomial_path.h"

namespace linesim::control {

/// Paper 2's parametric trajectory controller (Sobreira et al. 2019,
/// "Autonomous Robot Navigation for Automotive Assembly Task: An Industry
/// Use-Case", Sec. 5, Eqs. 1-17), over a route of polynomial segments
/// (models/polynomial_path.h), driven one after the other.
///
/// Per sample, with the pose (x, y, theta) and the current segment F:
///   t_n      = the global closest parameter on [0, 1] (ClosestParameter);
///   Err_D    = |F(t_n) - (x, y)|                            (Eq. 6, >= 0)
///   F_theta  = atan2(Fy', Fx') at t_n                       (Eq. 7; see
///              models::SegmentHeading for the argument order)
///   Err_theta = wrap(F_theta - theta)                       (Eq. 10)
///   T_theta  = wrap(atan2(Fy(t_n) - y, Fx(t_n) - x) - theta) (Eq. 11, same
///              argument order: the bearing of the closest point from the
///              robot, relative to its heading; > 0: the path is on its left)
///   s        = +1 if T_theta > 0, else -1                   (Eqs. 12 / 13)
///   w = s (K_P,D Err_D + K_I,D I_D) + K_P,theta Err_theta + K_I,theta I_theta
///       + feedForward(t_n)                                  (Eqs. 12-13, 17)
/// with feedForward = v (Fy'' Fx' - Fx'' Fy') / |F'|^3 at t_n (Eq. 17), v the
/// speed commanded at this sample. The integrals:
///   I_theta = integral of Err_theta dt;
///   I_D (distance_integral "unsigned", the default, as Eqs. 12-13 write it) =
///       integral of Err_D dt, >= 0, its sign switched with s like the
///       proportional term; ("signed") = integral of s Err_D dt, added as
///       K_I,D I_D without a further switch: the switch applied to the
///       distance before it is integrated (the usual signed cross-track
///       integral; it removes a steady error under a yaw-rate bias).
/// Anti-windup: each integral is clamped so that its term cannot exceed its
/// max_*_integral_rate (rad/s) (the unsigned distance integral never
/// decreases, so without a clamp it would grow for the whole route; and
/// any integral wound up while the robot turns onto the path overshoots
/// once it is there); and neither integrates in a sample whose yaw rate is
/// clamped at max_yaw_rate (conditional integration).
/// velocity_command = (v, 0): v = speed (paper 2: "the linear velocity is
/// constant"), except the stop at the route's end, which the paper does not
/// describe: v = min(speed, sqrt(2 deceleration r)), r the arc length left
/// from t_n to the end of the last segment, a constant deceleration that
/// ends on the final point. done latches when, on the last segment, t_n
/// reaches 1 or r <= stop_tolerance; then both commands are 0.
/// Segment advance: when t_n of the current segment reaches 1 (the end is
/// the nearest point: the robot is at or past the normal line through the
/// segment's end), the next segment becomes current (repeatedly, in the
/// same sample, past short segments). The index never goes back, so at a
/// joint the segment cannot chatter, whatever the pose noise; and with
/// tangent-continuous joints (the graph's Hermite edges share the node's
/// heading) Err_theta and the feed-forward are continuous across it.
/// UpdateOutputs evaluates the advance without committing it; DoStep
/// commits it, the integrals and done.
class RouteFollowerUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "route_follower";

  explicit RouteFollowerUnit(std::string name, std::vector<models::PolynomialSegment> segments);

  std::vector<cosim::ParameterProblem> CheckParameters() const override;
  /// Validates, resets segment, integrals and done; computes the outputs.
  void Initialize() override;
  void UpdateOutputs() override { ComputeOutputs(Evaluate()); }
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

  const std::vector<models::PolynomialSegment>& segments() const { return segments_; }

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  struct Sample {
    std::size_t segment = 0;
    double t = 0.0;
    double distance = 0.0;     // Err_D (Eq. 6)
    double cross_track = 0.0;  // + left of the path: s Err_D with s from T_theta
    double orientation = 0.0;  // Err_theta (Eq. 10)
    double side = 1.0;         // s
    double speed = 0.0;        // v commanded
    double yaw_rate = 0.0;     // after the clamp
    bool saturated = false;    // the unclamped yaw rate exceeded max_yaw_rate
    bool at_goal = false;
  };
  Sample Evaluate() const;
  void ComputeOutputs(const Sample& s);
  /// Arc length of every segment and what follows each (at Initialize and
  /// restore, not per step).
  void MeasureSegments();
  bool SignedDistanceIntegral() const { return distance_integral_ == "signed"; }

  std::vector<models::PolynomialSegment> segments_;
  std::vector<double> length_after_m_;  // per segment: arc length of the later segments

  // Parameters.
  double speed_ = 0.3;
  double k_p_distance_ = 7.5;
  double k_i_distance_ = 0.0;
  double k_p_orientation_ = 3.0;
  double k_i_orientation_ = 0.0;
  std::string distance_integral_ = "unsigned";
  double max_distance_integral_rate_ = 0.15;
  double max_orientation_integral_rate_ = 0.15;
  double max_yaw_rate_ = 1.0;
  double deceleration_ = 0.25;
  double stop_tolerance_ = 0.002;

  // Inputs.
  std::vector<double> position_;
  double yaw_measured_ = 0.0;
  // Outputs.
  std::vector<double> velocity_command_;
  double yaw_rate_command_ = 0.0;
  bool done_ = false;
  std::int64_t segment_out_ = 0;
  std::int64_t map_index_ = 0;
  double distance_error_ = 0.0;
  double cross_track_error_ = 0.0;
  double orientation_error_ = 0.0;
  double t_out_ = 0.0;

  // State.
  std::size_t segment_ = 0;
  double distance_integral_value_ = 0.0;     // I_D (m s)
  double orientation_integral_value_ = 0.0;  // I_theta (rad s)
  bool done_latched_ = false;
};

}  // namespace linesim::control
