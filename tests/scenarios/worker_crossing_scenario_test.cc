// Issue 22: the shipped worker_crossing scenario end to end (ODE chassis,
// CVODE motors, both S300s casting against the factory and the walking
// worker, the safety unit in the loop), over seeds.
#include <gtest/gtest.h>

#include <fstream>
#include <iostream>
#include <map>
#include <string>

#include "tests/scenarios/run_scenario.h"

namespace linesim {
namespace {

using test_scenarios::RunSeeds;
using test_scenarios::Shipped;

// Guards against a safety function that does not stop the robot for the
// worker standing in its path: over 8 seeds (the belt's speed variation
// and the lasers' noise differ) the robot never touches the worker, keeps a
// positive distance, makes at least one protective stop and still finishes
// its path.
// Spread seen (seeds 1..8): person_collisions 0 and collisions 0 on every
// seed; min_person_distance_m min 0.125 / median 0.131 / max 0.143 m (the
// protective stop leaves 12-14 cm to the nearest leg); protective_stops 1
// on every seed; time_stopped_s 8.68 / 8.72 / 8.80 s; task_time_s
// 35.46 / 35.48 / 35.52 s (the path alone takes about 25 s). The bounds
// asserted are the definition of the safety function's success, not the
// spread: no contact, a positive distance, a stop, a finished task.
TEST(WorkerCrossing, ProtectiveStopBeforeThePerson) {
  const auto runs = RunSeeds(Shipped("worker_crossing"), {}, 8);
  for (std::size_t i = 0; i < runs.seeds.size(); ++i) {
    EXPECT_EQ(runs["person_collisions"].values[i], 0.0) << "seed " << runs.seeds[i];
    EXPECT_EQ(runs["collisions"].values[i], 0.0) << "seed " << runs.seeds[i];
    EXPECT_GT(runs["min_person_distance_m"].values[i], 0.0) << "seed " << runs.seeds[i];
    EXPECT_GE(runs["protective_stops"].values[i], 1.0) << "seed " << runs.seeds[i];
    EXPECT_GT(runs["time_stopped_s"].values[i], 0.0) << "seed " << runs.seeds[i];
    EXPECT_GT(runs["task_time_s"].values[i], 0.0) << "seed " << runs.seeds[i];
  }
}

// Guards against a test that cannot fail: the same scenario without the
// safety function (safety.enabled false) drives into the worker: counted as
// a contact and timed (person contact is not modelled: the body passes
// through the worker, which issue 37's metric and warning say).
TEST(WorkerCrossing, WithoutSafetyTheRobotHitsThePerson) {
  const auto m = test_scenarios::RunFile(Shipped("worker_crossing"), {"safety.enabled=false"});
  EXPECT_GE(m.at("person_collisions"), 1.0);
  EXPECT_EQ(m.at("min_person_distance_m"), 0.0);
  EXPECT_GT(m.at("person_contact_time_s"), 0.0);
}

// Guards issue 37: a worker walking through a robot that holds its
// position pushed it to 5 m/s (the chassis collided with the worker's
// cylinders, geoms no force could move). Person contact is not modelled:
// the robot is not pushed, and the contact is counted, timed and warned of.
// The Rob@Work 3 holds at (0, -4) facing +y (its body 0.57 m wide across
// the worker's way, 0.33 m high: the legs meet it, the torso is above it);
// the worker walks along y = -4 at 1.37 m/s from x = -3, leaving at 1 s.
// Bounds: the hold's drift is the hold's own (mm on the floor; pushed it was
// metres), and a leg is within 0.75 m of the worker's centre along the way
// (0.285 m half width + 0.045 m leg radius + 0.42 m, the stance foot's
// reach, stance_fraction / 2 x 1.41 m), so the contact lasts at most
// 1.5 m / 1.37 m/s = 1.1 s.
TEST(WorkerCrossing, AWorkerWalkingThroughAHoldingRobotDoesNotPushIt) {
  const std::string file = ::testing::TempDir() + "worker_through_robot.yaml";
  std::ofstream(file) << R"(name: worker_through
duration_s: 6
seed: 1
master: {algorithm: gauss_seidel, step_s: 0.005}
robot: {model: raw3, pose: {x_m: 0.0, y_m: -4.0, yaw_deg: 90}}
scene: {model: factory_line}
control: {compensation: false, period_s: 0.02}
task: {type: hold}
sensors: {default: false, laser_front: true}
sensing: {surface_velocity: ground_truth}
localization: {source: ground_truth}
workers:
  - {name: walker, waypoints: [[-3.0, -4.0], [3.0, -4.0]], start_time_s: 1}
)";
  loader::Scenario s = loader::LoadScenario(file);
  cosim::MetricsObserver metrics(s.metrics);
  s.master->AddObserver(&metrics);
  const cosim::RunResult result = s.master->Run();
  ASSERT_TRUE(result.ok) << result.ErrorText();
  std::map<std::string, double> m;
  for (const auto& [metric, value] : metrics.Results()) m[metric] = value;
  for (const auto& [metric, value] : m) std::cout << "  " << metric << " = " << value << "\n";
  EXPECT_LT(m.at("max_position_drift_m"), 0.01);
  EXPECT_GE(m.at("person_collisions"), 1.0);
  EXPECT_EQ(m.at("min_person_distance_m"), 0.0);
  EXPECT_GT(m.at("person_contact_time_s"), 0.0);
  EXPECT_LE(m.at("person_contact_time_s"), 1.1);
  const auto& clearance = s.system->unit(*s.system->FindUnit("person_clearance"));
  ASSERT_FALSE(clearance.warnings().empty());
  EXPECT_NE(clearance.warnings().front().find("walker touches the robot's body: contact with a "
                                              "person is not modelled"),
            std::string::npos)
      << clearance.warnings().front();
}

}  // namespace
}  // namespace linesim
