// The `workers:` and `safety:` sections of a robot scenario: what they
// expand into, and bad input named at its file and key path.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "loader/robot_scenario.h"
#include "tests/loader/scenario_test.h"

namespace linesim::loader::testing {
namespace {

std::string Shipped() { return std::string(LINESIM_SOURCE_DIR) + "/scenarios/worker_crossing.yaml"; }

// Guards against workers that the lasers or the clearance do not get: one
// worker gives each S300 3 moving cylinders (21 numbers), and the
// scenario's safety section adds the safety unit.
TEST(PeopleAssembly, WorkersReachTheLasersAndTheSafetyUnit) {
  const Scenario s = LoadScenario(Shipped(), {"duration_s=0.1"});
  ASSERT_TRUE(s.system->FindUnit("worker").has_value());
  ASSERT_TRUE(s.system->FindUnit("person_clearance").has_value());
  ASSERT_TRUE(s.system->FindUnit("safety").has_value());
  for (const char* laser : {"laser_front", "laser_rear"}) {
    const auto& v = s.system->unit(*s.system->FindUnit(laser)).variables();
    const auto ref = v.Find("moving_cylinders");
    ASSERT_TRUE(ref.has_value()) << laser;
    EXPECT_EQ(v.info(*ref).size, 21u) << laser;
  }
  // The person clearance's body heights are raw3.yaml's box (0.07 to
  // 0.40 m), not a box about the centre of mass.
  const auto& pc = s.system->unit(*s.system->FindUnit("person_clearance")).variables();
  EXPECT_EQ(pc.GetReal(*pc.Find("body_z_min")), 0.07);
  EXPECT_NEAR(pc.GetReal(*pc.Find("body_z_max")), 0.40, 1e-15);
}

// Guards what the figures read of the workers and the safety fields: each
// worker's name and recorded legs, the field set column, and how far each
// field set's fields reach forward in base_link (models/robots/raw3.yaml:
// the front at 0.515 m, protective 0.15/0.25/1.0 m and warning
// 0.65/0.75/1.5 m beyond it).
TEST(PeopleAssembly, FiguresGetTheWorkersAndTheFieldsReach) {
  const Scenario s = LoadScenario(Shipped(), {"duration_s=0.1"});
  const RobotInfo& info = *s.robot;
  ASSERT_EQ(info.worker_names.size(), 1u);
  EXPECT_EQ(info.worker_names[0], "worker");
  ASSERT_EQ(info.worker_leg_columns.size(), 1u);
  EXPECT_EQ(info.worker_leg_columns[0][3], "worker.legs[3]");
  std::vector<std::string> recorded;
  for (const auto& p : s.recorded) recorded.push_back(p.label);
  for (const auto& column : {info.worker_leg_columns[0][0], info.field_set_column}) {
    EXPECT_NE(std::find(recorded.begin(), recorded.end(), column), recorded.end()) << column;
  }
  EXPECT_EQ(info.field_set_column, "safety.field_set");
  const double reach[3][2] = {{0.665, 1.165}, {0.765, 1.265}, {1.515, 2.015}};
  ASSERT_EQ(info.field_reach_m.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_NEAR(info.field_reach_m[k][0], reach[k][0], 1e-12) << k;
    EXPECT_NEAR(info.field_reach_m[k][1], reach[k][1], 1e-12) << k;
  }
}

// Guards against bad worker and safety keys passing silently: each is
// refused naming the file and the key path.
TEST(PeopleAssembly, BadKeysNamed) {
  const std::string base = R"(name: t
duration_s: 1
robot: {model: raw3, pose: {x_m: 0, y_m: -4, yaw_deg: 90}}
scene: {model: factory_line}
task: {type: path, waypoints: [[0, -4], [0, 3]], speed_mps: 0.3}
sensors: {default: false, laser_front: true}
)";
  const std::string bad_key = WriteScenario(
      "bad_worker_key.yaml", base + "workers:\n  - {waypoints: [[0, 0], [1, 0]], pace_s: 3}\n");
  std::string issues = Issues(bad_key);
  EXPECT_TRUE(Has(issues, bad_key)) << issues;
  EXPECT_TRUE(Has(issues, "workers.0.pace_s")) << issues;

  const std::string no_points =
      WriteScenario("worker_no_points.yaml", base + "workers:\n  - {name: w}\n");
  issues = Issues(no_points);
  EXPECT_TRUE(Has(issues, "workers.0.waypoints")) << issues;

  const std::string pauses = WriteScenario(
      "worker_pauses.yaml",
      base + "workers:\n  - {waypoints: [[0, 0], [1, 0]], pause_s: [1, 2, 3]}\n");
  issues = Issues(pauses);
  EXPECT_TRUE(Has(issues, "workers.0.pause_s")) << issues;

