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

using test_scenarios::RunFile;
using test_scenarios::Shipped;

// Guards the whole chain: the route is finished (the final pose was taken:
// a run that never finished fails), the robot stops near the work pose as
// paper 2's robot did, and the beacons measure it as well as paper 2 says
// they can.
TEST(VanEntryScenario, HuskyClimbsIntoTheVanAndStopsAtTheWorkPose) {
  const auto m = RunFile(Shipped("van_entry"), {});
  // Table 1's maxima (this model's own 20 runs stay within them too).
  EXPECT_LT(std::abs(m.at("final_error_x_m")), 0.019);
  EXPECT_LT(std::abs(m.at("final_error_y_m")), 0.014);
  EXPECT_LT(std::abs(m.at("final_error_yaw_deg")), 2.216);
  // The beacon system's own error: paper 2's 5 mm and 0.2 deg.
  EXPECT_LT(m.at("beacon_self_error_position_m"), 0.005);
  EXPECT_LT(std::abs(m.at("beacon_self_error_yaw_deg")), 0.2);
  // The robot stayed on its route (the follower on the fused pose) and
  // never touched the van: the body clears the walls and arches.
  EXPECT_LT(m.at("max_path_deviation_m"), 0.05);
  EXPECT_EQ(m.at("collisions"), 0.0);
  EXPECT_GT(m.at("min_clearance_m"), 0.1);
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
