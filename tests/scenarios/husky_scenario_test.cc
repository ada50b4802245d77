// The shipped Husky scenario (paper 2's skid-steer robot), run end to end
// through the real units: the differential path follower, the
// diff_drive_controller, CVODE motors and the ODE chassis with Coulomb
// scrub, crossing the running line between two car bodies.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "cosim/observers.h"
#include "loader/scenario.h"
#include "tests/spread.h"

namespace linesim {
namespace {

// Footprint of the Husky (models/robots/husky.yaml): the 0.9874 m body box
// and the wheels' outer faces, y = 0.2854 + 0.1143 / 2.
constexpr double kHalfLength = 0.9874 / 2;
constexpr double kHalfWidth = 0.2854 + 0.1143 / 2;

// Follows the run: when the follower is done, and how near the robot's
// footprint (its map-frame bounding box, conservative) comes to the car
// bodies, which the belt moves by its travelled distance.
class HuskyObserver : public cosim::Observer {
 public:
  explicit HuskyObserver(const loader::Scenario& s) : scene_(s.scene) {
    probes_ = cosim::ResolveProbes(
        *s.system, {"chassis.position[0]", "chassis.position[1]", "chassis.yaw",
                    "belt.travel[0]", "path_follower.done"});
  }
  void OnSample(cosim::TimeNs t, const cosim::System& system) override {
    double v[5];
    for (std::size_t i = 0; i < 5; ++i) v[i] = cosim::ReadProbe(system, probes_[i]);
    const double time = cosim::NsToSeconds(t);
    if (v[4] != 0.0 && done_s < 0.0) done_s = time;
    const double c = std::abs(std::cos(v[2])), sn = std::abs(std::sin(v[2]));
    const double hx = kHalfLength * c + kHalfWidth * sn, hy = kHalfLength * sn + kHalfWidth * c;
    for (const auto& body : scene_.carried) {
      // The bodies ride the line along +x (direction 0 deg), unrotated.
      const double bx = body.solid.x_m + v[3], by = body.solid.y_m;
      const double gap = std::max(std::abs(v[0] - bx) - hx - 0.5 * body.solid.length_m,
                                  std::abs(v[1] - by) - hy - 0.5 * body.solid.width_m);
      min_gap_m = std::min(min_gap_m, gap);
    }
    if (across_s < 0.0 && v[1] - hy > 1.0) across_s = time;  // fully past the line's far edge
  }

  double done_s = -1.0, across_s = -1.0;
  double min_gap_m = std::numeric_limits<double>::infinity();

