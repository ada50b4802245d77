// The surface fusion (units/estimation/surface_fusion_unit.h): paper 1's
// future work, the belt's velocity from the laser's position against the
// wheel encoders' dead reckoning and from the PX4Flow with the encoders as
// the robot's motion. Noise-free inputs: each case has an exact answer.
#include "units/estimation/surface_fusion_unit.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <vector>

#include "tests/units/test_helpers.h"
#include "units/estimation/steady_state_kalman.h"

namespace linesim::estimation {
namespace {

using cosim::TimeNs;
using test_helpers::Get;
using test_helpers::SetArray;

constexpr TimeNs kMs = 1'000'000;
constexpr TimeNs kStep = 20 * kMs;   // the control period the unit runs at
constexpr TimeNs kMatch = 40 * kMs;  // two S300 at 25 Hz, seen together every other step
constexpr TimeNs kMessage = 100 * kMs;  // px4flow publish_rate 10 Hz

// A rectangle of about the Rob@Work 3's size.
constexpr std::array<std::array<double, 2>, 4> kCorners = {
    {{0.3, 0.25}, {0.3, -0.25}, {-0.3, 0.25}, {-0.3, -0.25}}};
constexpr std::array<std::array<double, 2>, 4> kWheels = {
    {{0.25, 0.2}, {0.25, -0.2}, {-0.25, 0.2}, {-0.25, -0.2}}};

// A floor and one belt along x at y = 0, 2 m wide, 40 m long.
models::Scene Scene() {
  models::Scene s;
  s.surfaces.push_back({"floor", 0.8, 0.3, 3000.0});
  s.surfaces.push_back({"belt", 0.8, 0.3, 3000.0});
  s.floor = {-50, 50, -50, 50, 0};
  models::Belt b;
  b.area = {0.0, 0.0, 40.0, 2.0, 0.0};
  b.surface = 1;
  s.belts.push_back(b);
  return s;
}

std::unique_ptr<SurfaceFusionUnit> Fusion(const models::Scene& scene, double switch_gate = 3.0,
                                          bool imu = false) {
  auto u = std::make_unique<SurfaceFusionUnit>("fusion", 4, 4, scene, imu);
  std::vector<double> sx, sy, wx, wy;
  for (const auto& c : kCorners) {
    sx.push_back(c[0]);
    sy.push_back(c[1]);
  }
  for (const auto& w : kWheels) {
    wx.push_back(w[0]);
    wy.push_back(w[1]);
  }
  SetArray(*u, "sensor_x", sx);
  SetArray(*u, "sensor_y", sy);
  SetArray(*u, "sensor_yaw", {0.0, 0.0, 0.0, 0.0});
  SetArray(*u, "wheel_x", wx);
  SetArray(*u, "wheel_y", wy);
  u->variables().SetReal(*u->variables().Find("switch_gate"), switch_gate);
  return u;
}

// Drives the unit: the robot (heading 0) at `position(t)` in map, its wheels
// rolling at `wheel_speed` along x relative to the surface under them, a
// match every kMatch (referring to the previous step's time, as the matcher's
// match_time lags), flows silent unless `flow` gives the sensor-frame reading.
struct Drive {
  SurfaceFusionUnit& u;
  TimeNs t = 0;
  double matches = 0.0, messages = 0.0;

