// Paper 2's van entry end to end (scenarios/van_entry.yaml): the LMS151 in
// 3D, Perfect Match with the map switch, the EKF, the route follower, the
// Husky with its arm on the ramp, the beacon ground truth. Bounds are paper
// 2's Table 1 maxima (Sobreira et al. 2019: 0.019 m, 0.014 m, 2.216 deg over
// 20 runs) with the margin stated at each, and the beacon system's own
// stated error (5 mm, 0.2 deg).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

#include "tests/scenarios/run_scenario.h"

namespace linesim {
namespace {

using test_scenarios::RunSeeds;
using test_scenarios::Shipped;

// Guards the whole chain: the route is finished (the final pose was taken:
// a run that never finished fails), the robot stops near the work pose as
// paper 2's robot did, and the beacons measure it as well as paper 2 says
// they can.
//
// The spread over 20 runs (`linesim run scenarios/van_entry.yaml --runs 20`; |value|
// min / median / max): final_error_x_m 0.0001 / 0.0057 / 0.0147;
// final_error_y_m 0.0000 / 0.0013 / 0.0049; final_error_yaw_deg 0.030 /
// 0.467 / 0.860; beacon_self_error_position_m 0.0023 / 0.0034 / 0.0053;
// beacon_self_error_yaw_deg 0.001 / 0.024 / 0.110; max_path_deviation_m
// 0.0101 / 0.0108 / 0.0140; min_clearance_m 0.387 / 0.395 / 0.401;
// collisions 0. Seeds 1..8 (signed): final_error_x_m -0.0191 / -0.0032 /
// 0.0131; final_error_y_m -0.0014 / 0.0010 / 0.0045; final_error_yaw_deg
// -0.727 / 0.418 / 0.817; beacon_self_error_position_m 0.0026 / 0.0033 /
// 0.0048; beacon_self_error_yaw_deg -0.042 / 0.014 / 0.072;
// max_path_deviation_m 0.0100 / 0.0113 / 0.0147; min_clearance_m 0.388 /
// 0.394 / 0.396; collisions 0. (The heading's spread moves by a factor of
// two with the last bits of a math function: see docs/results.md.)
// Table 1's maximum is the largest of paper 2's own 20 runs, itself a draw:
// one of our 8 seeds may pass it (one stops 19.1 mm off in x with the exact
// ray casting), so a single run is held to twice it (a gross failure) and
// the median of the runs to it; the beacons likewise (their stated 5 mm is
// a typical accuracy: median under it, every run under twice it).
TEST(VanEntryScenario, HuskyClimbsIntoTheVanAndStopsAtTheWorkPose) {
  constexpr int kSeeds = 8;
  const auto m = RunSeeds(Shipped("van_entry"), {}, kSeeds);
  // Table 1's maxima.
  EXPECT_LT(m["final_error_x_m"].max_abs(), 2 * 0.019);
  EXPECT_LT(m["final_error_y_m"].max_abs(), 2 * 0.014);
  EXPECT_LT(m["final_error_yaw_deg"].max_abs(), 2 * 2.216);
  EXPECT_LT(std::abs(m["final_error_x_m"].median()), 0.019);
  EXPECT_LT(std::abs(m["final_error_y_m"].median()), 0.014);
  EXPECT_LT(std::abs(m["final_error_yaw_deg"].median()), 2.216);
  // The beacon system's own error: paper 2's 5 mm and 0.2 deg.
  EXPECT_LT(m["beacon_self_error_position_m"].median(), 0.005);
  EXPECT_LT(m["beacon_self_error_position_m"].max(), 2 * 0.005);
  EXPECT_LT(m["beacon_self_error_yaw_deg"].max_abs(), 0.2);
  // The robot stayed on its route (the follower on the fused pose) and
  // never touched the van: the body clears the walls and arches.
  EXPECT_LT(m["max_path_deviation_m"].max(), 0.05);
  EXPECT_EQ(m["collisions"].max(), 0.0);
  EXPECT_GT(m["min_clearance_m"].min(), 0.1);
}

// Guards the map switch's wiring: the follower's map index counts in the
// route graph's maps list, so localization.maps must name the same maps in
// the same order; a renamed map is refused before time zero.
TEST(VanEntryScenario, MapsMustBeTheRoutesMaps) {
  EXPECT_THROW(loader::LoadScenario(Shipped("van_entry"), {"localization.maps.1.name=inside"}),
               config::ScenarioError);
}

}  // namespace
}  // namespace linesim