 private:
  const models::Scene& scene_;
  std::vector<cosim::Probe> probes_;
};

// Guards the Husky's path following across the line (husky_floor_path.yaml:
// 25 m, two sharp corners, 0.8 m/s):
//  - it reaches the end: done (within goal_tolerance, 2 cm) and the final
//    progress within 3 cm of 25 m, in less than 45 s (about 40 s: 31 s of
//    cruise, three stops and starts at 0.5 m/s^2, two turns in place) of
//    the 50 s run; at 0.5 m/s it had not finished after 60 s (18 m);
//  - the belt carries it sideways at most by what the cross-track loop
//    lets through: the line moves at up to 0.11 m/s (0.10 +10 %), a lateral
//    disturbance velocity d; with the follower's heading law the linearised
//    loop is e'' + k_yaw e' + k_yaw k_cross e = d' + k_yaw d. For a step d
//    and the Husky's k_yaw 3/s, k_cross 0.75/s (a double pole at 1.5/s):
//      e(t) = d/k_cross (1 - e^{-1.5 t}) - d t e^{-1.5 t},
//    monotone, never above d t (no correction) nor d/k_cross (0.147 m). The
//    footprint is on the belt while it crosses the 2 m line plus its own
//    0.99 m length at 0.8 m/s, 3.7 s: e(3.7 s) = 0.145 m;
//  - it crosses between the car bodies: its footprint never touches them
//    (conservative bounding box), and it is across the line before the rear
//    body's front edge (-4.7 + 0.11 t m) could reach it at x = 0.66 m (49 s).
// Seeds 1..8 (the seed draws the belt's speed variation; the sensors are
// off, nothing reads them: every metric the same to the bit, measured at
// seed 5): done_s 39.641 / 39.641 / 39.661; across_s
// 22.719 / 22.722 / 22.727; nearest car body 2.4998 / 2.4999 / 2.4999 m;
// final_progress_m 24.980 / 24.981 / 24.981; max_path_deviation_m 0.1215 /
// 0.1259 / 0.1352 (20 runs, `linesim run --runs 20`: 0.1179 / 0.1269 /
// 0.1351) against the analytic 0.145: within 7 %, since the belt's speed
// nears its +10 % at some seeds and the bound is what the loop reaches at
// that speed; final_path_deviation_m 0.0001 / 0.0002 / 0.0004.
// One seed's run: the observer's numbers, the metrics and the analytic
// bound of the belt's sideways carry (from the run's own parameters).
struct HuskyRun {
  double done_s = -1.0, across_s = -1.0, min_gap_m = 0.0, bound = 0.0;
  std::map<std::string, double> m;
};

HuskyRun RunHusky(int seed) {
  loader::Scenario s =
      loader::LoadScenario(std::string(LINESIM_SOURCE_DIR "/scenarios/husky_floor_path.yaml"),
                           {"seed=" + std::to_string(seed), "sensors.default=false"});
  cosim::MetricsObserver metrics(s.metrics);
  HuskyObserver husky(s);
  s.master->AddObserver(&metrics);
  s.master->AddObserver(&husky);
  const cosim::RunResult result = s.master->Run();
  EXPECT_TRUE(result.ok) << result.ErrorText();
  HuskyRun run;
  for (const auto& [metric, value] : metrics.Results()) run.m[metric] = value;
  run.done_s = husky.done_s;
  run.across_s = husky.across_s;
  run.min_gap_m = husky.min_gap_m;
  std::cout << "husky_floor_path seed " << seed << ": done at " << husky.done_s
            << " s, across the line at " << husky.across_s << " s, nearest car body "
            << husky.min_gap_m << " m";
  for (const auto& [metric, value] : run.m) std::cout << "\n  " << metric << " = " << value;
  std::cout << "\n";

  // The bound's numbers from the run itself: the belt's top speed (nominal
  // + its variation), the follower's gains (a double pole at k_yaw / 2 when
  // k_yaw = 4 k_cross, as the Husky's are), the line's width, the body's
  // length and the cruise speed: 0.145 m for the shipped files.
  const auto param = [&](const char* unit, const char* name) {
    const auto& v = s.system->unit(*s.system->FindUnit(unit)).variables();
    return v.GetReal(*v.Find(name));
  };
  const models::Belt& line = s.scene.belts.at(0);
  const double d = line.nominal_speed_mps * (1.0 + line.speed_variation);
  const double k_cross = param("path_follower", "k_cross");
  const double pole = 0.5 * param("path_follower", "k_yaw");
  EXPECT_NEAR(param("path_follower", "k_yaw"), 4.0 * k_cross, 1e-12);  // the double pole
  const double t_on =
      (line.area.width_m + param("chassis", "body_length")) / param("path_follower", "speed");
  run.bound = d / k_cross * (1.0 - std::exp(-pole * t_on)) - d * t_on * std::exp(-pole * t_on);
  return run;
}

TEST(HuskyScenario, FinishesThePathAndCrossesTheLineBetweenTheBodies) {
  constexpr int kSeeds = 8;
  std::vector<double> done, across, gap, progress, deviation, final_deviation;
  double bound = 0.0;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    const HuskyRun r = RunHusky(seed);
    done.push_back(r.done_s);
    across.push_back(r.across_s);
    gap.push_back(r.min_gap_m);
    progress.push_back(r.m.at("final_progress_m"));
    deviation.push_back(r.m.at("max_path_deviation_m"));
    final_deviation.push_back(r.m.at("final_path_deviation_m"));
    bound = r.bound;
  }
  using test_spread::Print;
  const auto done_s = Print("done_s", done);
  const auto across_s = Print("across_s", across);
  const auto min_gap = Print("min_gap_m", gap);
  const auto final_progress = Print("final_progress_m", progress);
  const auto max_dev = Print("max_path_deviation_m", deviation);
  const auto final_dev = Print("final_path_deviation_m", final_deviation);

  EXPECT_GT(done_s.min(), 0.0);
  EXPECT_LT(done_s.max(), 45.0);
  EXPECT_LT(std::abs(final_progress.min() - 25.0), 0.03);
  EXPECT_LT(std::abs(final_progress.max() - 25.0), 0.03);
  EXPECT_LT(max_dev.max(), bound) << "bound " << bound;
  EXPECT_LT(final_dev.max(), 0.02);
  EXPECT_GT(min_gap.min(), 0.0);
  EXPECT_GT(across_s.min(), 0.0);
  EXPECT_LT(across_s.max(), (0.66 + 4.7) / 0.11);
}

}  // namespace
}  // namespace linesim
