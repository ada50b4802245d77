// The worker's walk against its closed form: distances of a trapezoidal
// speed profile, pauses, and the gait's stance feet fixed on the floor.
#include "units/people/worker_unit.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "models/moving_solids.h"

#include "../test_helpers.h"

namespace linesim::people {
namespace {

using test_helpers::Get;
using test_helpers::SetAll;

constexpr cosim::TimeNs kStep = cosim::kNsPerSecond / 100;  // 10 ms

// Steps u from 0 to t_s (a multiple of 10 ms).
void RunTo(WorkerUnit& u, double t_s, cosim::TimeNs& now) {
  const auto end = static_cast<cosim::TimeNs>(std::llround(t_s * 1e9));
  while (now < end) {
    ASSERT_EQ(u.DoStep(now, kStep), cosim::StepResult::kOk);
    now += kStep;
  }
}

// Guards against a speed profile that is not the trapezoid: 1 s standing,
// 4 m at 1.37 m/s with 1 m/s^2 ramps (ramp 1.37 s over v^2 / 2a = 0.93845 m;
// cruise (4 - 1.8769) / 1.37 s), a 3 s pause at the line, 4 m back.
TEST(Worker, TrapezoidDistancesAndPause) {
  WorkerUnit u("w", {{0.0, 0.0}, {0.0, 4.0}, {0.0, 0.0}});
  SetAll(u, "start_time", 1.0);
  SetAll(u, "pause", 3.0);
  u.Setup(0, 0);
  u.Initialize();
  const double v = 1.37, a = 1.0, ramp = v / a, ramp_d = v * v / (2 * a);
  const double walk = 2 * ramp + (4.0 - 2 * ramp_d) / v;
  EXPECT_DOUBLE_EQ(u.SegmentEnd(0), 1.0 + walk);
  EXPECT_DOUBLE_EQ(u.SegmentStart(1), 1.0 + walk + 3.0);
  cosim::TimeNs now = 0;
  RunTo(u, 1.0, now);
  EXPECT_EQ(Get(u, "distance")[0], 0.0);
  // Half a second into the ramp: a t^2 / 2.
  RunTo(u, 1.5, now);
  EXPECT_NEAR(Get(u, "distance")[0], 0.5 * a * 0.25, 1e-12);
  EXPECT_NEAR(Get(u, "speed")[0], 0.5, 1e-12);
  EXPECT_NEAR(Get(u, "pose")[1], 0.125, 1e-12);
  EXPECT_NEAR(Get(u, "pose")[2], M_PI / 2, 1e-12);
  // Cruising.
  RunTo(u, 3.0, now);
  EXPECT_NEAR(Get(u, "speed")[0], v, 1e-12);
  EXPECT_NEAR(Get(u, "distance")[0], ramp_d + v * (2.0 - ramp), 1e-12);
  // At the line for the whole pause: 4 m walked, standing.
  RunTo(u, 1.0 + walk + 0.01, now);
  EXPECT_NEAR(Get(u, "distance")[0], 4.0, 1e-12);
  EXPECT_EQ(Get(u, "speed")[0], 0.0);
  const auto legs_at_line = Get(u, "legs");
  RunTo(u, 1.0 + walk + 2.99, now);
  EXPECT_NEAR(Get(u, "pose")[1], 4.0, 1e-12);
  EXPECT_EQ(Get(u, "legs"), legs_at_line);
  // Standing, the feet side by side across the heading (+y): at x = +-0.1.
  EXPECT_NEAR(legs_at_line[0], -0.1, 1e-12);
  EXPECT_NEAR(legs_at_line[1], 4.0, 1e-12);
  EXPECT_NEAR(legs_at_line[2], 0.1, 1e-12);
  EXPECT_NEAR(legs_at_line[3], 4.0, 1e-12);
  // Back: 8 m in all, heading -y, at waypoint 0.
  RunTo(u, 1.0 + 2 * walk + 3.0 + 0.5, now);
  EXPECT_NEAR(Get(u, "distance")[0], 8.0, 1e-12);
  EXPECT_NEAR(Get(u, "pose")[1], 0.0, 1e-12);
  EXPECT_NEAR(Get(u, "pose")[2], -M_PI / 2, 1e-12);
}

// Guards against legs that slide on the floor or swing in step: the gait
// phase is distance / stride length (1.41 m), a stance foot (60 % of the
// stride, Perry & Burnfield 2010) stays where it was put while the body
// walks on, and the right leg is half a stride behind the left.
TEST(Worker, StanceFootStaysOnTheFloor) {
  WorkerUnit u("w", {{0.0, 0.0}, {10.0, 0.0}});
  u.Setup(0, 0);
  u.Initialize();
  cosim::TimeNs now = 0;
  RunTo(u, 3.0, now);  // cruising at 1.37 m/s
  const double d = Get(u, "distance")[0];
  EXPECT_NEAR(Get(u, "phase")[0], d / 1.41, 1e-12);
  // Wait until the left foot has just touched down (phase fraction small).
  while (Get(u, "phase")[0] - std::floor(Get(u, "phase")[0]) > 0.05) RunTo(u, 1e-9 * now + 0.01, now);
  const auto touch = Get(u, "legs");
  const double phase0 = Get(u, "phase")[0];
  // Within the stance (0.6 stride = 0.846 m = 0.617 s at 1.37 m/s) the left
  // foot does not move; the body does.
  RunTo(u, 1e-9 * now + 0.5, now);
  ASSERT_LT(Get(u, "phase")[0] - phase0, 0.55);
  EXPECT_NEAR(Get(u, "legs")[0], touch[0], 1e-9);
  EXPECT_NEAR(Get(u, "legs")[1], touch[1], 1e-12);
  EXPECT_NEAR(Get(u, "leg_velocities")[0], 0.0, 1e-12);
  // The left foot is ahead of the body at touch-down by stance / 2 strides
  // (0.3 * 1.41 m) less what it walked since phase 0.
  // The legs are leg_spacing (0.2 m) apart across the heading (+y: left).
  EXPECT_NEAR(touch[1] - touch[3], 0.2, 1e-12);
  // Cylinders: left leg, right leg at the legs; torso at the body.
  const auto cyl = Get(u, "cylinders");
  ASSERT_EQ(cyl.size(), 21u);
  EXPECT_EQ(cyl[0], Get(u, "legs")[0]);
  EXPECT_EQ(cyl[7 + 1], Get(u, "legs")[3]);
  EXPECT_EQ(cyl[14], Get(u, "pose")[0]);
  EXPECT_EQ(cyl[4], 0.045);
}

// Guards against leg velocities (what a scanner extrapolates a leg with)
// that are not the legs' motion: at instants in the ramp up, while
// cruising and in the ramp down, leg_velocities equals the central
// difference of legs over +-10 us (truncation h^2 x''' / 6 below 1e-8 m/s
// for accelerations of order 100 m/s^2 in swing; rounding 4 m * 1e-16 /
// 1e-5 s = 4e-11 m/s).
TEST(Worker, LegVelocitiesAreTheLegsMotion) {
  WorkerUnit u("w", {{0.0, 0.0}, {0.0, 4.0}});
  u.Setup(0, 0);
  u.Initialize();
  const cosim::TimeNs h = 10'000;  // 10 us
  for (const double t : {0.5, 2.0, 3.9}) {
    const auto at = static_cast<cosim::TimeNs>(std::llround(t * 1e9));
    ASSERT_EQ(u.DoStep(at - 2 * h, h), cosim::StepResult::kOk);  // outputs at t - h
    const auto before = Get(u, "legs");
    ASSERT_EQ(u.DoStep(at - h, h), cosim::StepResult::kOk);  // at t
    const auto velocity = Get(u, "leg_velocities");
    ASSERT_EQ(u.DoStep(at, h), cosim::StepResult::kOk);  // at t + h
    const auto after = Get(u, "legs");
    for (std::size_t i = 0; i < 4; ++i) {
      EXPECT_NEAR(velocity[i], (after[i] - before[i]) / 2e-5, 1e-6) << "t " << t << " i " << i;
    }
  }
}

// Guards against a leg offset profile that jumps: at the end of swing the
// foot is where the stance starts (+stance/2 strides), at the end of the
// stance at -stance/2; the swing's offset rate integrates to the stance's
// travel.
TEST(Worker, LegOffsetIsContinuous) {
  WorkerUnit u("w", {{0.0, 0.0}});
  u.Setup(0, 0);
  u.Initialize();
  double o = 0, r = 0;
  u.LegOffset(0.0, o, r);
  EXPECT_NEAR(o, 0.3 * 1.41, 1e-12);
  EXPECT_EQ(r, -1.0);
  u.LegOffset(0.6 - 1e-12, o, r);
  EXPECT_NEAR(o, -0.3 * 1.41, 1e-9);
  u.LegOffset(1.0 - 1e-12, o, r);
  EXPECT_NEAR(o, 0.3 * 1.41, 1e-9);
  // Swing: sum of rate * (distance per phase step) over the swing = 0.6 strides.
  double sum = 0.0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    u.LegOffset(0.6 + 0.4 * (i + 0.5) / n, o, r);
    sum += r * 0.4 * 1.41 / n;
  }
  EXPECT_NEAR(sum, 0.6 * 1.41, 1e-6);
}

TEST(Worker, RefusesRepeatedWaypoint) {
  WorkerUnit u("w", {{0.0, 0.0}, {0.0, 0.0}});
  const auto p = u.CheckParameters();
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p[0].variable, "waypoints");
}

