// A fleet (`robots:`): each robot's units and metrics under its name, one
// world through connections, and bad input named at robots.I's key paths.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "loader/robot_scenario.h"
#include "tests/loader/scenario_test.h"

namespace linesim::loader::testing {
namespace {

std::string Shipped() { return std::string(LINESIM_SOURCE_DIR) + "/scenarios/fleet_line.yaml"; }

bool Connected(const Scenario& s, const std::string& from, const std::string& to) {
  for (const auto& c : s.expanded["connections"]) {
    if (c["from"].as<std::string>() == from && c["to"].as<std::string>() == to) return true;
  }
  return false;
}

bool HasMetric(const Scenario& s, const std::string& name) {
  return std::any_of(s.metrics.begin(), s.metrics.end(),
                     [&](const auto& m) { return m.name == name; });
}

// Guards the scoping: every robot's units live under its name, the scene's
// belt and the workers are one unit each, metrics are per robot, and the
// plots' columns are the scoped ones (the first robot's, the others in
// `fleet`).
TEST(FleetAssembly, RobotsAreScopedByTheirNames) {
  const Scenario s = LoadScenario(Shipped(), {"duration_s=0.1"});
  for (const char* unit :
       {"raw3_a.chassis", "raw3_a.motors", "raw3_a.wheel_controller", "raw3_a.laser_front",
        "raw3_a.safety", "raw3_b.chassis", "raw3_b.path_follower", "husky.chassis",
        "husky.laser_front", "belt", "worker_1", "worker_2", "raw3_a.robot_clearance"}) {
    EXPECT_TRUE(s.system->FindUnit(unit).has_value()) << unit;
  }
  for (const char* unit : {"chassis", "raw3_a.belt", "raw3_a.worker_1", "husky.safety"}) {
    EXPECT_FALSE(s.system->FindUnit(unit).has_value()) << unit;
  }
  for (const char* metric :
       {"raw3_a.max_path_deviation_m", "raw3_b.max_position_drift_m", "husky.collisions",
        "raw3_a.protective_stops", "husky.robot_raw3_a_collisions",
        "raw3_b.min_robot_distance_m", "raw3_a.robot_worker_1_collisions"}) {
    EXPECT_TRUE(HasMetric(s, metric)) << metric;
  }
  ASSERT_TRUE(s.robot);
  EXPECT_EQ(s.robot->name, "raw3_a");
  EXPECT_EQ(s.robot->x_column, "raw3_a.chassis.position[0]");
  ASSERT_EQ(s.robot->fleet.size(), 2u);
  EXPECT_EQ(s.robot->fleet[1].name, "husky");
  EXPECT_EQ(s.robot->fleet[1].yaw_column, "husky.chassis.yaw");
  EXPECT_EQ(s.robot->fleet[1].body_length_m, 0.9874);  // models/robots/husky.yaml
  // The belt drives every chassis.
  EXPECT_TRUE(Connected(s, "belt.velocity", "husky.chassis.belt_velocity"));
  EXPECT_TRUE(Connected(s, "belt.velocity", "raw3_b.chassis.belt_velocity"));
}

// Guards the one world: the moving_bodies unit gathers the three chassis'
// bodies (10 numbers each); each robot's chassis, lasers and robot
// clearance read them whole, leaving out their own robot's; the lasers take
// the workers' legs and torsos (2 workers x 3 cylinders x 7 numbers), the
// chassis does not (person contact is not modelled: issue 37).
TEST(FleetAssembly, EveryRobotSeesTheOthersAndTheWorkers) {
  const Scenario s = LoadScenario(Shipped(), {"duration_s=0.1"});
  for (const char* unit : {"raw3_a.chassis", "raw3_a.laser_front", "raw3_a.laser_rear",
                           "raw3_b.chassis", "husky.chassis", "husky.laser_front"}) {
    const auto& v = s.system->unit(*s.system->FindUnit(unit)).variables();
    const auto boxes = v.Find("moving_boxes");
    const auto cylinders = v.Find("moving_cylinders");
    ASSERT_TRUE(boxes.has_value()) << unit;
    EXPECT_EQ(v.info(*boxes).size, 30u) << unit;
    if (std::string(unit).ends_with(".chassis")) {
      EXPECT_FALSE(cylinders.has_value()) << unit;
    } else {
      ASSERT_TRUE(cylinders.has_value()) << unit;
      EXPECT_EQ(v.info(*cylinders).size, 42u) << unit;
    }
  }
  EXPECT_TRUE(Connected(s, "raw3_b.chassis.body_box[0]", "moving_bodies.bodies_in[10]"));
  EXPECT_TRUE(Connected(s, "husky.chassis.body_box[9]", "moving_bodies.bodies_in[29]"));
  EXPECT_TRUE(Connected(s, "moving_bodies.bodies", "raw3_a.laser_front.moving_boxes"));
  EXPECT_TRUE(Connected(s, "moving_bodies.bodies", "husky.chassis.moving_boxes"));
  EXPECT_TRUE(Connected(s, "moving_bodies.bodies", "husky.robot_clearance.bodies"));
  const auto own_box = [&](const std::string& unit) {
    const auto& v = s.system->unit(*s.system->FindUnit(unit)).variables();
    return v.GetInteger(*v.Find("own_box"));
  };
  EXPECT_EQ(own_box("husky.laser_front"), 2);
  EXPECT_EQ(own_box("raw3_b.chassis"), 1);
  EXPECT_TRUE(Connected(s, "worker_2.cylinders[0]", "husky.laser_front.moving_cylinders[21]"));
}

// Guards the override paths: robots.I.KEY reaches robot I's units only.
TEST(FleetAssembly, SetReachesOneRobot) {
  const Scenario s = LoadScenario(Shipped(), {"duration_s=0.1", "robots.1.pose.x_m=2.5",
                                              "robots.2.task.speed_mps=0.4"});
  EXPECT_EQ(Param(s, "raw3_b.chassis", "initial_x"), 2.5);
  EXPECT_EQ(Param(s, "raw3_a.chassis", "initial_x"), -0.5);
  EXPECT_EQ(Param(s, "husky.path_follower", "speed"), 0.4);
  EXPECT_EQ(Param(s, "raw3_a.path_follower", "speed"), 0.3);
}

// Guards against problems reported at the one-robot paths (task.speed) or
// not at all: each names robots.I's key, in the file or on the command
// line; robots that would start inside each other, a name given twice, a
// name that is no identifier and robot: beside robots: are refused.
TEST(FleetAssembly, ProblemsAreNamedAtTheRobotsKeys) {
  std::string issues = Issues(Shipped(), {"robots.1.task.speed=3", "robots.2.pose.x_m=abc",
                                          "robots.0.control.compensation=maybe"});
  EXPECT_TRUE(Has(issues, "robots.1.task.speed")) << issues;
  EXPECT_TRUE(Has(issues, "closest: robots.1.task.speed_mps")) << issues;
  EXPECT_TRUE(Has(issues, "robots.2.pose.x_m")) << issues;
  EXPECT_TRUE(Has(issues, "robots.0.control.compensation")) << issues;

  issues = Issues(Shipped(), {"robots.1.pose.x_m=-0.4", "robots.1.pose.y_m=-3.2"});
  EXPECT_TRUE(Has(issues, "robots.1.pose")) << issues;
  EXPECT_TRUE(Has(issues, "would start inside robot 'raw3_a'")) << issues;

  issues = Issues(Shipped(), {"robots.2.name=raw3_a"});
  EXPECT_TRUE(Has(issues, "robots.2.name")) << issues;
  EXPECT_TRUE(Has(issues, "given twice")) << issues;

  issues = Issues(Shipped(), {"robots.2.name=my-husky"});
  EXPECT_TRUE(Has(issues, "robots.2.name")) << issues;

  const std::string both = WriteScenario("fleet_and_robot.yaml", R"(name: t
duration_s: 1
scene: {model: factory_line}
robot: {model: raw3}
robots:
  - {name: a, model: raw3, task: {type: hold}}
)");
  issues = Issues(both);
  EXPECT_TRUE(Has(issues, "not both")) << issues;
  // A section of the shorthand at the top level of a fleet is not a key there.
  const std::string top = WriteScenario("fleet_top_task.yaml", R"(name: t
duration_s: 1
scene: {model: factory_line}
task: {type: hold}
robots:
  - {name: a, model: raw3, task: {type: hold}}
)");
  issues = Issues(top);
  EXPECT_TRUE(Has(issues, ": task")) << issues;
}

// Guards issue 37 in a fleet: a robot that would start on a worker is
// refused at the worker's first waypoint, naming the robot and its pose
// key; a worker named as a robot (whose metrics then took the names of the
// robots' pair metrics, reported at metrics.44.name) at its name.
TEST(FleetAssembly, WorkersAgainstTheRobots) {
  std::string issues = Issues(Shipped(), {"robots.2.pose.x_m=1.5", "robots.2.pose.y_m=-6.5"});
  EXPECT_TRUE(Has(issues, "workers.1.waypoints.0")) << issues;
  EXPECT_TRUE(Has(issues,
                  "worker 'worker_2' would start inside or touching the body of robot "
                  "'husky' (at robots.2.pose)"))
      << issues;
  issues = Issues(Shipped(), {"workers.0.name=raw3_a"});
  EXPECT_TRUE(Has(issues, "workers.0.name")) << issues;
  EXPECT_TRUE(Has(issues, "'raw3_a' is the name of a robot")) << issues;
  EXPECT_FALSE(Has(issues, "metrics.")) << issues;
}

// Guards issue 37: 1,000 robots reached 7.7 GB and std::bad_alloc after
// 267 s. More than kMaxRobots are refused at `robots` before anything is
// built, naming the limit; so are more workers than the robot-worker pairs
// allow with them.
TEST(FleetAssembly, TooManyRobotsRefusedAtRobots) {
  std::string text = "name: t\nduration_s: 1\nscene: {model: factory_line}\nrobots:\n";
  for (std::size_t i = 0; i <= kMaxRobots; ++i) {
    text += "  - {name: r" + std::to_string(i) + ", model: raw3, task: {type: hold}}\n";
  }
  std::string issues = Issues(WriteScenario("fleet_many.yaml", text));
  EXPECT_TRUE(Has(issues, "robots: " + std::to_string(kMaxRobots + 1) + " robots: at most " +
                              std::to_string(kMaxRobots) + " ("))
      << issues;
  EXPECT_FALSE(Has(issues, "would start inside")) << issues;  // nothing was expanded

  std::string workers =
      "name: t\nduration_s: 1\nscene: {model: factory_line}\nrobots:\n"
      "  - {name: a, model: raw3, task: {type: hold}}\n"
      "  - {name: b, model: raw3, pose: {x_m: 3}, task: {type: hold}}\n"
      "workers:\n";
  for (std::size_t k = 0; k <= kMaxRobotWorkerPairs / 2; ++k) {
    workers +=
        "  - {waypoints: [[-10, " + std::to_string(-9.0 + 0.001 * static_cast<double>(k)) + "]]}\n";
  }
  issues = Issues(WriteScenario("fleet_many_workers.yaml", workers));
  EXPECT_TRUE(Has(issues, "workers: " + std::to_string(kMaxRobotWorkerPairs / 2 + 1) +
                              " workers with 2 robots: at most " +
                              std::to_string(kMaxRobotWorkerPairs / 2)))
      << issues;
}

}  // namespace
}  // namespace linesim::loader::testing
