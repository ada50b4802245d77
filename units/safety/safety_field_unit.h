#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"

namespace linesim::safety {

/// The S300's field evaluation and the robot's safety function, between the
/// path follower and the wheel controller (SICK S300 operating instructions
/// 8010948: field sets of a protective and a warning field, switched as
/// monitoring cases by the vehicle's speed; multiple sampling; the OSSDs).
///
/// Fields: each field set holds a protective polygon and optionally a
/// warning polygon ([x, y] corners in the scanner frame, m) and the top
/// speed it is for; the active set is the first whose max_speed is at least
/// the speed the unit last commanded (the S300 switches monitoring cases by
/// the speed of its incremental encoder inputs), else the last one. At each
/// new scan (scan_count changes) every returning beam's point (r cos a_i,
/// r sin a_i), a_i = first_beam_angle + i angular_step, is tested against
/// the active set's polygons. A field counts as infringed after
/// multiple_sampling consecutive infringing scans (at least 2: with the
/// S300's 40 ms scan, its 80 ms basic response time), clear after one scan
/// without (no restart interlock: the OSSDs switch on again; the resume is
/// delayed here instead, as the vehicle controller of a mobile application
/// does).
///
/// Safety function, on the speed cap c (m/s; infinite: no limit):
///   protective infringed -> c falls to 0 at braking_deceleration (a safe
///     stop from the speed last commanded; protective_stops counts them,
///     an infringement before the last stop's restart delay has run out
///     extends that stop);
///   warning infringed    -> c falls to warning_speed at braking_deceleration;
///   both clear for restart_delay -> c rises at resume_acceleration, and is
///     lifted once it reaches the command.
/// task_time: when the task's done input first rose (s after the start;
/// -1 before): what the stops cost the task.
/// Outputs: the commands scaled by min(1, c / |v|) (the direction kept; the
/// yaw rate scaled alike; both 0 when c = 0), computed from the current
/// inputs at each communication point (feedthrough: no added delay).
class SafetyFieldUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "safety_field";

  struct FieldSet {
    double max_speed_mps = 0.0;
    std::vector<std::array<double, 2>> protective, warning;  // warning may be empty
  };

  /// At least one field set, each with a protective polygon and a warning
  /// polygon (or none) that are simple polygons (models::PolygonProblem:
  /// no zero area, no crossing edges). Throws cosim::UnitError otherwise.
  SafetyFieldUnit(std::string name, int beam_count, std::vector<FieldSet> field_sets);

  std::vector<cosim::ParameterProblem> CheckParameters() const override;
  void Setup(cosim::TimeNs start, cosim::TimeNs stop) override {
    (void)stop;
    start_ = start;
  }
  void Initialize() override;
  void UpdateOutputs() override;
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

  /// Whether (x, y) (scanner frame) lies inside the polygon.
  static bool Inside(const std::vector<std::array<double, 2>>& polygon, double x, double y);

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  void EvaluateScan();
  cosim::TimeNs start_ = 0;
  std::size_t ActiveSet() const;

  int beam_count_;
  std::vector<FieldSet> sets_;

  // Parameters. The S300's beam geometry (models/sensors/sick_s300.yaml).
  double first_beam_angle_ = -2.356194490192345, angular_step_ = 0.008726646259971648,
         no_return_value_ = 0.0;
  std::int64_t multiple_sampling_ = 2;
  double braking_deceleration_ = 1.0, warning_speed_ = 0.3, restart_delay_ = 2.0,
         resume_acceleration_ = 0.5;

  // Inputs.
  std::vector<double> ranges_, velocity_command_;
  double scan_count_ = 0.0, yaw_rate_command_ = 0.0;
  bool task_done_ = false;
  // Outputs.
  std::vector<double> velocity_out_;
  double yaw_rate_out_ = 0.0, protective_clear_ = 1.0, warning_clear_ = 1.0, field_set_ = 0.0,
         speed_cap_out_ = -1.0, protective_stops_ = 0.0, time_stopped_ = 0.0, task_time_ = -1.0;

  // State.
  double last_scan_count_ = 0.0;
  // Consecutive infringing scans.
  std::int64_t protective_scans_ = 0, warning_scans_ = 0;
  // The speed cap, and the cap held since the last infringement (+inf: no
  // limit, none).
  double cap_ = 0.0, target_ = 0.0;
  cosim::TimeNs clear_for_ = 0;  // time both fields have been clear
  double last_speed_ = 0.0;      // |velocity_out| last commanded
};

}  // namespace linesim::safety
