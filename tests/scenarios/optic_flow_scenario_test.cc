// Paper 1 Sec. VI-A and Fig. 4, end to end: the Rob@Work 3 holds its place
// on a treadmill that starts, runs at 0.20 m/s and stops; its four PX4Flow
// units (real firmware emulation, seeded per unit) against the treadmill's
// encoder wheel.
#include <gtest/gtest.h>

#include <map>
#include <string>
#include <vector>

#include "cosim/observers.h"
#include "loader/scenario.h"

namespace linesim {
namespace {

struct ProfileRun {
  std::map<std::string, double> metrics;
};

ProfileRun RunProfile(std::vector<std::string> sets) {
  loader::Scenario s =
      loader::LoadScenario(LINESIM_SOURCE_DIR "/scenarios/optic_flow_profile.yaml", sets);
  cosim::MetricsObserver metrics(s.metrics);
  s.master->AddObserver(&metrics);
  const cosim::RunResult result = s.master->Run();
  EXPECT_TRUE(result.ok) << result.ErrorText();
  ProfileRun run;
  for (const auto& [metric, value] : metrics.Results()) run.metrics[metric] = value;
  return run;
}

// Guards Fig. 4's picture as numbers. Expected: the raw flow tracks the
// encoder wheel with an error above zero (a real device is noisy: the
// emulated block matching quantizes to half pixels and adds matching
// noise) and within paper 1's in-house figure for the measurement noise,
// sigma = 3 cm/s (Sec. VI-A); on a lit, textured treadmill every frame is
// valid, so the mean quality is at least 112, the firmware's lowest valid
// quality (11 blocks x 255 / 25).
TEST(OpticFlowScenario, RawFlowTracksTheTreadmillWithinThePapersNoise) {
  const ProfileRun run = RunProfile({});
  const double rmse = run.metrics.at("surface_velocity_rmse_raw_mps");
  EXPECT_GT(rmse, 0.0);
  EXPECT_LT(rmse, 0.03);
  EXPECT_GE(run.metrics.at("optic_flow_quality_mean"), 112.0);
}

// Guards the dependence on the surface (paper 1: "performance ... is
// dependent on the quality of image features present on the surface").
// Expected: on a featureless belt (texture contrast 0) the blocks match
// noise, so the raw flow misses the treadmill by more than paper 1's 3 cm/s
// and the quality drops below a textured belt's.
TEST(OpticFlowScenario, AFeaturelessBeltDefeatsTheSensor) {
  const ProfileRun textured = RunProfile({});
  const ProfileRun bare = RunProfile({"scene.surfaces.1.texture_contrast=0"});
  EXPECT_GT(bare.metrics.at("surface_velocity_rmse_raw_mps"), 0.03);
  EXPECT_LT(bare.metrics.at("optic_flow_quality_mean"),
            textured.metrics.at("optic_flow_quality_mean"));
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
TEST(OpticFlowScenario, TheRobotHoldsOnTheTreadmillWithItsFilteredFlow) {
  const ProfileRun run = RunProfile({});
  EXPECT_LT(run.metrics.at("surface_velocity_rmse_filtered_mps"), 0.03);
  EXPECT_LT(run.metrics.at("max_position_drift_m"), 0.07);
}

}  // namespace
}  // namespace linesim
