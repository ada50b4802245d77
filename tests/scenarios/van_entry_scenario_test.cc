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
// The spread over 20 runs (`linesim run scenarios/van_entry.yaml --runs 20`;
// one LMS151, maps built with it, the beacons' installation 1; signed
// mean +- std [min, max]): final_error_x_m -0.0026 +- 0.0003 [-0.0031,
// -0.0021]; final_error_y_m 0.0005 +- 0.0010 [-0.0022, 0.0020];
// final_error_yaw_deg 0.865 +- 0.032 [0.815, 0.948] (the edge of the
// skid-steer's heading band: docs/architecture.md); beacon_self_error_
// position_m 0.0035 +- 0.0005 [0.0020, 0.0041] and beacon_self_error_yaw_deg
// -0.021 +- 0.029 [-0.076, 0.032] (mostly the installation's survey offset,
// the same in every run); max_path_deviation_m 0.0106 +- 0.0001;
// min_clearance_m 0.3925 +- 0.0003; collisions 0. Seeds 1..8 (min /
// median / max): final_error_x_m -0.0029 / -0.0027 / -0.0023;
// final_error_y_m 0.0001 / 0.0007 / 0.0020; final_error_yaw_deg 0.840 /
// 0.858 / 0.891; beacon_self_error_position_m 0.0032 / 0.0035 / 0.0039;
// beacon_self_error_yaw_deg -0.074 / -0.024 / 0.002; max_path_deviation_m
// 0.0105 / 0.0106 / 0.0108; min_clearance_m 0.392 / 0.393 / 0.393.
// Table 1's maximum is the largest of paper 2's own 20 runs, itself a draw,
// so a single run is held to twice it (a gross failure) and the median of
// the runs to it. The beacons' stated 5 mm and 0.2 deg are the system's
// 1-sigma accuracy, which the scenario draws once as the installation's
// survey (installation_seed, not changed by the run's seed): held to 3
// sigma, which any installation but one in 370 passes.
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
  // The beacon system's own error: paper 2's 5 mm and 0.2 deg, 3 sigma.
  EXPECT_LT(m["beacon_self_error_position_m"].max(), 3 * 0.005);
  EXPECT_LT(m["beacon_self_error_yaw_deg"].max_abs(), 3 * 0.2);
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
