#pragma once

#include <string>
#include <vector>

#include "cosim/unit.h"

namespace linesim::world {

/// The moving bodies of a scene in one array: a fleet's robots' bodies
/// (each chassis' `body_box`, models::MovingBox values) gathered into
/// `bodies`, which every unit that meets them (each robot's chassis, lasers
/// and robot clearance) reads whole, skipping its own robot's box by index
/// (their `own_box`).
///
/// Why a unit: without it each of those units would take the N - 1 others'
/// boxes element by element, 10 (N - 1) connections each, O(N^2) element
/// transfers per step (at 10 robots 3,700 of them, 14 % of the run in the
/// master); through it, 10 N element connections in and one whole-array
/// connection per reader (a memcmp and a copy).
///
/// Direct feedthrough: `bodies` out is `bodies` in at the same
/// communication point (UpdateOutputs), so a reader stepped after it sees
/// where the bodies are now.
class MovingBodiesUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "moving_bodies";

  /// `count` bodies (at least 1).
  MovingBodiesUnit(std::string name, int count);

  void Initialize() override { UpdateOutputs(); }
  void UpdateOutputs() override { out_ = in_; }
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

 private:
  std::vector<double> in_, out_;
};

}  // namespace linesim::world
