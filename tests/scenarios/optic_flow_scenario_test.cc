// Paper 1 Sec. VI-A and Fig. 4, end to end: the Rob@Work 3 holds its place
// on a treadmill that starts, runs at 0.20 m/s and stops; its four PX4Flow
// units (real firmware emulation, seeded per unit) against the treadmill's
// encoder wheel.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include "tests/scenarios/run_scenario.h"
#include "tests/spread.h"

namespace linesim {
namespace {

// Seeds per test: every bound below must hold for each (the seed draws the
// PX4Flow's textures and noise and the treadmill's speed variation); the
// spreads quoted are min / median / max over them.
constexpr int kSeeds = 8;

test_scenarios::SeedRuns RunProfile(std::vector<std::string> sets) {
  return test_scenarios::RunSeeds(test_scenarios::Shipped("optic_flow_profile"), std::move(sets),
                                  kSeeds);
}

// The shipped (textured) profile's runs, made once for the tests below.
const test_scenarios::SeedRuns& Textured() {
  static const test_scenarios::SeedRuns runs = RunProfile({});
  return runs;
}

// Guards the device's noise on the treadmill's plateaus at 0.2 m/s
// (issue 36: sigma 20-30 mm/s, from paper 1's 3 cm/s "based on in-house
// tests" and PX4's EKF2_OF_N_MIN 0.15 rad/s x 0.1841 m = 27.6 mm/s).
// Expected: the line-on plateau's raw RMSE within 20-30 mm/s, where the
// unexplained residual's calibration puts it (models/sensors/px4flow.yaml:
// the quadrature difference between 27.6 mm/s and the mechanisms' 8.5
// mm/s, the median of 20 runs); with the residual off, what the modelled
// mechanisms give alone, above 0 and under 15 mm/s (their 20-run maximum
// 11.2 mm/s: two thirds per-device scale, the rest flicker, the half-pixel
// grid); on a lit, textured treadmill every frame is valid, so the mean
// quality is at least 112, the firmware's lowest valid quality (11 blocks
// x 255 / 25). Seeds 1..8: surface_velocity_on_rmse_raw_mps 26.8 / 27.7 / 29.3 mm/s;
// residual off 6.5 / 7.8 / 9.3 mm/s; optic_flow_quality_mean 254.2 / 254.3 / 254.3.
TEST(OpticFlowScenario, RawFlowHasTheDevicesMeasuredNoise) {
  const auto& run = Textured();
  const auto& on = run["surface_velocity_on_rmse_raw_mps"];
  EXPECT_GT(on.min(), 0.020);
  EXPECT_LT(on.max(), 0.030);
  EXPECT_GE(run["optic_flow_quality_mean"].min(), 112.0);
  std::vector<std::string> off;
  for (const char* s :
       {"flow_front_left", "flow_rear_left", "flow_rear_right", "flow_front_right"}) {
    off.push_back(std::string("sensors.") + s + ".parameters.residual=false");
  }
  const auto mechanisms = RunProfile(off);
  EXPECT_GT(mechanisms["surface_velocity_on_rmse_raw_mps"].min(), 0.0);
  EXPECT_LT(mechanisms["surface_velocity_on_rmse_raw_mps"].max(), 0.015);
}

// Guards the dependence on the surface (paper 1: "performance ... is
// dependent on the quality of image features present on the surface").
// Expected: on a featureless belt (texture contrast 0) the blocks match
// noise, so the raw flow misses the treadmill by more than paper 1's 3 cm/s
// and the quality drops below a textured belt's. Seeds 1..8, featureless:
// surface_velocity_rmse_raw_mps 0.1314 / 0.1322 / 0.1336 (textured: 0.0267
// / 0.0272 / 0.0280); optic_flow_quality_mean 152.1 / 152.6 / 152.8
// (textured: 254.2 and up).
TEST(OpticFlowScenario, AFeaturelessBeltDefeatsTheSensor) {
  const auto& textured = Textured();
  const auto bare = RunProfile({"scene.surfaces.1.texture_contrast=0"});
  EXPECT_GT(bare["surface_velocity_rmse_raw_mps"].min(), 0.03);
  EXPECT_LT(bare["optic_flow_quality_mean"].max(), textured["optic_flow_quality_mean"].min());
}

// Guards the filtered estimate the robot holds with (paper 1 Sec. IV-A) and
// Fig. 4's run ending settled (issue 36 item 4). The treadmill reaches 0.2
// m/s in 1 s, 0.005 m/s per 40 Hz message; paper 1's fixed gain (K =
// 0.105) lags a ramp of slope a by a (1 - K) / K = 0.043 m/s, under the
// switch detector's gate (0.079 m/s: no restart), and the belt carries the
// robot by that lag's area, 0.043 x 1 s / 2 over the ramp + 0.043 x 0.22 s
// (the filter's time constant, 0.025 / 0.111) after it: 31 mm; the same,
// the other way, at the stop. Expected: the filtered estimate's error
// within paper 1's 3 cm/s over the run; the drift under 5 cm (the lag's
// 31 mm plus the filtered noise's wander); and at the end, 6 s after the
// stop, under 1 cm: the filter settled about 1.2 s after the stop and the
// hold law (about 0.7 /s here) took the robot back (ending 2 s after the
// stop, as the run did, left 13-19 mm). Seeds 1..8:
// surface_velocity_rmse_filtered_mps 12.6 / 13.3 / 14.4 mm/s; max_position_drift_m
// 29.6 / 33.1 / 35.9 mm; final_position_drift_m 0.5 / 1.1 / 3.4 mm.
TEST(OpticFlowScenario, TheRobotHoldsOnTheTreadmillWithItsFilteredFlow) {
  const auto& run = Textured();
  EXPECT_LT(run["surface_velocity_rmse_filtered_mps"].max(), 0.03);
  EXPECT_LT(run["max_position_drift_m"].max(), 0.05);
  EXPECT_LT(run["final_position_drift_m"].max(), 0.01);
}

// Guards the settling after each switch (issue 21 item 2). Expected, from
// the lag above: after the ramp's end the belt's estimate (the mean of the
// four sensors) is 0.043 m/s off and decays by 0.895 per message; it is
// within 2 cm/s for good once the lag is under 2 cm/s less 3 standard
// deviations of that mean's scale bias (2.5 % / 2 x 0.2 m/s: 0.75 cm/s)
// and of its white part (0.235 x 26.3 mm/s / 2: 0.93 cm/s), 0.32 cm/s,
// after ln(0.0032 / 0.043) / ln(0.895) = 23 messages, 0.59 s: measured
// from the switch's start (the reference 1 cm/s into the ramp, 0.05 s),
// 0.95 s + 0.59 s = 1.54 s at most, and not before the ramp's end.
// Seeds 1..8: surface_velocity_settling_time_s 1.075 / 1.095 / 1.175 s.
TEST(OpticFlowScenario, TheFilteredEstimateSettlesAfterEachSwitch) {
  const auto& run = Textured();
  EXPECT_LT(run["surface_velocity_settling_time_s"].max(), 1.54);
  EXPECT_GT(run["surface_velocity_settling_time_s"].min(), 0.95);
}

// Guards paper 1's filter against the device's noise (issue 36: on the
// plateaus at most a third of the raw). Expected: its gain passes white
// noise x sqrt(K / (2 - K)) = 0.235, and the raw plateau error is mostly
// white (the residual, 26.3 mm/s); the per-device scale (2.5 %, 5 mm/s on
// the line-on plateau, half the plateau samples) is a bias it keeps: with
// the scale's RMS over the four sensors at 2 sigma, filtered / raw =
// sqrt(0.0554 x 26.3^2 + 10^2 / 2) / sqrt(26.3^2 + 10^2 / 2) = 0.29, at 3
// sigma 0.35. Asserted: each seed under 0.36 and the median at most a
// third. Seeds 1..8: filtered / raw on the plateaus 0.256 / 0.287 / 0.299.
TEST(OpticFlowScenario, PaperOnesFilterTakesTwoThirdsOffThePlateaus) {
  const auto& run = Textured();
  const auto& raw = run["surface_velocity_plateau_rmse_raw_mps"];
  const auto& filtered = run["surface_velocity_plateau_rmse_filtered_mps"];
  std::vector<double> ratio;
  for (std::size_t i = 0; i < raw.values.size(); ++i) {
    ratio.push_back(filtered.values[i] / raw.values[i]);
    EXPECT_LT(ratio.back(), 0.36) << i;
  }
  // The median over however many seeds ran (the sanitizer build runs
  // fewer: run_scenario.h).
  ASSERT_FALSE(ratio.empty());
  std::sort(ratio.begin(), ratio.end());
  const std::size_t n = ratio.size();
  const double median = n % 2 == 1 ? ratio[n / 2] : 0.5 * (ratio[n / 2 - 1] + ratio[n / 2]);
  EXPECT_LE(median, 1.0 / 3.0);
  test_spread::Print("plateau filtered / raw", ratio);
}

}  // namespace
}  // namespace linesim
