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

using test_scenarios::RunFile;
using test_scenarios::Shipped;

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
// cell of the truth all the way.
TEST(ClosedLoopScenarios, CrossLineWithItsOwnSensorsStaysWithin4cm) {
  const auto m = RunFile(Shipped("cross_line"), kClosedLoop);
  EXPECT_LT(m.at("max_path_deviation_m"), 0.04);
  EXPECT_GT(m.at("final_progress_m"), 3.9);
  EXPECT_LT(m.at("localization_error_max_m"), 0.025);
  EXPECT_LT(m.at("pose_fusion_fallback_fraction"), 0.01);  // only before the first match
}

// Fallback: both S300 blacked out for 4 s while the robot is on the belt
// (a covered window: no echo at all). The matcher has nothing to match
// (laser_status 2), the fusion runs on odometry alone after its 0.5 s
// timeout (source 1) and returns to matching when the scans come back: the
// share of the run on the fallback is about (4 - 0.5) s / 20 s = 0.175.
// Meanwhile the pose is dead reckoning on a moving floor: its drift over the
// 3.5 s is the error of the fusion's belt-velocity state, bounded by losing
// the belt altogether: 0.11 m/s (0.10 m/s + 10 %) x 3.5 s = 0.385 m; over 8
// seeds it drifted 8.6 to 57.8 mm (localization) and the path deviated 5.6 to
// 55.8 mm, beyond paper 1's 4 cm, which it sets for a robot that sees. Once
// the lasers are back the matches pull the pose in, and the robot ends
// within the paper's 4 cm of its path.
TEST(ClosedLoopScenarios, LasersBlackedOutTheFusionFallsBackToOdometryAndReturns) {
  const std::string file =
      WithSensors("cross_line",
                  "  laser_front: {parameters: {blackout_from: 5, blackout_until: 9}}\n"
                  "  laser_rear: {parameters: {blackout_from: 5, blackout_until: 9}}\n",
                  "blackout");
  const auto m = RunFile(file, kClosedLoop);
  EXPECT_GT(m.at("pose_fusion_fallback_fraction"), 0.17);
  // At most: the 3.5 s, one scan period (40 ms) and one control period
  // (20 ms) at each edge of the blackout (the scans straddling it and the
  // steps that see them), and the same 60 ms at the start, before the
  // first match: (3.5 + 3 x 0.06) s / 20 s.
  EXPECT_LT(m.at("pose_fusion_fallback_fraction"), (3.5 + 3 * 0.06) / 20);
  EXPECT_LT(m.at("localization_error_max_m"), 0.11 * 3.5);
  EXPECT_LT(m.at("final_path_deviation_m"), 0.04);
}

// Fallback: the light goes out under all four PX4Flow at 4 s, before the
// robot reaches the line (no light on the surface: the firmware matches
// image noise, its quality stays high and its flow reads about zero). The
// encoders' check refuses every message while sensor and wheels share a
// surface (|0 - relative motion| = 0.3 m/s > 0.09 m/s), the sensors go
// held and then stale, and the wheels get no surface velocity: the robot
// crosses as the nominal system does, with the standing error v / k of a
// loop of gain k = 1/s against a belt at v = 0.10 m/s (+10 % variation):
// bounded by 0.11 m, never carried away.
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
  const auto m = RunFile(file, kClosedLoop);
  EXPECT_GT(m.at("refused_front_left"), 10.0);
  EXPECT_GE(m.at("wheel_source_max"), 2.0);  // held, then none
  EXPECT_LT(m.at("max_path_deviation_m"), 0.11);
  EXPECT_GT(m.at("final_progress_m"), 3.9);
}

}  // namespace
}  // namespace linesim
