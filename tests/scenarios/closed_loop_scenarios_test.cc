// The robot on the line with its own sensors (paper 1 Secs. IV and VI):
// the controllers get the surface velocity from the four PX4Flow through
// the surface estimator (Eq. 2, the steady-state Kalman filter, the line
// map) and the pose from the fusion of the wheel odometry (Eq. 3) with
// hector-style matching of both S300 scans. Everything runs through the
// real units; the metrics are measured on the ground truth.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "tests/scenarios/run_scenario.h"

namespace linesim {
namespace {

using test_scenarios::RunSeeds;
using test_scenarios::Shipped;

// Seeds per test: every bound below must hold for each of them (the seed
// draws the belt's speed variation, the PX4Flow's and lasers' noise and
// biases, the IMU's): the spreads quoted are min / median / max over these.
constexpr int kSeeds = 8;

const std::vector<std::string> kClosedLoop = {"sensing.surface_velocity=px4flow",
                                              "localization.source=fused"};

// A shipped scenario with `add` written under its `sensors:` section (the
// faults a test injects), saved beside the test's other files.
std::string WithSensors(const std::string& name, const std::string& add, const std::string& tag) {
  std::ifstream in(Shipped(name));
  std::stringstream text;
  text << in.rdbuf();
  std::string s = text.str();
  const std::string key = "sensors:\n  default: true\n";
  const auto at = s.find(key);
  if (at == std::string::npos) {
    ADD_FAILURE() << name << " has no sensors: {default: true} section";
    return Shipped(name);
  }
  s.insert(at + key.size(), add);
  // One file per test (ctest runs tests in parallel).
  const auto file =
      std::filesystem::temp_directory_path() / ("linesim_" + name + "_" + tag + ".yaml");
  std::ofstream(file) << s;
  return file.string();
}

// Paper 1 Sec. VI-B's bound, met here with the robot's own sensors (the
// paper met it with perfect sensing in Gazebo): crossing the line at
// 0.10 m/s the robot stays within 4 cm of its path. The localization (the
// fusion of odometry and matching against a 0.025 m grid) stays within one
// cell of the truth all the way. The fusion is on odometry alone only before
// the first match: one 40 ms scan and the 5 ms step, 45 ms of 20 s (0.00225).
// Seeds 1..8 (the PX4Flow at its measured noise and px4flow_node's 40 Hz,
// issue 36): max_path_deviation_m 0.0045 / 0.0082 / 0.0114 (20 runs of
// `linesim run --runs 20`: 0.0055 / 0.0077 / 0.0144); localization_error_max_m
// 0.0087 / 0.0106 / 0.0112 (20 runs: 0.0090 / 0.0104 / 0.0122);
// final_progress_m 3.9802 / 3.9808 / 3.9814; pose_fusion_fallback_fraction
// 0.00225 at every seed.
TEST(ClosedLoopScenarios, CrossLineWithItsOwnSensorsStaysWithin4cm) {
  const auto m = RunSeeds(Shipped("cross_line"), kClosedLoop, kSeeds);
  EXPECT_LT(m["max_path_deviation_m"].max(), 0.04);
  EXPECT_GT(m["final_progress_m"].min(), 3.9);
  EXPECT_LT(m["localization_error_max_m"].max(), 0.025);
  EXPECT_LT(m["pose_fusion_fallback_fraction"].max(), 0.01);  // only before the first match
}

// Fallback: both S300 blacked out for 4 s while the robot is on the belt
// (a covered window: no echo at all). The matcher has nothing to match
// (laser_status 2), the fusion runs on odometry alone after its 0.5 s
// timeout (source 1) and returns to matching when the scans come back: the
// share of the run on the fallback is about (4 - 0.5) s / 20 s = 0.175.
// Meanwhile the pose is dead reckoning on a moving floor: its drift over the
// 3.5 s is the error of the odometry's surface velocity (Eq. 3), bounded by
// losing the belt altogether: 0.11 m/s (0.10 m/s + 10 %) x 3.5 s = 0.385 m.
// Once the lasers are back the matches pull the pose in, and the robot ends
// within the paper's 4 cm of its path. The surface velocity is the fused
// estimator's (fused_flow: encoders, IMU and flow, which the blackout leaves
// bounded): paper 1's filter fed by this fusion's velocity (Eq. 2) is not,
// at the PX4Flow's 40 Hz: with the wheels on the belt its input is its own
// estimate plus the fusion's odometry offset, which the blackout freezes,
// and it integrates that offset at K = 0.105 a message, 4.2 /s (issue 36;
// docs/results.md: over these seeds the localization drifted up to 0.52 m
// and one run did not find its map again). Seeds 1..8: localization_error_
// max_m 8.9 / 20.7 / 29.8 mm; final_path_deviation_m at most 0.6 mm;
// pose_fusion_fallback_fraction 0.1812 at every seed.
TEST(ClosedLoopScenarios, LasersBlackedOutTheFusionFallsBackToOdometryAndReturns) {
  const std::string file =
      WithSensors("cross_line",
                  "  laser_front: {parameters: {blackout_from: 5, blackout_until: 9}}\n"
                  "  laser_rear: {parameters: {blackout_from: 5, blackout_until: 9}}\n",
                  "blackout");
  const auto m =
      RunSeeds(file, {"sensing.surface_velocity=fused_flow", "localization.source=fused"}, kSeeds);
  EXPECT_GT(m["pose_fusion_fallback_fraction"].min(), 0.17);
  // At most: the 3.5 s, one scan period (40 ms) and one control period
  // (20 ms) at each edge of the blackout (the scans straddling it and the
  // steps that see them), and the same 60 ms at the start, before the
  // first match: (3.5 + 3 x 0.06) s / 20 s.
  EXPECT_LT(m["pose_fusion_fallback_fraction"].max(), (3.5 + 3 * 0.06) / 20);
  EXPECT_LT(m["localization_error_max_m"].max(), 0.11 * 3.5);
  EXPECT_LT(m["final_path_deviation_m"].max(), 0.04);
}

// Fallback: the light goes out under all four PX4Flow at 4 s, before the
// robot reaches the line (no light on the surface: the firmware matches
// image noise, its quality stays high and its flow reads about zero). The
// encoders' check refuses every message while sensor and wheels share a
// surface (|0 - relative motion| = 0.3 m/s > 0.09 m/s), the sensors go
// held and then stale, and the wheels get no surface velocity: the robot
// crosses as the nominal system does, with the standing error v / k of a
// loop of gain k = 1/s against a belt at v = 0.10 m/s (+10 % variation):
// bounded by 0.11 m, never carried away. Seeds 1..8: max_path_deviation_m
// 0.0913 / 0.0972 / 0.1009 (within 9 % of the analytic 0.11: the belt's
// speed nears its +10 % at some seeds and the loop nears v / k);
// refused_front_left 395 / 398 / 402 (messages at 40 Hz); wheel_source_max
// 3 at every seed; final_progress_m 3.9804 / 3.9811 / 3.9814.
TEST(ClosedLoopScenarios, DarkFlowSensorsAreRefusedAndTheRobotStaysBounded) {
  std::string file =
      WithSensors("cross_line",
                  "  flow_front_left: {parameters: {dark_from: 4, dark_until: 100}}\n"
                  "  flow_rear_left: {parameters: {dark_from: 4, dark_until: 100}}\n"
                  "  flow_rear_right: {parameters: {dark_from: 4, dark_until: 100}}\n"
                  "  flow_front_right: {parameters: {dark_from: 4, dark_until: 100}}\n",
                  "dark");
  std::ofstream(file, std::ios::app)
      << "metrics:\n  - {name: refused_front_left, of: 'surface_estimator.implausible_count[0]', "
         "reduce: final}\n  - {name: wheel_source_max, of: "
         "'surface_estimator.wheel_source[0]', reduce: max}\n";
  const auto m = RunSeeds(file, kClosedLoop, kSeeds);
  EXPECT_GT(m["refused_front_left"].min(), 10.0);
  EXPECT_GE(m["wheel_source_max"].min(), 2.0);  // held, then none
  EXPECT_LT(m["max_path_deviation_m"].max(), 0.11);
  EXPECT_GT(m["final_progress_m"].min(), 3.9);
}

}  // namespace
}  // namespace linesim