  template <class Position>
  void Run(TimeNs until, Position position, double wheel_speed,
           const std::array<double, 2>* flow = nullptr) {
    for (; t < until; t += kStep) {
      const auto p = position(t);
      SetArray(u, "position", {p[0], p[1]});
      std::vector<double> wheels(8, 0.0);
      for (int j = 0; j < 4; ++j) wheels[2 * j] = wheel_speed;
      SetArray(u, "wheel_velocity", wheels);
      if (t % kMatch == 0 && t > 0) {
        const TimeNs tm = t - kStep;
        const auto q = position(tm);
        SetArray(u, "laser_position", {q[0], q[1]});
        u.variables().SetReal(*u.variables().Find("match_time"), cosim::NsToSeconds(tm));
        matches += 1.0;
        u.variables().SetReal(*u.variables().Find("match_count"), matches);
      }
      if (flow != nullptr && t % kMessage == 0 && t > 0) {
        std::vector<double> v;
        for (int i = 0; i < 4; ++i) {
          v.push_back((*flow)[0]);
          v.push_back((*flow)[1]);
        }
        SetArray(u, "sensor_velocity", v);
        SetArray(u, "sensor_valid", {1, 1, 1, 1});
        SetArray(u, "sensor_quality", {200, 200, 200, 200});
        messages += 1.0;
        SetArray(u, "sensor_message_count", {messages, messages, messages, messages});
      }
      ASSERT_EQ(u.DoStep(t, kStep), cosim::StepResult::kOk);
    }
  }
};

// A constant belt under a robot whose wheels stand still (encoders 0): the
// laser sees the robot carried at the belt's 0.2 m/s, so position minus
// dead reckoning grows at 0.2 m/s and the belt's estimate converges to it.
// Detector off: a Kalman filter of a constant (a special case of its
// random walk) with exact measurements converges to it; after 2 s of 50
// matches the prior's pull is sigma_p^2 / (sigma_0^2 sum (t - mean t)^2)
// of the step (0.0015^2 / (0.2^2 x 50 x 2^2 / 12) = 3.4e-6 of 0.2 m/s,
// below 1e-6 m/s) plus what the residual's random walk lets the estimate
// wander on exact data (none): 1e-4 m/s holds with a margin.
TEST(SurfaceFusion, ConstantBeltFromLaserAgainstEncodersConverges) {
  const auto scene = Scene();
  auto u = Fusion(scene, 0.0);
  u->Setup(0, 1000'000 * kMs);
  u->Initialize();
  Drive d{*u};
  d.Run(2000 * kMs, [](TimeNs t) { return std::array<double, 2>{0.2 * cosim::NsToSeconds(t), 0.0}; },
        0.0);
  const auto belt = Get(*u, "belt_velocity");
  EXPECT_NEAR(belt[0], 0.2, 1e-4);
  EXPECT_NEAR(belt[1], 0.0, 1e-4);
  // Every wheel is over the belt: each gets it, turned to base_link (yaw 0).
  const auto wheel = Get(*u, "wheel_surface_velocity");
  for (int j = 0; j < 4; ++j) EXPECT_EQ(wheel[2 * j], belt[0]);
  EXPECT_EQ(Get(*u, "switch_count")[0], 0.0);
}

// With the detector on, the same belt restarts the filter at the second
// match beyond the gate, from the least-squares slope of the residuals:
// exact data give the belt's speed at once (to rounding).
TEST(SurfaceFusion, DetectorRestartsFromTheResidualsSlope) {
  const auto scene = Scene();
  auto u = Fusion(scene);
  u->Setup(0, 1000'000 * kMs);
  u->Initialize();
  Drive d{*u};
  // Standing still on the belt at rest for 1 s, then carried at 0.2 m/s.
  constexpr TimeNs kStepAt = 1000 * kMs;
  const auto position = [](TimeNs t) {
    return std::array<double, 2>{t < kStepAt ? 0.0 : 0.2 * cosim::NsToSeconds(t - kStepAt), 0.0};
  };
  d.Run(kStepAt, position, 0.0);
  EXPECT_NEAR(Get(*u, "belt_velocity")[0], 0.0, 1e-9);
  // The detector's time: the innovation of a match tm after the step is
  // 0.2 tm minus what the residual state took of the earlier ones; the gate
  // is 3 sqrt(S), S = P_D + sigma_p^2 + ... = a few mm^2 (sigma_p 1.5 mm):
  // about 6 mm, passed by the first match more than 30 ms after the step;
  // the second beyond it is 40 ms later. Matches every 40 ms: the restart
  // comes within 30 + 40 + 40 ms of the step, plus a step of the unit (20
  // ms): 130 ms. Then the slope is of residuals of which one may lie
  // before the step (biased low); the ramp's process noise lets the next
  // matches correct it: within ramp_time (1 s) the estimate is the belt's
  // to the 2 cm/s, and on exact data to 1 mm/s.
  d.Run(kStepAt + 140 * kMs, position, 0.0);
  EXPECT_EQ(Get(*u, "switch_count")[0], 1.0);
  d.Run(kStepAt + 1000 * kMs, position, 0.0);
  EXPECT_NEAR(Get(*u, "belt_velocity")[0], 0.2, 1e-3);
  EXPECT_NEAR(Get(*u, "belt_velocity")[1], 0.0, 1e-3);
}

// A robot driving over the floor: the wheels roll at 0.3 m/s and the laser
// sees it move at 0.25 m/s (it slips: the encoders overstate it). No wheel
// is over the belt, so the residual's drift has no belt term (M = 0): the
// belt's estimate and its correlation with the residual stay exactly 0,
// whatever the residual does; its sigma grows as the random walk alone,
// sqrt(sigma_0^2 + q t).
TEST(SurfaceFusion, WheelsOverTheFloorContributeNothing) {
  const auto scene = Scene();
  auto u = Fusion(scene);
  u->Setup(0, 1000'000 * kMs);
  u->Initialize();
  Drive d{*u};
  constexpr double kY = 5.0;  // the floor beside the 2 m belt
  d.Run(2000 * kMs,
        [](TimeNs t) { return std::array<double, 2>{0.25 * cosim::NsToSeconds(t), kY}; }, 0.3);
  EXPECT_EQ(Get(*u, "belt_velocity")[0], 0.0);
  EXPECT_EQ(Get(*u, "belt_velocity")[1], 0.0);
  for (double w : Get(*u, "wheel_surface_velocity")) EXPECT_EQ(w, 0.0);
  for (double w : Get(*u, "wheel_on_belt")) EXPECT_EQ(w, 0.0);
  const double q = 0.0105 * 0.0105;  // belt_random_walk^2 (paper 1)
  EXPECT_NEAR(Get(*u, "belt_sigma")[0], std::sqrt(0.2 * 0.2 + q * 2.0), 1e-9);
}

// The flow alone: the robot stands on the floor, its front sensors over a
// narrow belt moving at 0.1 m/s along x that no wheel is on; each reads
// the surface relative to itself, 0.1 m/s (the encoders: at rest). With
// no wheel on the belt the flow measures it with H = I. The time-varying
// gain from the prior is never below the steady-state one of the flow's
// scalar filter (paper 1's figures per 0.1 s message: K = 0.1051), four
// sensors per message only raise it: after 5 s (50 messages) the error is
// at most 0.1 (1 - K)^50 = 3.9e-4 m/s.
TEST(SurfaceFusion, FlowMeasuresABeltNoWheelIsOn) {
  models::Scene scene = Scene();
  // A belt across x ahead of the wheels (x = +-0.25): x in [0.75, 0.85].
  scene.belts[0].area = {0.8, 0.0, 0.1, 10.0, 0.0};
  auto u = Fusion(scene);
  // Front sensors at x = 0.8 (over the belt), rear ones far behind.
  SetArray(*u, "sensor_x", {0.8, 0.8, -0.8, -0.8});
  u->Setup(0, 1000'000 * kMs);
  u->Initialize();
  Drive d{*u};
  // The robot stands (it would carry the sensors off a narrow belt):
  // encoders 0, laser still; the belt moves at 0.1 under the front sensors.
  const std::array<double, 2> flow = {0.1, 0.0};
  d.Run(5100 * kMs, [](TimeNs) { return std::array<double, 2>{0.0, 0.0}; }, 0.0, &flow);
  const double k = SteadyStateKalman((0.01 / 3) * (0.01 / 3), 0.03 * 0.03).gain();
  const double bound = 0.1 * std::pow(1.0 - k, 50);
  EXPECT_NEAR(Get(*u, "belt_velocity")[0], 0.1, bound);
  EXPECT_NEAR(Get(*u, "belt_velocity")[1], 0.0, bound);
  // The sensors over the belt report it, the others 0.
  const auto sensors = Get(*u, "sensor_surface_velocity");
  EXPECT_EQ(sensors[0], Get(*u, "belt_velocity")[0]);
  EXPECT_EQ(sensors[4], 0.0);
}

// Save and restore: a restored unit continues bit for bit.
// The IMU: a robot standing on the belt (wheels still) while the belt
// starts with a ramp of 0.5 m/s^2 (the scenes' acceleration_mps2) to 0.2
// m/s; the laser sees it carried, the accelerometer feels the ramp, with a
// constant bias of 0.02 m/s^2 on x (inside the ADIS16470's 5 mg turn-on
// sigma) that the 2 s of a standing belt let the filter learn (over the
// standing belt W = b: b' = R beta is observed). The unit steps at the
// IMU's 10 ms. Detection: W's innovation is the belt's velocity less the
// estimate, against 3 sqrt(S) with S about r = dead_reckoning_noise^2 / h
// = 1e-4 (m/s)^2: 3 cm/s, which the ramp passes at 0.06 s; two samples
// beyond it (switch_samples 2): 0.08 s; the reopened belt takes the next W
// (gain 0.04 / (0.04 + 1e-4)): by 0.1 s the estimate is the belt's within
// one step of the ramp (5 mm/s) and the bias's error. Asserted from 0.15 s
// on: within 2 cm/s (the settling band). Without the IMU the same
// laser data leave the estimate at 0.15 s further behind than that (the
// matches need 0.13 s to restart it: see DetectorRestarts... above).
TEST(SurfaceFusion, TheImuFeelsABeltStartBeforeTheLaserSeesIt) {
  constexpr TimeNs kImuStep = 10 * kMs;
  constexpr TimeNs kRampAt = 2000 * kMs;
  constexpr double kAccel = 0.5, kTop = 0.2, kBias = 0.02;
  const auto belt_speed = [&](TimeNs t) {
    const double s = cosim::NsToSeconds(t - kRampAt);
    return t < kRampAt ? 0.0 : std::min(kTop, kAccel * s);
  };
  const auto belt_travel = [&](TimeNs t) {
    const double s = cosim::NsToSeconds(t - kRampAt), ramp = kTop / kAccel;
    if (t < kRampAt) return 0.0;
    return s < ramp ? 0.5 * kAccel * s * s : 0.5 * kAccel * ramp * ramp + kTop * (s - ramp);
  };
  const auto scene = Scene();
  for (bool imu : {true, false}) {
    auto u = Fusion(scene, 3.0, imu);
    u->Setup(0, 1000'000 * kMs);
    u->Initialize();
    double matches = 0.0, worst_after = 0.0, error_at = 0.0;
    for (TimeNs t = 0; t < kRampAt + 1000 * kMs; t += kImuStep) {
      SetArray(*u, "position", {belt_travel(t), 0.0});
      SetArray(*u, "wheel_velocity", std::vector<double>(8, 0.0));
      if (imu) {
        // The sample at t: the mean acceleration over the IMU's last
        // interval, plus the bias.
        const double a = (belt_speed(t) - belt_speed(t - kImuStep)) / cosim::NsToSeconds(kImuStep);
        SetArray(*u, "imu_acceleration", {a + kBias, 0.0, 9.80665});
      }
      if (t % kMatch == 0 && t > 0) {
        const TimeNs tm = t - kStep;
        SetArray(*u, "laser_position", {belt_travel(tm), 0.0});
        u->variables().SetReal(*u->variables().Find("match_time"), cosim::NsToSeconds(tm));
        matches += 1.0;
        u->variables().SetReal(*u->variables().Find("match_count"), matches);
      }
      ASSERT_EQ(u->DoStep(t, kImuStep), cosim::StepResult::kOk);
      const TimeNs end = t + kImuStep;
      const double error = std::abs(Get(*u, "belt_velocity")[0] - belt_speed(end));
      if (end == kRampAt + 150 * kMs) error_at = error;
      if (end >= kRampAt + 150 * kMs) worst_after = std::max(worst_after, error);
      if (imu && end == kRampAt) {
        EXPECT_NEAR(Get(*u, "belt_velocity")[0], 0.0, 0.005) << "the bias is not the belt";
      }
    }
    if (imu) {
      EXPECT_LT(worst_after, 0.02) << "with the IMU";
      EXPECT_GE(Get(*u, "switch_count")[0], 1.0);
    } else {
      EXPECT_GT(error_at, 0.02) << "the laser alone is slower";
    }
  }
}

TEST(SurfaceFusion, RestoredStateContinuesIdentically) {
  const auto scene = Scene();
  auto a = Fusion(scene);
  a->Setup(0, 1000'000 * kMs);
  a->Initialize();
  Drive da{*a};
  const auto position = [](TimeNs t) {
    return std::array<double, 2>{0.1 * cosim::NsToSeconds(t), 0.0};
  };
  da.Run(500 * kMs, position, 0.0);
  cosim::UnitState saved = a->SaveState();
  da.Run(1000 * kMs, position, 0.0);
  const auto expected = Get(*a, "belt_velocity");
  a->RestoreState(saved);
  Drive db{*a, 500 * kMs, 12.0, 0.0};
  db.Run(1000 * kMs, position, 0.0);
  EXPECT_EQ(Get(*a, "belt_velocity"), expected);
}

}  // namespace
}  // namespace linesim::estimation
