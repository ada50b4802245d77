#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"

namespace linesim::sensors {

/// The belt's ground-truth speed sensor of paper 1 (Sec. V, "True Surface
/// Velocity"): a free wheel rolling on the moving floor, mounted off the
/// robot, turning a quadrature encoder that a microcontroller (an Arduino in
/// the paper) reads once per sample. Connect `travel` to the belt unit's
/// travel[k].
///
/// At each sample (the unit step; direct feedthrough from `travel`):
///   position = travel / wheel_radius * counts_per_revolution / (2 pi)
///   counts   = IncrementalCount(previous counts, position, hysteresis)
///            (floor(position) for hysteresis 0; see wheel_encoder_unit.h)
///   speed    = (counts - counts m samples ago) * 2 pi wheel_radius
///              / counts_per_revolution / (time since that sample),
///   m = min(average_window, samples so far): the count difference over one
/// sample interval as the microcontroller computes it (average_window 1), or
/// its moving average over the last average_window intervals. The wheel
/// rolls without slip on the belt (no slip model). The first sample reads
/// speed 0. DoStep(t, dt) commits the sample taken at t by UpdateOutputs
/// (or Initialize), whatever input it is given since.
class BeltEncoderUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "belt_encoder";

  explicit BeltEncoderUnit(std::string name);

  void Setup(cosim::TimeNs start, cosim::TimeNs stop) override;
  void Initialize() override;
  void UpdateOutputs() override;
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  double Position() const;

  // Parameters.
  double wheel_radius_;
  double counts_per_revolution_;
  double hysteresis_ = 0.0;
  std::int64_t average_window_ = 1;
  // Input and outputs.
  double travel_ = 0.0;
  double counts_ = 0.0;
  double speed_ = 0.0;
  // State: the counter after the last committed sample, the time of the
  // coming sample, and a ring of the last average_window committed samples
  // (count and time; `ring_size_` of them valid, the oldest at ring_head_).
  std::int64_t count_ = 0;
  cosim::TimeNs start_ = 0;
  cosim::TimeNs sample_time_ = 0;
  std::vector<std::int64_t> ring_counts_;
  std::vector<cosim::TimeNs> ring_times_;
  std::size_t ring_head_ = 0;
  std::size_t ring_size_ = 0;
};

}  // namespace linesim::sensors
