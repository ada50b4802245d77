#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cosim/unit.h"

namespace linesim::evaluation {

/// How far a localization's estimate is from the truth: the distance
/// between the estimated and the true position of base_link and the
/// wrapped yaw difference at every communication point, with their maxima
/// and root mean squares over the run (the table issue 11 asks for: the
/// localization error beside each closed-loop result).
///
/// With a region (region_length > 0: a rectangle in map, centre region_x,
/// region_y, its length along region_yaw), the statistics count only the
/// points where the TRUE position lies inside it: the error while the robot
/// is on a ramp, say (the loader's localization_error_on_<piece>).
class PoseErrorUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "pose_error";

  explicit PoseErrorUnit(std::string name);

  void Initialize() override;
  /// The current errors follow the inputs; the statistics move on in DoStep.
  void UpdateOutputs() override { Evaluate(); }
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  void Evaluate();

  // Inputs.
  std::vector<double> true_position_ = std::vector<double>(2, 0.0);
  std::vector<double> estimated_position_ = std::vector<double>(2, 0.0);
  double true_yaw_ = 0.0, estimated_yaw_ = 0.0;
  // Parameters: the region (length 0: none, every point counts).
  double region_x_ = 0.0, region_y_ = 0.0, region_yaw_ = 0.0, region_length_ = 0.0,
         region_width_ = 0.0;
  // Outputs.
  double position_error_ = 0.0, yaw_error_ = 0.0;
  double max_position_error_ = 0.0, rms_position_error_ = 0.0;
  double max_yaw_error_ = 0.0, rms_yaw_error_ = 0.0;
  double samples_out_ = 0.0;
  // Sums of squares and the number of samples in them.
  double sum_squared_position_ = 0.0, sum_squared_yaw_ = 0.0;
  std::int64_t samples_ = 0;
};

}  // namespace linesim::evaluation
