// The route graph files (loader/route_graph_file.h) and the `route` task
// (loader/assembly/task.cc).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "loader/route_graph_file.h"
#include "loader/scenario.h"
#include "models/models_dir.h"
#include "scenario_test.h"

namespace linesim::loader {
namespace {

using testing::Has;
using testing::Issues;
using testing::Param;
using testing::WriteScenario;

std::string VanBay() { return models::ModelsDir() + "/graphs/van_bay.yaml"; }

std::string GraphIssues(const std::string& file) {
  try {
    LoadRouteGraphFile(file);
  } catch (const ScenarioError& e) {
    return e.what();
  }
  return "(no error)";
}

// A Husky scenario on the open floor following a route; `task` is the
// task section's body.
std::string RouteScenario(const std::string& name, const std::string& task) {
  return WriteScenario(name, R"(name: route
duration_s: 1
master: {algorithm: gauss_seidel, step_s: 0.001}
robot:
  model: husky
  pose: {x_m: -1.5, y_m: -1.0, yaw_deg: 0}
control: {period_s: 0.02}
sensors: {default: false}
task:
)" + task);
}

// Guards the shipped van bay graph: the poses the van contract fixes
// (start (-1.5, -1, 0), ramp foot (1.4, 0), ramp top (4.4, 0), work
// (5.9, 0)), the maps in index order and the edges' maps (factory, factory,
// van), each a Hermite cubic through its nodes.
TEST(RouteGraph, VanBayLoads) {
  const RouteGraph g = LoadRouteGraphFile(VanBay());
  EXPECT_EQ(g.maps, (std::vector<std::string>{"factory", "van"}));
  ASSERT_EQ(g.nodes.size(), 4u);
  EXPECT_EQ(g.nodes[0].name, "start");
  EXPECT_EQ(g.nodes[0].x_m, -1.5);
  EXPECT_EQ(g.nodes[0].y_m, -1.0);
  EXPECT_EQ(g.nodes[3].name, "work");
  EXPECT_EQ(g.nodes[3].x_m, 5.9);
  ASSERT_EQ(g.edges.size(), 3u);
  EXPECT_EQ(g.edges[0].segment.map, 0);
  EXPECT_EQ(g.edges[1].segment.map, 0);
  EXPECT_EQ(g.edges[2].segment.map, 1);
  const auto end = models::SegmentPosition(g.edges[0].segment, 1.0);
  EXPECT_NEAR(end[0], 1.4, 1e-12);
  EXPECT_NEAR(end[1], 0.0, 1e-12);
}

// Guards the located errors of a graph file: file, line, key path, what was
// expected (an unknown key with the closest; an edge naming an unknown node
// or map with the closest; explicit coefficients off their node; a node
// twice; a missing required value).
TEST(RouteGraph, FileErrorsAreLocated) {
  const std::string f = WriteScenario("bad_graph.yaml", R"(maps: [factory, van]
nodes:
  - {name: a, x_m: 0, y_m: 0, yaw_dg: 0}
  - {name: b, x_m: 1, y_m: 0, yaw_deg: 0}
  - {name: b, x_m: 2, y_m: 0, yaw_deg: 0}
edges:
  - {from: a, to: bb, map: factory}
  - {from: a, to: b, map: vann}
  - {from: b, to: a, map: van, x: [1.0, -0.5], y: [0]}
)");
  const std::string e = GraphIssues(f);
  EXPECT_TRUE(Has(e, f + ":3: nodes.0.yaw_dg: unknown key; closest: nodes.0.yaw_deg")) << e;
  EXPECT_TRUE(Has(e, "nodes.0.yaw_deg: missing required key")) << e;
  EXPECT_TRUE(Has(e, f + ":5: nodes.2.name: 'b' is defined twice")) << e;
  EXPECT_TRUE(Has(e, f + ":7: edges.0.to: no node 'bb' in this graph: expected one of a, b, b"))
      << e;
  EXPECT_TRUE(Has(e, f + ":8: edges.1.map: no map 'vann' in this graph")) << e;
  EXPECT_TRUE(Has(e, "(closest: van)")) << e;
  EXPECT_TRUE(Has(e, f + ":9: edges.2.x: the coefficients end at (0.5, 0), 0.5 m from node 'a'"))
      << e;
  // Unknown top-level key; missing lists.
  const std::string g = WriteScenario("bad_graph_top.yaml", "mapz: [factory]\n");
  const std::string e2 = GraphIssues(g);
  EXPECT_TRUE(Has(e2, g + ":1: mapz: unknown key; closest: maps")) << e2;
  EXPECT_TRUE(Has(e2, "nodes: missing required key")) << e2;
  EXPECT_TRUE(Has(e2, "edges: missing required key")) << e2;
}

// Guards the route task's errors at task.route.i: an unknown node (with
// the closest) and a pair of nodes without an edge (naming both and where
// the first one's edges go); a graph that does not exist; keys of the path
// task refused with a reason, and the route keys refused for a path task.
TEST(RouteGraph, RouteErrorsNameTheNodeAndTheMissingEdge) {
  const std::string unknown =
      RouteScenario("route_unknown.yaml",
                    "  type: route\n  graph: van_bay\n  route: [start, ramp_foot, ramp_tp]\n");
  std::string e = Issues(unknown);
  EXPECT_TRUE(Has(e, unknown + ":12: task.route.2: no node 'ramp_tp' in route graph")) << e;
  EXPECT_TRUE(Has(e, "(closest: ramp_top)")) << e;
  const std::string missing = RouteScenario(
      "route_missing.yaml", "  type: route\n  graph: van_bay\n  route: [start, work]\n");
  e = Issues(missing);
  EXPECT_TRUE(Has(e, "task.route.1: no edge from 'start' to 'work' in route graph " + VanBay() +
                         ": edges from 'start' go to ramp_foot"))
      << e;
  const std::string nograph = RouteScenario(
      "route_nograph.yaml", "  type: route\n  graph: van_bey\n  route: [start, ramp_foot]\n");
  e = Issues(nograph);
  EXPECT_TRUE(Has(e, "task.graph: no route graph file")) << e;
  EXPECT_TRUE(Has(e, "(closest: van_bay)")) << e;
  const std::string heading =
      RouteScenario("route_heading.yaml",
                    "  type: route\n  graph: van_bay\n  route: [start, ramp_foot]\n  yaw_deg: 0\n");
  e = Issues(heading);
  EXPECT_TRUE(Has(e, "task.yaw_deg: a route steers the robot's heading")) << e;
  const std::string path = RouteScenario(
      "route_on_path.yaml", "  type: path\n  waypoints: [[0, 0], [1, 0]]\n  graph: van_bay\n");
  e = Issues(path);
  EXPECT_TRUE(Has(e, "task.graph: only for task.type route")) << e;
  const std::string gains = RouteScenario(
      "route_gains.yaml",
      "  type: route\n  graph: van_bay\n  route: [start, ramp_foot]\n  gains: {k_p_distanc: 1}\n");
  e = Issues(gains);
  EXPECT_TRUE(Has(e, "task.gains.k_p_distanc: unknown key; closest: task.gains.k_p_distance")) << e;
}

// Guards the route task's expansion: the route_follower (under the
// follower's name, at the control period) gets the route's segments with
// their map indices, the robot's yaw-rate limit (husky.yaml 2.0 rad/s), the
// speed, K_P,D = 1.5^2 / V (the default design at this speed) unless the
// gains say otherwise; the path the plots and the deviation use is the
// sampled route, from the start node to the last node.
TEST(RouteGraph, RouteTaskExpandsIntoTheFollower) {
  const std::string f =
      RouteScenario("route_ok.yaml",
                    "  type: route\n  graph: van_bay\n  route: [start, ramp_foot, ramp_top, work]\n"
                    "  speed_mps: 0.25\n  gains: {k_p_orientation: 2.5}\n");
  const Scenario s = LoadScenario(f);
  const YAML::Node unit = s.expanded["units"]["path_follower"];
  EXPECT_EQ(unit["type"].as<std::string>(), "route_follower");
  ASSERT_EQ(unit["parameters"]["segments"].size(), 3u);
  EXPECT_EQ(unit["parameters"]["segments"][2]["map"].as<int>(), 1);
  EXPECT_EQ(unit["step_s"].as<double>(), 0.02);
  EXPECT_EQ(Param(s, "path_follower", "speed"), 0.25);
  EXPECT_EQ(Param(s, "path_follower", "max_yaw_rate"), 2.0);
  EXPECT_NEAR(Param(s, "path_follower", "k_p_distance"), 2.25 / 0.25, 1e-12);
  EXPECT_EQ(Param(s, "path_follower", "k_p_orientation"), 2.5);
  ASSERT_TRUE(s.robot);
  EXPECT_EQ(s.robot->task, "route");
  ASSERT_GT(s.robot->path.size(), 300u);  // 7.6 m at 2 cm
  EXPECT_NEAR(s.robot->path.front()[0], -1.5, 1e-12);
  EXPECT_NEAR(s.robot->path.front()[1], -1.0, 1e-12);
  EXPECT_NEAR(s.robot->path.back()[0], 5.9, 1e-12);
  // A bad gain is reported at the key the user wrote.
  const std::string bad = RouteScenario("route_bad_gain.yaml",
                                        "  type: route\n  graph: van_bay\n  route: [start, "
                                        "ramp_foot]\n  gains: {k_p_orientation: -1}\n");
  const std::string e = Issues(bad);
  EXPECT_TRUE(Has(e, "task.gains.k_p_orientation")) << e;
}

}  // namespace
}  // namespace linesim::loader
