// Paper 1 Sec. VI-A and Fig. 4, end to end: the Rob@Work 3 holds its place
// on a treadmill that starts, runs at 0.20 m/s and stops; its four PX4Flow
// units (real firmware emulation, seeded per unit) against the treadmill's
// encoder wheel.
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "tests/scenarios/run_scenario.h"

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

// Guards Fig. 4's picture as numbers. Expected: the raw flow tracks the
// encoder wheel with an error above zero (a real device is noisy: the
// emulated block matching quantizes to half pixels and adds matching
// noise) and within paper 1's in-house figure for the measurement noise,
// sigma = 3 cm/s (Sec. VI-A); on a lit, textured treadmill every frame is
// valid, so the mean quality is at least 112, the firmware's lowest valid
// quality (11 blocks x 255 / 25). Seeds 1..8 (with the disturbances of
// issue 21: the lab's flicker and roughness, gyro compensation, per-device
// scale): surface_velocity_rmse_raw_mps 0.01024 / 0.01072 / 0.01147;
// optic_flow_quality_mean 252.23 / 252.27 / 252.35.
TEST(OpticFlowScenario, RawFlowTracksTheTreadmillWithinThePapersNoise) {
  const auto& run = Textured();
  const auto& rmse = run["surface_velocity_rmse_raw_mps"];
  EXPECT_GT(rmse.min(), 0.0);
  EXPECT_LT(rmse.max(), 0.03);
  EXPECT_GE(run["optic_flow_quality_mean"].min(), 112.0);
}

// Guards the dependence on the surface (paper 1: "performance ... is
// dependent on the quality of image features present on the surface").
// Expected: on a featureless belt (texture contrast 0) the blocks match
// noise, so the raw flow misses the treadmill by more than paper 1's 3 cm/s
// and the quality drops below a textured belt's. Seeds 1..8, featureless:
// surface_velocity_rmse_raw_mps 0.1491 / 0.1498 / 0.1502;
// optic_flow_quality_mean 151.2 / 151.7 / 152.2 (textured: 252.23 and up).
TEST(OpticFlowScenario, AFeaturelessBeltDefeatsTheSensor) {
  const auto& textured = Textured();
  const auto bare = RunProfile({"scene.surfaces.1.texture_contrast=0"});
  EXPECT_GT(bare["surface_velocity_rmse_raw_mps"].min(), 0.03);
  EXPECT_LT(bare["optic_flow_quality_mean"].max(), textured["optic_flow_quality_mean"].min());
}

// Guards the filtered estimate the robot holds with (paper 1 Sec. IV-A).
// Expected: its error against the encoder wheel within paper 1's in-house
// measurement sigma, 3 cm/s (the filter's lag over the 1 s ramps is most
// of it, see the note below); and the hold: the treadmill reaches 0.2 m/s
// in 1 s and the state-switch detector restarts the filter at the 7th
// message of that ramp (a 0.7 s lag, units/estimation tests), so the belt
// carries the robot at most about half the speed for that long before the
// compensation has it: 0.1 m/s x 0.7 s = 0.07 m.
// Not asserted, because it does not hold: a filtered RMSE a third of the
// raw. The raw error here (about 1 cm/s) is not white noise a low-pass
// filter removes but the firmware's half-pixel quantization bias and the
// Eq. 2 window; the filter can only add its lag to it.
// Seeds 1..8: surface_velocity_rmse_filtered_mps 0.02561 / 0.02585 /
// 0.02619: within 15 % of paper 1's 3 cm/s (the filter's lag over the
// ramps, nearly the same at every seed); max_position_drift_m 0.0471 /
// 0.0480 / 0.0483.
TEST(OpticFlowScenario, TheRobotHoldsOnTheTreadmillWithItsFilteredFlow) {
  const auto& run = Textured();
  EXPECT_LT(run["surface_velocity_rmse_filtered_mps"].max(), 0.03);
  EXPECT_LT(run["max_position_drift_m"].max(), 0.07);
}


// Guards the settling after each switch (issue 21 item 2). Expected, from
// paper 1's gain (K = 0.105) and the switch detector (units/estimation):
// the 1 s ramp of 0.02 m/s per message restarts the filter at its 7th
// message, the last 3 leave a lag of 0.02 (1 - 0.895^3) / 0.105 = 5.4 cm/s,
// which decays by 0.895 per message. Every sensor is within 2 cm/s of the
// truth once the lag is under 2 cm/s less its own scale bias; at 3 sigma
// of scale_error (3 x 2.5 % x 0.2 m/s = 1.5 cm/s) that is 0.5 cm/s, after
// ln(0.005 / 0.054) / ln(0.895) = 21 messages: 1 s + 2.1 s, plus one
// message for the detector's restart moving with the noise: 3.2 s.
// Not asserted, because it does not hold: the plateaus' filtered RMSE a
// third of the raw; what is left on them is the per-device scale (a bias)
// and the half-pixel quantization, not white noise (docs/results.md).
// Seeds 1..8: surface_velocity_settling_time_s 1.795 / 2.015 / 2.455;
// plateau RMSE raw 3.2 / 4.5 / 6.5 mm/s, filtered 4.5 / 5.7 / 7.2 mm/s.
TEST(OpticFlowScenario, TheFilteredEstimateSettlesAfterEachSwitch) {
  const auto& run = Textured();
  EXPECT_LT(run["surface_velocity_settling_time_s"].max(), 3.2);
  EXPECT_GT(run["surface_velocity_settling_time_s"].min(), 1.0);  // not before the ramp's end
}

}  // namespace
}  // namespace linesim
