#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"

namespace linesim::evaluation {

/// Ground-truth distance of a robot's body from the other robots' bodies in
/// a fleet, and robot-robot contacts counted as collisions, per pair.
///
/// Each body is its chassis' `body_box` (models::MovingBox: a box yawed
/// about the vertical, with the heights it spans), all of the fleet's in
/// `bodies` (world::MovingBodiesUnit's), this robot's at index `own`. Two
/// boxes whose height
/// ranges overlap are at the distance of their footprint rectangles (0 when
/// the rectangles overlap: separating axes; otherwise, for two disjoint
/// convex polygons, the smallest distance of a corner of one from the
/// other); boxes with no height in common are not compared. Two bodies are
/// in contact closer than `contact_distance` (default 5 mm): each robot's
/// chassis meets the other's body as it was at the last communication point
/// moved on at its velocity, so two bodies pushing each other keep a gap of
/// up to their relative speed times the master step (1 m/s x 5 ms; 0.65 mm
/// measured for a 0.5 m/s push at 5 ms, where the footprints never touch).
/// A collision is one contact event (in contact now, not at the previous step), counted
/// per robot of `bodies` (`robot_collisions`: the pair this robot - robot k;
/// its own entry stays 0) and
/// in all (`collisions`). Each of the pair's units counts it, once each.
class RobotClearanceUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "robot_clearance";

  /// `bodies` robots in the fleet (at least 2).
  RobotClearanceUnit(std::string name, int bodies);

  void Initialize() override;
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

  /// Distance between the footprints of two models::MovingBox values (0
  /// when they overlap).
  static double FootprintDistance(const double* a, const double* b);

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  void Evaluate();

  int bodies_;
  double contact_distance_ = 0.005;
  std::int64_t own_ = 0;
  // Inputs.
  std::vector<double> boxes_;
  // Outputs.
  double distance_ = 0.0, min_distance_ = 0.0, nearest_ = -1.0, collisions_ = 0.0;
  std::vector<double> robot_distance_, robot_collisions_;
  // State: per robot, in contact at the last step.
  std::vector<std::uint8_t> contact_before_;
};

}  // namespace linesim::evaluation
