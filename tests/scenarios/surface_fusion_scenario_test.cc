// The robot on the line with its own sensors and the fused surface sensing
// (sensing.surface_velocity: fused_flow, units/estimation/surface_fusion_unit.h):
// paper 1's future work (Sec. VI-D), the belt's velocity from the laser
// localization's position against the wheel encoders' dead reckoning and
// from the PX4Flow. Everything runs through the real units; the metrics are
// measured on the ground truth.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/scenarios/run_scenario.h"

namespace linesim {
namespace {

using test_scenarios::RunSeeds;
using test_scenarios::Shipped;

// Seeds per test: every bound below must hold for each of them (the seed
// draws the belt's speed variation and the sensors' noise and biases); the
// spreads quoted are min / median / max over these.
constexpr int kSeeds = 8;

const std::vector<std::string> kOwnSensors = {"sensing.surface_velocity=fused_flow",
                                              "localization.source=fused"};

// Paper 1 Sec. VI-B's bound: crossing the line at 0.10 m/s the robot stays
// within 4 cm of its path (the paper: with perfect sensing in Gazebo). The
// corner PX4Flow see the belt before the wheels reach it, with the encoders
// of the wheels still on the floor as the robot's motion (the flow
// measurement's H = I): the estimate is ready when the wheels arrive.
// max_path_deviation_m with the IMU fused and the PX4Flow at its measured
// noise (issue 36), 20 runs (--runs 20): 4.1 / 5.2 / 6.0 mm; seeds 1..8:
// 4.2 / 4.5 / 6.3 mm (before issue 36, 20 runs: 5.2 / 5.8 / 6.5 mm; without
// the IMU: 5.6 / 7.9 / 18.0 mm); final_progress_m above 3.9 at every seed.
TEST(SurfaceFusionScenarios, CrossLineStaysWithin4cm) {
  const auto m = RunSeeds(Shipped("cross_line"), kOwnSensors, kSeeds);
  EXPECT_LT(m["max_path_deviation_m"].max(), 0.04);
  EXPECT_GT(m["final_progress_m"].min(), 3.9);
}

// Position hold on the line while it switches on and off at 0.20 m/s:
// paper 1's 4 cm on every peak at the switches and the 1 cm on the
// final deviation (the line steady again for 9 s at the end of the run).
// With the IMU fused and the wheel controller's steering threshold (no
// wheel re-aimed on noise-level commands, left across the belt when it
// starts), with the PX4Flow at its measured noise (issue 36), 20 runs
// (--runs 20): peak 11.2 / 12.1 / 22.4 mm, final 0.1 / 1.0 / 1.8 mm; seeds
// 1..8: peak 11.2 / 13.0 / 20.6 mm, final 0.4 / 1.0 / 1.8 mm. (Before issue
// 36: 20 runs peak 11.5 / 12.2 / 22.4 mm, 40 more at most 21.2 mm, final at
// most 2.0 mm; before the threshold one run of 20 peaked at 62 mm; without
// the IMU, 8 of 20 over 4 cm.)
TEST(SurfaceFusionScenarios, HoldOnBeltHoldsWithin4cmAndEndsWithin1cm) {
  const auto m = RunSeeds(Shipped("hold_on_belt"), kOwnSensors, kSeeds);
  EXPECT_LT(m["final_position_drift_m"].max(), 0.01);
  EXPECT_LT(m["max_position_drift_m"].max(), 0.04);
}

// Straddling the line's edge (two wheels on the belt, two on the floor:
// the robot turns as well): the same bounds. With the PX4Flow at its
// measured noise (issue 36), 20 runs: peak 12.0 / 21.7 / 30.7 mm, final
// 0.5 / 1.9 / 3.5 mm; seeds 1..8: peak 17.6 / 21.5 / 31.9 mm, final 1.3 /
// 2.1 / 4.1 mm. (Before issue 36: 20 runs peak 12.5 / 22.4 / 34.0 mm; 40
// more: peak at most 36.5 mm, the estimate's lag behind the belt's 1 s
// ramp with the wheels aligned in time, final at most 6.7 mm; before the
// threshold 2 of 20 peaked over 4 cm, at 44 and 48 mm.)
TEST(SurfaceFusionScenarios, HoldStraddleHoldsWithin4cmAndEndsWithin1cm) {
  const auto m = RunSeeds(Shipped("hold_straddle"), kOwnSensors, kSeeds);
  EXPECT_LT(m["final_position_drift_m"].max(), 0.01);
  EXPECT_LT(m["max_position_drift_m"].max(), 0.04);
}

}  // namespace
}  // namespace linesim
