// The route task end to end: the Husky A200 (paper 2's robot) drives the
// van bay's route graph (models/graphs/van_bay.yaml) with paper 2's
// parametric trajectory controller (route_follower), through the real
// diff_drive_controller, CVODE motors and the ODE chassis with Coulomb
// scrub, on a flat open floor (the ramp and the van are the integrator's
// scene), with ground-truth localization.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include "cosim/observers.h"
#include "loader/route_graph_file.h"
#include "loader/scenario.h"
#include "models/models_dir.h"
#include "models/polynomial_path.h"

namespace linesim {
namespace {

// Follows the run: when done latches, where the robot is when the map index
// first changes, and the pose at the end.
class RouteObserver : public cosim::Observer {
 public:
  explicit RouteObserver(const loader::Scenario& s) {
    probes_ = cosim::ResolveProbes(*s.system,
                                   {"chassis.position[0]", "chassis.position[1]", "chassis.yaw",
                                    "path_follower.done", "path_follower.map_index"});
  }
  void OnSample(cosim::TimeNs t, const cosim::System& system) override {
    double v[5];
    for (std::size_t i = 0; i < 5; ++i) v[i] = cosim::ReadProbe(system, probes_[i]);
    if (v[3] != 0.0 && done_s < 0.0) done_s = cosim::NsToSeconds(t);
    if (v[4] == 1.0 && map_change_x < -1e9) map_change_x = v[0];
    x = v[0];
    y = v[1];
    yaw = v[2];
  }
  double done_s = -1.0, map_change_x = -1e10, x = 0, y = 0, yaw = 0;

 private:
  std::vector<cosim::Probe> probes_;
};

// Guards the route task on the Husky:
//  - it drives the whole route (start -> ramp_foot -> ramp_top -> work,
//    L = the edges' arc lengths, 7.6 m) and stops: done no earlier than
//    L / V (the constant speed of Eq. 5) and no later than L / V + V / (2 a)
//    (the final stop's extra time) + 1 s (the wheel loop's start);
//  - the map index turns to the van's map (1) at the ramp top (x = 4.4 m,
//    within 1 cm: the segment advances when the end is the nearest point);
//  - the final pose is within paper 2's Table 1 maxima of the work pose
//    (0.019 m in x, 0.014 m in y, 2.216 deg), which the real robot met with
//    its own localization: with the true pose the controller alone must do
//    at least as well; and the route is followed within 0.014 m throughout.
// One seed: the seed draws nothing in this run (no sensors, no belt): its
// signals.csv is the same to the last bit for seeds 1, 2 and 7 (measured
// with `linesim run --set seed=N`). Measured: done at 25.80 s (L / V =
// 25.33 s); map 1 from x = 4.4010 m; final (5.9012, -0.0047, 0.86 deg;
// the van floor flat where the robot stands) against 0.019 m, 0.014 m and
// 2.216 deg; max_path_deviation_m 0.0063
// against 0.014.
TEST(RouteScenario, HuskyDrivesTheVanBayRouteAndStopsOnTheWorkPose) {
  const std::string file = ::testing::TempDir() + std::to_string(getpid()) + "_van_route.yaml";
  std::ofstream(file) << R"(name: van_route_flat
duration_s: 32
seed: 1
master: {algorithm: gauss_seidel, step_s: 0.001}
robot:
  model: husky
  pose: {x_m: -1.5, y_m: -1.0, yaw_deg: 0}
control: {compensation: false, period_s: 0.02}
sensors: {default: false}
task:
  type: route
  graph: van_bay
  route: [start, ramp_foot, ramp_top, work]
  speed_mps: 0.3
)";
  loader::Scenario s = loader::LoadScenario(file, {});
  cosim::MetricsObserver metrics(s.metrics);
  RouteObserver route(s);
  s.master->AddObserver(&metrics);
  s.master->AddObserver(&route);
  const cosim::RunResult result = s.master->Run();
  ASSERT_TRUE(result.ok) << result.ErrorText();
  std::map<std::string, double> m;
  for (const auto& [metric, value] : metrics.Results()) m[metric] = value;

  const loader::RouteGraph graph =
      loader::LoadRouteGraphFile(models::ModelsDir() + "/graphs/van_bay.yaml");
  double length = 0.0;
  for (const auto& e : graph.edges) length += models::SegmentArcLength(e.segment, 0.0, 1.0);
  const auto& v = s.system->unit(*s.system->FindUnit("path_follower")).variables();
  const double speed = v.GetReal(*v.Find("speed"));
  const double deceleration = v.GetReal(*v.Find("deceleration"));
  std::cout << "van_route_flat: route " << length << " m, done at " << route.done_s
            << " s, map 1 from x = " << route.map_change_x << " m, final (" << route.x << ", "
            << route.y << ", " << route.yaw << " rad)";
  for (const auto& [metric, value] : m) std::cout << "\n  " << metric << " = " << value;
  std::cout << "\n";

  EXPECT_GE(route.done_s, length / speed);
  EXPECT_LE(route.done_s, length / speed + speed / (2 * deceleration) + 1.0);
  EXPECT_NEAR(route.map_change_x, 4.4, 0.01);
  EXPECT_NEAR(route.x, 5.9, 0.019);
  EXPECT_NEAR(route.y, 0.0, 0.014);
  EXPECT_NEAR(route.yaw, 0.0, 2.216 * M_PI / 180);
  EXPECT_LT(m.at("max_path_deviation_m"), 0.014);  // the deviation from the sampled route
}

}  // namespace
}  // namespace linesim