  const std::string param = WriteScenario(
      "worker_param.yaml",
      base + "workers:\n  - {waypoints: [[0, 0], [1, 0]], parameters: {walking_speed: -1}}\n");
  issues = Issues(param);
  EXPECT_TRUE(Has(issues, "workers.0.parameters.walking_speed")) << issues;

  const std::string field = WriteScenario(
      "safety_field.yaml",
      base + "safety:\n  field_sets:\n    - {max_speed_mps: 1, protective: [[0, 0], [1, 0]]}\n");
  issues = Issues(field);
  EXPECT_TRUE(Has(issues, "safety.field_sets.0.protective")) << issues;

  const std::string scanner =
      WriteScenario("safety_scanner.yaml",
                    base + "safety:\n  scanner: laser_rear\n  field_sets:\n    - {max_speed_mps: "
                           "1, protective: [[0, 0], [1, 0], [0, 1]]}\n");
  issues = Issues(scanner);
  EXPECT_TRUE(Has(issues, "safety.scanner")) << issues;
}

// Guards the vehicle's configuration: `safety: {enabled: true}` takes the
// field sets of the robot file (models/robots/raw3.yaml: three speed
// cases), a scenario's key replaces the file's, and a bad value in the
// robot file's section is reported there, at its key path.
TEST(PeopleAssembly, FieldSetsComeFromTheRobotFile) {
  const Scenario s = LoadScenario(Shipped(), {"duration_s=0.1"});
  EXPECT_EQ(s.expanded["units"]["safety"]["parameters"]["field_sets"].size(), 3u);
  EXPECT_EQ(Param(s, "safety", "restart_delay"), 2.0);  // the robot file's
  const Scenario t =
      LoadScenario(Shipped(), {"duration_s=0.1", "safety.parameters={restart_delay: 0.5}"});
  EXPECT_EQ(Param(t, "safety", "restart_delay"), 0.5);

  std::ifstream in(LINESIM_SOURCE_DIR "/models/robots/raw3.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string good = "- max_speed_mps: 0.4";
  text.replace(text.find(good), good.size(), "- max_speed_mps: -0.4");
  const std::string robot = WriteScenario("raw3_bad_field_set.yaml", text);
  const std::string issues = Issues(Shipped(), {"robot.model=" + robot});
  EXPECT_TRUE(Has(issues, robot)) << issues;
  EXPECT_TRUE(Has(issues, "safety.field_sets.1.max_speed_mps")) << issues;

  // The Husky has no safety section and no S300.
  const std::string husky = Issues(Shipped(), {"robot.model=husky"});
  EXPECT_TRUE(Has(husky, "safety.scanner")) << husky;
}

// The one-robot scenario the next tests vary: the Rob@Work 3 at (0, -4)
// facing +y (its body 1.03 x 0.57 m, heights -0.07 to 0.33 m).
const std::string kBase = R"(name: t
duration_s: 1
robot: {model: raw3, pose: {x_m: 0, y_m: -4, yaw_deg: 90}}
scene: {model: factory_line}
task: {type: path, waypoints: [[0, -4], [0, 3]], speed_mps: 0.3}
sensors: {default: false, laser_front: true}
)";

// Guards issue 37: a worker placed inside a robot was accepted and threw it
// at 11 m/s. Person contact is not modelled, so a worker must start clear
// of the body: inside or touching is refused at its first waypoint, naming
// the robot. The body's half width along x here is 0.285 m and a standing
// worker facing +y has its legs (radius 0.045 m) 0.1 m to either side of
// its centre: at x = 0.42 the nearer leg overlaps the body by 1 cm, at
// x = 0.44 it is 1 cm clear.
TEST(PeopleAssembly, WorkersStartClearOfTheRobot) {
  const auto with_worker = [&](const std::string& name, const std::string& worker) {
    return WriteScenario(name, kBase + "workers:\n  - " + worker + "\n");
  };
  std::string issues =
      Issues(with_worker("worker_inside.yaml", "{name: w, waypoints: [[0.0, -4.0]]}"));
  EXPECT_TRUE(Has(issues, "workers.0.waypoints.0")) << issues;
  EXPECT_TRUE(Has(issues,
                  "worker 'w' would start inside or touching the body of the robot (at "
                  "robot.pose)"))
      << issues;
  EXPECT_TRUE(Has(issues, "contact with a person is not modelled")) << issues;
  issues = Issues(
      with_worker("worker_touching.yaml", "{name: w, waypoints: [[0.42, -4.0], [0.42, -3.0]]}"));
  EXPECT_TRUE(Has(issues, "workers.0.waypoints.0")) << issues;
  EXPECT_EQ(Issues(with_worker("worker_clear.yaml",
                               "{name: w, waypoints: [[0.44, -4.0], [0.44, -3.0]]}")),
            "(no error)");
  // The worker's own body: thicker legs reach the robot from farther.
  issues = Issues(with_worker(
      "worker_thick.yaml",
      "{name: w, waypoints: [[0.5, -4.0], [0.5, -3.0]], parameters: {leg_radius: 0.2}}"));
  EXPECT_TRUE(Has(issues, "workers.0.waypoints.0")) << issues;
}

// Guards issue 37: a collinear, zero-area or self-intersecting field was
// accepted and silently disabled the stop: refused at its key, as written
// (base_link), in the scenario or the robot file.
TEST(PeopleAssembly, DegenerateFieldsRefusedAtTheirKey) {
  const auto field = [&](const std::string& name, const std::string& protective) {
    return Issues(WriteScenario(
        name, kBase + "safety:\n  field_sets:\n    - {max_speed_mps: 1, protective: " + protective +
                  "}\n"));
  };
  std::string issues = field("field_line.yaml", "[[0.3, -0.2], [0.6, 0.0], [0.9, 0.2]]");
  EXPECT_TRUE(Has(issues, "safety.field_sets.0.protective: the field has zero area")) << issues;
  issues = field("field_bow.yaml", "[[0.3, -0.3], [0.9, 0.3], [0.9, -0.3], [0.3, 0.3]]");
  EXPECT_TRUE(Has(issues, "safety.field_sets.0.protective: the field is self-intersecting"))
      << issues;
  issues = field("field_repeat.yaml", "[[0.3, -0.3], [0.9, -0.3], [0.9, -0.3], [0.3, 0.3]]");
  EXPECT_TRUE(Has(issues, "repeats corner 1")) << issues;
  EXPECT_EQ(field("field_ok.yaml", "[[0.3, -0.3], [0.9, -0.3], [0.9, 0.3], [0.3, 0.3]]"),
            "(no error)");
}

// Guards issue 37's messages at the user's key: a repeated waypoint (the
// worker unit's check) was reported at units.worker.parameters.waypoints.1,
// a name with a blank in 86 connections.N lines, a scenario metric that a
// worker's metric repeats at metrics.N.name of the expansion. Each is
// reported once, at the key the user wrote.
TEST(PeopleAssembly, WorkerProblemsAtTheWorkersKeys) {
  std::string issues = Issues(WriteScenario(
      "worker_repeat.yaml",
      kBase + "workers:\n  - {name: w, waypoints: [[-3, -1.2], [-3, -1.2], [0, -1.2]]}\n"));
  EXPECT_TRUE(Has(issues, "workers.0.waypoints.1: repeats the waypoint before it")) << issues;
  EXPECT_FALSE(Has(issues, "units.")) << issues;

  const std::string blank = WriteScenario(
      "worker_blank.yaml", kBase + "workers:\n  - {name: bad name, waypoints: [[-3, -1.2]]}\n");
  issues = Issues(blank);
  EXPECT_TRUE(Has(issues, "workers.0.name: worker name 'bad name' is not valid")) << issues;
  EXPECT_FALSE(Has(issues, "connections.")) << issues;
  EXPECT_EQ(std::count(issues.begin(), issues.end(), '\n'), 0) << issues;  // one issue

  const std::string metric = WriteScenario(
      "worker_metric.yaml",
      kBase +
          "workers:\n  - {name: w, waypoints: [[-3, -1.2]]}\n"
          "metrics:\n  - {name: w_time_waited_s, of: 'belt.speed[0]', reduce: max}\n");
  issues = Issues(metric);
  EXPECT_TRUE(Has(issues,
                  "metrics.0.name: metric 'w_time_waited_s' is also one the robot "
                  "scenario gives"))
      << issues;

  const std::string pause = WriteScenario(
      "worker_pause.yaml",
      kBase + "workers:\n  - {name: w, waypoints: [[-3, -1.2], [0, -1.2]], pause_s: [0, -1]}\n");
  issues = Issues(pause);
  EXPECT_TRUE(Has(issues, "workers.0.pause_s.1")) << issues;
}

// Guards issue 37: 3,400 workers were refused after 20 s at an internal key
// (units.chassis.parameters.moving_cylinders) that never said "workers".
// Too many are refused at `workers`, naming the limit, before anything is
// built (this one-robot file's limit: kMaxRobotWorkerPairs).
TEST(PeopleAssembly, TooManyWorkersRefusedAtWorkers) {
  std::string text = kBase + "workers:\n";
  for (std::size_t k = 0; k <= kMaxRobotWorkerPairs; ++k) {
    text += "  - {waypoints: [[" + std::to_string(-10.0 + 0.01 * static_cast<double>(k)) +
            ", -8.0]]}\n";
  }
  const std::string issues = Issues(WriteScenario("many_workers.yaml", text));
  EXPECT_TRUE(Has(issues, "workers: " + std::to_string(kMaxRobotWorkerPairs + 1) +
                              " workers with 1 robot: at most " +
                              std::to_string(kMaxRobotWorkerPairs)))
      << issues;
  EXPECT_EQ(std::count(issues.begin(), issues.end(), '\n'), 0) << issues;  // one issue
}

}  // namespace
}  // namespace linesim::loader::testing