// Guards the yielding: a worker walking along +x (from x = 0 to 10 m) and
// a robot (a 1 x 0.6 m body) driving across its way at x = 4 m along +y at
// 0.5 m/s. With stop_distance 0.5 m the worker stops where walking on would
// bring its torso (radius 0.2 m) within 0.5 m of the moving body, waits
// while the robot passes, and walks on where its plan left off (it reaches
// the end later by the time it waited); never closer than stop_distance
// less one step's walk. Without stop_distance (0) it does not wait, and a
// robot that stands (speed 0) does not stop it either.
TEST(Worker, WaitsForAPassingRobot) {
  const auto run = [](double stop_distance, double robot_speed, double& waited,
                      double& closest) {
    WorkerUnit u("w", {{0.0, 0.0}, {10.0, 0.0}}, 1);
    SetAll(u, "stop_distance", stop_distance);
    u.Setup(0, 0);
    u.Initialize();
    closest = 1e9;
    cosim::TimeNs now = 0;
    for (int k = 0; k < 2000; ++k) {
      const double t = k * 0.01;
      // The robot's centre at x = 4 m crosses y = 0 at 3 s.
      const double y = robot_speed > 0.0 ? robot_speed * (t - 3.0) : -0.9;
      test_helpers::SetArray(u, "robots", {4.0, y, 1.5707963267948966, 0.0, robot_speed, 0.0,
                                           1.0, 0.6, 0.0, 0.5});
      ASSERT_EQ(u.DoStep(now, kStep), cosim::StepResult::kOk);
      now += kStep;
      const auto pose = Get(u, "pose");
      const double box[10] = {4.0, y, 1.5707963267948966, 0.0, 0.0, 0.0, 1.0, 0.6, 0.0, 0.5};
      closest = std::min(closest, models::FootprintDistance(box, pose[0], pose[1]) - 0.2);
    }
    waited = Get(u, "time_waited")[0];
    EXPECT_NEAR(Get(u, "pose")[0], 10.0, 1e-9);  // it arrives all the same
  };
  double waited = 0.0, closest = 0.0;
  run(0.5, 0.5, waited, closest);
  EXPECT_GT(waited, 0.5);
  // One 10 ms step at 1.37 m/s is 13.7 mm.
  EXPECT_GT(closest, 0.5 - 0.014);
  run(0.0, 0.5, waited, closest);
  EXPECT_EQ(waited, 0.0);
  EXPECT_LT(closest, 0.0 + 1e-9);  // it walks into the robot's way
  run(0.5, 0.0, waited, closest);
  EXPECT_EQ(waited, 0.0);
}

}  // namespace
}  // namespace linesim::people
