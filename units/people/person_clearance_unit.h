#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"

namespace linesim::people {

/// Ground-truth distance of the robot's body from the workers, and
/// robot-person contacts counted as collisions.
///
/// The body is the clearance unit's box (body_length x body_width, centred
/// on base_link, heights [body_z_min, body_z_max] above the floor); each
/// worker is WorkerUnit's three vertical cylinders (`cylinders`: legs and
/// torso, 7 numbers each). A cylinder whose height range overlaps the
/// body's is at the distance of its axis from the body's footprint
/// rectangle (yawed with the robot) less its radius, 0 when they overlap
/// (closed form: no FCL needed for a circle and a rectangle); the others
/// are ignored (a torso above a low base). A worker is in contact when any
/// of its cylinders is at distance 0; a collision is one contact event (in
/// contact now, not at the previous step), counted per worker
/// (`worker_collisions`: the pair robot - worker k), and timed
/// (`contact_time`: the steps that end in contact, summed).
///
/// Contact with a person is not modelled: nothing pushes either (the
/// chassis does not collide with the workers' cylinders, the worker walks
/// its plan), so the body passes through the person. Each contact event is
/// therefore also a warning of the run (cosim::Unit::Warn), naming the
/// worker: what follows it is not what a real contact would give.
class PersonClearanceUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "person_clearance";
  static constexpr int kCylindersPerWorker = 3;
  static constexpr int kCylinderValues = 7;

  /// `names`: the workers' names for the warnings (empty: "worker k").
  PersonClearanceUnit(std::string name, int workers, std::vector<std::string> names = {});

  void Setup(cosim::TimeNs start, cosim::TimeNs stop) override {
    (void)stop;
    start_ = start;
  }
  void Initialize() override;
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

  /// Distance from (x, y) to the rectangle of half sizes (hx, hy) centred
  /// at the origin of its own axes (0 inside).
  static double DistanceToRectangle(double x, double y, double hx, double hy);

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  void Evaluate(bool commit, cosim::TimeNs t, cosim::TimeNs dt);

  int workers_;
  std::vector<std::string> names_;
  cosim::TimeNs start_ = 0;
  // Parameters (the clearance unit's body; the assembly sets them from the
  // robot file).
  double body_length_, body_width_, body_z_min_ = 0.0, body_z_max_ = 0.5;
  // Inputs.
  std::vector<double> position_3d_ = std::vector<double>(3, 0.0);
  std::vector<double> orientation_ = {1.0, 0.0, 0.0, 0.0};
  std::vector<double> cylinders_;
  // Outputs.
  double distance_ = 0.0, min_distance_ = 0.0, nearest_ = -1.0, collisions_ = 0.0,
         contact_time_ = 0.0;
  std::vector<double> worker_distance_, worker_collisions_, worker_contact_time_;
  // State: per worker, in contact at the last step.
  std::vector<std::uint8_t> contact_before_;
};

}  // namespace linesim::people
