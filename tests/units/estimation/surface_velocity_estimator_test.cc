// The surface velocity estimator (units/estimation/surface_velocity_estimator.h):
// paper 1 (Unhelkar et al., ICRA 2014) Sec. IV-A.
#include "units/estimation/surface_velocity_estimator.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "config/unit_registry.h"
#include "config/yaml_reader.h"
#include "tests/spread.h"
#include "tests/units/test_helpers.h"
#include "units/estimation/steady_state_kalman.h"
#include "units/sensors/px4flow_unit.h"

namespace linesim::estimation {
namespace {

using cosim::TimeNs;
using test_helpers::Get;
using test_helpers::SetAll;
using test_helpers::SetArray;

constexpr TimeNs kMs = 1'000'000;
constexpr TimeNs kStep = 20 * kMs;      // the control period the estimator runs at
constexpr TimeNs kMessage = 100 * kMs;  // px4flow publish_rate 10 Hz
constexpr double kPi = std::numbers::pi;

// Paper 1: four PX4Flow at the corners of the Rob@Work 3's rectangular
// planform, 0.1841 m above the floor. The corner and wheel coordinates are
// a rectangle of about its size (the exact numbers do not matter here).
constexpr std::array<std::array<double, 2>, 4> kCorners = {
    {{0.3, 0.25}, {0.3, -0.25}, {-0.3, 0.25}, {-0.3, -0.25}}};
constexpr std::array<std::array<double, 2>, 4> kWheels = {
    {{0.25, 0.2}, {0.25, -0.2}, {-0.25, 0.2}, {-0.25, -0.2}}};
constexpr double kHeight = 0.1841;

// A floor and one belt along x at y = 0, `width` wide, 40 m long (or none).
models::Scene Scene(double width, bool belt = true) {
  models::Scene s;
  s.surfaces.push_back({"floor", 0.8, 0.3, 3000.0});
  s.surfaces.push_back({"belt", 0.8, 0.3, 3000.0});
  s.floor = {-50, 50, -50, 50, 0};
  if (belt) {
    models::Belt b;
    b.area = {0.0, 0.0, 40.0, width, 0.0};
    b.surface = 1;
    s.belts.push_back(b);
  }
  return s;
}

std::unique_ptr<SurfaceVelocityEstimator> Estimator(const models::Scene& scene,
                                                    const std::array<double, 4>& mount_yaw) {
  auto e = std::make_unique<SurfaceVelocityEstimator>("est", 4, 4, scene);
  std::vector<double> sx, sy, wx, wy;
  for (const auto& c : kCorners) {
    sx.push_back(c[0]);
    sy.push_back(c[1]);
  }
  for (const auto& w : kWheels) {
    wx.push_back(w[0]);
    wy.push_back(w[1]);
  }
  SetArray(*e, "sensor_x", sx);
  SetArray(*e, "sensor_y", sy);
  SetArray(*e, "sensor_yaw", {mount_yaw.begin(), mount_yaw.end()});
  SetArray(*e, "wheel_x", wx);
  SetArray(*e, "wheel_y", wy);
  e->Setup(0, 1000'000 * kMs);
  e->Initialize();
  return e;
}

// The robot's motion and what the sensors send, as the estimator's inputs.
struct Motion {
  double x = 0.0, y = 0.0, yaw = 0.0, vx = 0.0, vy = 0.0, w = 0.0;
};

void SetPose(SurfaceVelocityEstimator& e, const Motion& m) {
  SetArray(e, "position", {m.x, m.y});
  SetAll(e, "yaw", m.yaw);
  SetArray(e, "velocity", {m.vx, m.vy});
  SetAll(e, "yaw_rate", m.w);
}

// What a PX4Flow at corner i (mount yaw `mount`) measures over a surface
// moving at (ux, uy) in map: the surface relative to the sensor point
// (v + omega x r), in the sensor frame (paper 1 Eq. 2 solved for the
// measurement).
std::array<double, 2> Measurement(const Motion& m, std::size_t i, double mount, double ux,
                                  double uy) {
  const double c = std::cos(m.yaw), s = std::sin(m.yaw);
  const double rx = c * kCorners[i][0] - s * kCorners[i][1];
  const double ry = s * kCorners[i][0] + c * kCorners[i][1];
  const double relx = ux - (m.vx - m.w * ry), rely = uy - (m.vy + m.w * rx);
  const double a = m.yaw + mount;
  return {std::cos(a) * relx + std::sin(a) * rely, -std::sin(a) * relx + std::cos(a) * rely};
}

// Map point of a base_link point.
std::array<double, 2> ToMap(const Motion& m, const std::array<double, 2>& p) {
  const double c = std::cos(m.yaw), s = std::sin(m.yaw);
  return {m.x + c * p[0] - s * p[1], m.y + s * p[0] + c * p[1]};
}

// Synthetic sensor outputs: every sensor over the belt |y| <= half_width
// sees (belt_vx, 0) plus `noise`, the others the floor; one message per
// 100 ms, with the given validity and quality per sensor.
struct Feed {
  double half_width = 0.5;
  double belt_vx = 0.1;
  std::array<double, 4> mount = {0, 0, 0, 0};
  std::array<double, 4> valid = {1, 1, 1, 1};
  std::array<double, 4> quality = {200, 200, 200, 200};
  std::array<double, 4> bias = {0, 0, 0, 0};  // added to the belt's speed per sensor
  std::array<double, 4> count = {0, 0, 0, 0};
  std::array<bool, 4> silent = {false, false, false, false};  // no messages at all
  std::vector<double> velocity = std::vector<double>(8, 0.0);

  // Called at every estimator step time t: a message at each multiple of
  // 100 ms (the px4flow publishes at t = k * 100 ms, seen at that step).
  void Apply(SurfaceVelocityEstimator& e, const Motion& m, TimeNs t, double sigma = 0.0,
             std::mt19937_64* rng = nullptr) {
    const bool message = t > 0 && t % kMessage == 0;
    for (std::size_t i = 0; i < 4; ++i) {
      if (!message || silent[i]) continue;
      count[i] += 1.0;
      if (valid[i] == 0.0) continue;  // the px4flow holds its velocity
      const auto p = ToMap(m, kCorners[i]);
      const double u = std::abs(p[1]) <= half_width ? belt_vx + bias[i] : 0.0;
      auto z = Measurement(m, i, mount[i], u, 0.0);
      if (rng) {
        std::normal_distribution<double> n(0.0, sigma);
        z[0] += n(*rng);
        z[1] += n(*rng);
      }
      velocity[2 * i] = z[0];
      velocity[2 * i + 1] = z[1];
    }
    SetArray(e, "sensor_velocity", velocity);
    SetArray(e, "sensor_valid", {valid.begin(), valid.end()});
    SetArray(e, "sensor_quality", {quality.begin(), quality.end()});
    SetArray(e, "sensor_message_count", {count.begin(), count.end()});
    SetPose(e, m);
  }
};

void Step(SurfaceVelocityEstimator& e, TimeNs t, TimeNs dt = kStep) {
  ASSERT_EQ(e.DoStep(t, dt), cosim::StepResult::kOk) << e.last_error();
}

// Four REAL px4flow units at the corners, stepped at 1 ms with the true
// motion, and their outputs handed to the estimator as the assembly wires
// them.
struct RealFlows {
  std::vector<std::unique_ptr<sensors::Px4FlowUnit>> units;
  std::vector<double> velocity = std::vector<double>(8), valid = std::vector<double>(4),
                      quality = std::vector<double>(4), count = std::vector<double>(4);

  RealFlows(const models::Scene& scene, const std::array<double, 4>& mounts, std::uint64_t seed) {
    for (std::size_t i = 0; i < 4; ++i) {
      auto u = std::make_unique<sensors::Px4FlowUnit>("flow" + std::to_string(i), scene,
                                                      seed + i);
      SetAll(*u, "mount_x", kCorners[i][0]);
      SetAll(*u, "mount_y", kCorners[i][1]);
      SetAll(*u, "mount_height", kHeight);
      SetAll(*u, "mount_yaw", mounts[i]);
      u->Setup(0, 1000'000 * kMs);
      u->Initialize();
      units.push_back(std::move(u));
    }
  }

  // One control period from t; `belt` (m/s along x) when the scene has one.
  template <typename Truth>
  void Advance(TimeNs t, const Truth& truth, std::optional<double> belt = std::nullopt) {
    for (TimeNs tf = t; tf < t + kStep; tf += kMs) {
      const Motion m = truth(tf);
      for (auto& u : units) {
        SetArray(*u, "position", {m.x, m.y});
        SetAll(*u, "yaw", m.yaw);
        SetArray(*u, "linear_velocity", {m.vx, m.vy});
        SetAll(*u, "yaw_rate", m.w);
        SetArray(*u, "angular_velocity", {0.0, 0.0, m.w});
        if (belt) SetArray(*u, "belt_velocity", {*belt, 0.0});
        ASSERT_EQ(u->DoStep(tf, kMs), cosim::StepResult::kOk);
      }
    }
  }

  void Feed(SurfaceVelocityEstimator& e) {
    for (std::size_t i = 0; i < 4; ++i) {
      const auto v = Get(*units[i], "velocity");
      velocity[2 * i] = v[0];
      velocity[2 * i + 1] = v[1];
      valid[i] = Get(*units[i], "valid")[0];
      quality[i] = Get(*units[i], "quality")[0];
      count[i] = Get(*units[i], "message_count")[0];
    }
    SetArray(e, "sensor_velocity", velocity);
    SetArray(e, "sensor_valid", valid);
    SetArray(e, "sensor_quality", quality);
    SetArray(e, "sensor_message_count", count);
  }
};

// ---------------------------------------------------------------------------

// Guards against a gain typed in or solved from the wrong variances: the
// unit's kalman_gain is the closed-form Riccati solution for its defaults,
// paper 1's 3 sigma = 1 cm/s per sample and sigma = 3 cm/s (K = 0.1051).
TEST(SurfaceVelocityEstimator, GainFromThePapersNoiseFigures) {
  auto e = Estimator(Scene(1.0), {0, 0, 0, 0});
  EXPECT_DOUBLE_EQ(Get(*e, "kalman_gain")[0],
                   SteadyStateKalman::Gain((0.01 / 3) * (0.01 / 3), 0.03 * 0.03));
  EXPECT_NEAR(Get(*e, "kalman_gain")[0], 0.1051, 1e-4);
  SetAll(*e, "measurement_sigma", 0.01);
  e->Initialize();
  EXPECT_DOUBLE_EQ(Get(*e, "kalman_gain")[0],
                   SteadyStateKalman::Gain((0.01 / 3) * (0.01 / 3), 0.01 * 0.01));
}

// Guards against Eq. 2 without omega x r, without the mount rotation or
// with the robot's velocity in the wrong frame. Four REAL px4flow units
// (mounts turned 0, 90, 180 and -45 deg) look at a still floor while the
// robot turns at 0.5 rad/s and translates at (0.15, -0.05) m/s in map; the
// estimator gets their outputs and the true motion. The absolute surface
// velocity must be 0 to within the sensor's quantization: the firmware's
// half-pixel flow step (flow.c: sub-pixel search on a half-pixel grid)
// converted to m/s, 0.5 px * h / f * frame_rate = 0.5 * 0.1841 / 666.7 *
// 400 = 0.0552 m/s. Leaving out omega x r would be off by 0.5 * 0.39 =
// 0.195 m/s, a wrong mount by up to twice the sensor's speed. Seeds 1..8
// (units seeded 10 seed + i), the largest |raw| over the quantum: 0.413 /
// 0.421 / 0.426.
TEST(SurfaceVelocityEstimator, Eq2GivesZeroOnAStillFloorWhileTurning) {
  const models::Scene scene = Scene(1.0, /*belt=*/false);
  const std::array<double, 4> mounts = {0.0, kPi / 2, kPi, -kPi / 4};
  const double f = 666.7, frame_rate = 400.0;  // the px4flow's defaults (px4flow_unit.h)
  const double quantum = 0.5 * kHeight / f * frame_rate;
  EXPECT_NEAR(quantum, 0.0552, 1e-4);
  std::vector<double> worsts;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    auto e = Estimator(scene, mounts);
    RealFlows flows(scene, mounts, 10 * seed);

    const double w = 0.5, vx = 0.15, vy = -0.05;
    const auto truth = [&](TimeNs t) {
      const double ts = cosim::NsToSeconds(t);
      return Motion{vx * ts, vy * ts + 5.0, 0.3 + w * ts, vx, vy, w};
    };
    int checked = 0;
    double worst = 0.0;
    for (TimeNs t = 0; t < 6000 * kMs; t += kStep) {
      // The sensors step at 1 ms with the truth at each step's start.
      flows.Advance(t, truth);
      const TimeNs te = t + kStep;
      flows.Feed(*e);
      SetPose(*e, truth(te));
      Step(*e, te);
      if (te % kMessage != 0 || te < 2 * kMessage) continue;  // from the 2nd message on
      const auto raw = Get(*e, "raw_surface_velocity");
      const auto status = Get(*e, "sensor_status");
      for (std::size_t i = 0; i < 4; ++i) {
        ASSERT_EQ(flows.valid[i], 1.0) << "sensor " << i << " at " << te;
        EXPECT_EQ(status[i], 0.0);
        EXPECT_NEAR(raw[2 * i], 0.0, quantum) << "sensor " << i << " at " << te;
        EXPECT_NEAR(raw[2 * i + 1], 0.0, quantum) << "sensor " << i << " at " << te;
        worst = std::max({worst, std::abs(raw[2 * i]), std::abs(raw[2 * i + 1])});
        ++checked;
      }
    }
    EXPECT_EQ(checked, 4 * 59);
    // Filtered (the floor over the floor): within the same bound.
    for (double v : Get(*e, "filtered_surface_velocity")) EXPECT_NEAR(v, 0.0, quantum);
    for (double v : Get(*e, "wheel_surface_velocity")) EXPECT_EQ(v, 0.0);
    worsts.push_back(worst / quantum);
  }
  test_spread::Print("largest |raw| on the still floor / quantum", worsts);
}

// Guards against the wheel rule: the paper's wheels over the belt take the
// mean of the sensors over the belt, the others 0, in base_link. The robot
// stands across the belt's edge, turned 30 deg, so that two corners and two
// wheels are over the belt (checked from the geometry here); the two belt
// sensors measure 0.10 and 0.12 m/s (noise-free), so the rigid belt's
// estimate is their mean 0.11 m/s along map x (a filter started at its
// first measurement stays there on constant input: x + K (z - x) = z).
TEST(SurfaceVelocityEstimator, StraddlingWheelsTakeTheBeltSensorsMean) {
  auto e = Estimator(Scene(1.0), {0, 0, 0, 0});
  Motion m;
  m.yaw = kPi / 6;
  m.y = 0.5;
  Feed feed;
  std::array<bool, 4> sensor_on{}, wheel_on{};
  int sensors_on = 0, wheels_on = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    sensor_on[i] = std::abs(ToMap(m, kCorners[i])[1]) <= 0.5;
    wheel_on[i] = std::abs(ToMap(m, kWheels[i])[1]) <= 0.5;
    sensors_on += sensor_on[i];
    wheels_on += wheel_on[i];
  }
  ASSERT_EQ(sensors_on, 2);
  ASSERT_EQ(wheels_on, 2);
  double expected = 0.0;
  bool first = true;
  for (std::size_t i = 0; i < 4; ++i) {
    if (!sensor_on[i]) continue;
    feed.bias[i] = first ? 0.0 : 0.02;
    expected += 0.5 * (0.1 + feed.bias[i]);
    first = false;
  }
  for (TimeNs t = 0; t <= 2000 * kMs; t += kStep) {
    feed.Apply(*e, m, t);
    Step(*e, t);
  }
  const auto wheel = Get(*e, "wheel_surface_velocity");
  const auto on = Get(*e, "wheel_on_belt");
  const auto source = Get(*e, "wheel_source");
  const auto sensor_belt = Get(*e, "sensor_on_belt");
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(sensor_belt[i], sensor_on[i] ? 1.0 : 0.0) << i;
    EXPECT_EQ(on[i], wheel_on[i] ? 1.0 : 0.0) << i;
    EXPECT_EQ(source[i], wheel_on[i] ? 1.0 : 0.0) << i;
    // (expected, 0) in map is (c e, -s e) in base_link.
    const double bx = wheel_on[i] ? std::cos(m.yaw) * expected : 0.0;
    const double by = wheel_on[i] ? -std::sin(m.yaw) * expected : 0.0;
    EXPECT_NEAR(wheel[2 * i], bx, 1e-12) << i;
    EXPECT_NEAR(wheel[2 * i + 1], by, 1e-12) << i;
  }
  // The floor sensors see the floor: 0.
  const auto filtered = Get(*e, "filtered_surface_velocity");
  for (std::size_t i = 0; i < 4; ++i) {
    if (!sensor_on[i]) {
      EXPECT_NEAR(std::hypot(filtered[2 * i], filtered[2 * i + 1]), 0.0, 1e-12);
    }
  }
}

// Guards against a filter that does not settle on the belt's velocity, or
// a wheel value in the wrong frame: four REAL px4flow units over a belt at
// 0.15 m/s, the robot driving along it at 0.1 m/s while turning slowly
// (0.1 rad/s). After the filter settles (3 s: 30 messages, (1 - K)^30 =
// 0.04 of the start left) every wheel gets the belt's velocity in base_link
// to within the firmware's rounding bound, a quarter pixel per frame
// (round to the half-pixel grid): 0.25 * 0.1841 / 666.7 * 400 = 0.0276 m/s.
// Seeds 1..8 (units seeded 10 seed + i), the largest error over the bound:
// 0.566 / 0.568 / 0.570.
TEST(SurfaceVelocityEstimator, BeltVelocityAfterTheFilterSettles) {
  const models::Scene scene = Scene(1.4);
  const std::array<double, 4> mounts = {0.0, kPi / 2, kPi, -kPi / 4};
  std::vector<double> worsts;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    auto e = Estimator(scene, mounts);
    RealFlows flows(scene, mounts, 10 * seed);
    double worst = 0.0;
    const double belt = 0.15, bound = 0.25 * kHeight / 666.7 * 400.0;
    const auto truth = [&](TimeNs t) {
      const double ts = cosim::NsToSeconds(t);
      return Motion{-2.0 + 0.1 * ts, 0.0, 0.1 * ts, 0.1, 0.0, 0.1};
    };
    for (TimeNs t = 0; t < 6000 * kMs; t += kStep) {
      flows.Advance(t, truth, belt);
      const TimeNs te = t + kStep;
      flows.Feed(*e);
      const Motion m = truth(te);
      SetPose(*e, m);
      Step(*e, te);
      if (te < 3000 * kMs) continue;
      const auto wheel = Get(*e, "wheel_surface_velocity");
      const auto source = Get(*e, "wheel_source");
      const double c = std::cos(m.yaw), s = std::sin(m.yaw);
      for (std::size_t j = 0; j < 4; ++j) {
        ASSERT_EQ(source[j], 1.0) << j;
        EXPECT_NEAR(wheel[2 * j], c * belt, bound) << j << " at " << te;
        EXPECT_NEAR(wheel[2 * j + 1], -s * belt, bound) << j << " at " << te;
        worst = std::max(
            {worst, std::abs(wheel[2 * j] - c * belt), std::abs(wheel[2 * j + 1] + s * belt)});
      }
    }
    worsts.push_back(worst / bound);
    const auto filtered = Get(*e, "filtered_surface_velocity");
    std::printf("filtered at 6 s: (%.4f %.4f) (%.4f %.4f) (%.4f %.4f) (%.4f %.4f), belt 0.15\n",
                filtered[0], filtered[1], filtered[2], filtered[3], filtered[4], filtered[5],
                filtered[6], filtered[7]);
  }
  test_spread::Print("largest wheel error after 3 s / the rounding bound", worsts);
}

// Guards against the fallbacks: with all four sensors over a belt at 0.1
// m/s, sensor 0's messages turn to quality 0 at 2 s: it is held (status 1)
// and its value decays as x_hold exp(-(t - t_hold) / hold_time_constant)
// (the unit's stated law, applied per step), while the wheels keep taking
// the fresh sensors (source 1). When every sensor turns invalid the wheels
// take the held values (source 2), and stale_after (2 s) after each
// sensor's last valid message it gives no estimate (status 2), the wheels
// source 3 and 0.
TEST(SurfaceVelocityEstimator, FallbacksHoldDecayAndGoStale) {
  auto e = Estimator(Scene(1.4), {0, 0, 0, 0});
  Motion m;  // at rest over the belt's middle
  Feed feed;
  feed.half_width = 0.7;
  TimeNs t = 0;
  for (; t <= 2000 * kMs; t += kStep) {
    feed.Apply(*e, m, t);
    Step(*e, t);
  }
  // t = 2.02 s now; all fresh at 0.1.
  for (double s : Get(*e, "sensor_status")) EXPECT_EQ(s, 0.0);
  const double x_hold = Get(*e, "filtered_surface_velocity")[0];
  EXPECT_NEAR(x_hold, 0.1, 1e-12);
  feed.valid[0] = 0.0;
  feed.quality[0] = 0.0;
  const double tau = 1.0;  // hold_time_constant default
  TimeNs t_hold = -1;
  for (; t <= 3000 * kMs; t += kStep) {
    feed.Apply(*e, m, t);
    Step(*e, t);
    const double status = Get(*e, "sensor_status")[0];
    if (t_hold < 0 && status == 1.0) t_hold = t;  // decays from the start of this step
    if (t_hold < 0) {
      EXPECT_EQ(status, 0.0);
      continue;
    }
    EXPECT_EQ(status, 1.0);
    const double held = cosim::NsToSeconds(t + kStep - t_hold);
    EXPECT_NEAR(Get(*e, "filtered_surface_velocity")[0], x_hold * std::exp(-held / tau), 1e-12);
    for (double s : Get(*e, "wheel_source")) EXPECT_EQ(s, 1.0);
    for (std::size_t j = 0; j < 4; ++j) {
      EXPECT_NEAR(Get(*e, "wheel_surface_velocity")[2 * j], 0.1, 1e-12);
    }
  }
  // The first invalid message is the one at 2.1 s.
  EXPECT_EQ(t_hold, 2100 * kMs);
  // Every sensor invalid from 3.1 s on: all held, the wheels take the held mean.
  feed.valid = {0, 0, 0, 0};
  feed.quality = {0, 0, 0, 0};
  bool saw_held_wheels = false, saw_stale = false;
  for (; t <= 6000 * kMs; t += kStep) {
    feed.Apply(*e, m, t);
    Step(*e, t);
    const auto status = Get(*e, "sensor_status");
    const auto source = Get(*e, "wheel_source");
    const auto filtered = Get(*e, "filtered_surface_velocity");
    // Sensor 0's last valid message was at 2.0 s: stale from 4.0 s.
    EXPECT_EQ(status[0], t >= 4000 * kMs ? 2.0 : 1.0) << t;
    // The others' last valid message at 3.0 s: held from 3.1 s, stale from 5 s.
    const double others = t < 3100 * kMs ? 0.0 : (t < 5000 * kMs ? 1.0 : 2.0);
    for (std::size_t i = 1; i < 4; ++i) EXPECT_EQ(status[i], others) << t;
    if (others == 1.0) {
      saw_held_wheels = true;
      double mean = 0.0, n = 0.0;
      for (std::size_t i = 0; i < 4; ++i) {
        if (status[i] == 1.0) {
          mean += filtered[2 * i];
          n += 1.0;
        }
      }
      for (std::size_t j = 0; j < 4; ++j) {
        EXPECT_EQ(source[j], 2.0) << t;
        EXPECT_NEAR(Get(*e, "wheel_surface_velocity")[2 * j], mean / n, 1e-12) << t;
      }
    }
    if (others == 2.0) {
      saw_stale = true;
      for (std::size_t j = 0; j < 4; ++j) {
        EXPECT_EQ(source[j], 3.0) << t;
        EXPECT_EQ(Get(*e, "wheel_surface_velocity")[2 * j], 0.0) << t;
      }
      for (double v : filtered) EXPECT_EQ(v, 0.0);
    }
  }
  EXPECT_TRUE(saw_held_wheels);
  EXPECT_TRUE(saw_stale);
  // Valid again: the filter starts from its first measurement (status 0).
  feed.valid = {1, 1, 1, 1};
  feed.quality = {200, 200, 200, 200};
  for (; t <= 6200 * kMs; t += kStep) {
    feed.Apply(*e, m, t);
    Step(*e, t);
  }
  for (double s : Get(*e, "sensor_status")) EXPECT_EQ(s, 0.0);
  EXPECT_NEAR(Get(*e, "wheel_surface_velocity")[0], 0.1, 1e-12);
}

// Guards against a sensor whose messages stop altogether staying fresh: a
// valid message overdue by half a period (1.5 sample_period after the last
// one, plus the step) holds it.
TEST(SurfaceVelocityEstimator, SilentSensorIsHeld) {
  auto e = Estimator(Scene(1.4), {0, 0, 0, 0});
  Motion m;
  Feed feed;
  feed.half_width = 0.7;
  TimeNs t = 0;
  for (; t <= 1000 * kMs; t += kStep) {
    feed.Apply(*e, m, t);
    Step(*e, t);
  }
  feed.silent[2] = true;  // last message at 1.0 s
  for (; t <= 1200 * kMs; t += kStep) {
    feed.Apply(*e, m, t);
    Step(*e, t);
    // Held once t - 1.0 s > 150 ms + 20 ms: from t = 1.18 s.
    EXPECT_EQ(Get(*e, "sensor_status")[2], t > 1170 * kMs ? 1.0 : 0.0) << t;
  }
}

// Guards against a corner reaching the belt lagging behind: when the map
// moves a sensor from the floor onto the belt, its filter restarts from the
// fresh estimate of the sensors already over the belt, at once (before its
// own first message there), instead of climbing from 0 with the filter's
// 0.9 s time constant.
TEST(SurfaceVelocityEstimator, SensorReachingTheBeltStartsFromTheOthers) {
  auto e = Estimator(Scene(1.0), {0, 0, 0, 0});
  Motion m;
  m.y = 0.7;  // corners at y - 0.25 = 0.45 (belt) and y + 0.25 = 0.95 (floor)
  Feed feed;
  TimeNs t = 0;
  for (; t <= 1000 * kMs; t += kStep) {
    feed.Apply(*e, m, t);
    Step(*e, t);
  }
  auto belt = Get(*e, "sensor_on_belt");
  EXPECT_EQ(belt, (std::vector<double>{0, 1, 0, 1}));
  EXPECT_NEAR(Get(*e, "filtered_surface_velocity")[0], 0.0, 1e-12);
  // Between messages the robot's pose moves 0.3 m towards the belt's
  // middle: all four corners over it.
  m.y = 0.2;
  t += kStep;  // 1.04 s, no message at this step
  feed.Apply(*e, m, t);
  Step(*e, t);
  belt = Get(*e, "sensor_on_belt");
  EXPECT_EQ(belt, (std::vector<double>{1, 1, 1, 1}));
  const auto filtered = Get(*e, "filtered_surface_velocity");
  const auto status = Get(*e, "sensor_status");
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(status[i], 0.0) << i;
    EXPECT_NEAR(filtered[2 * i], 0.1, 1e-12) << i;
  }
  // With no sensor over the belt before, a sensor moved onto it has no
  // estimate until its first measurement there, which it starts from: the
  // first message whose whole window (100 ms) lies over the belt. The
  // message of 1.1 s was integrated from 1.0 s, before the move at 1.04 s
  // (part floor, part belt): it does not count; the one of 1.2 s does.
  auto f = Estimator(Scene(1.0), {0, 0, 0, 0});
  m.y = 1.0;  // all corners over the floor
  t = 0;
  for (; t <= 1000 * kMs; t += kStep) {
    feed.Apply(*f, m, t);
    Step(*f, t);
  }
  m.y = 0.2;
  t += kStep;  // 1.04 s
  feed.Apply(*f, m, t);
  Step(*f, t);
  for (double s : Get(*f, "sensor_status")) EXPECT_EQ(s, 2.0);
  for (double s : Get(*f, "wheel_source")) EXPECT_EQ(s, 3.0);
  for (t += kStep; t <= 1100 * kMs; t += kStep) {
    feed.Apply(*f, m, t);
    Step(*f, t);
  }
  for (double s : Get(*f, "sensor_status")) EXPECT_EQ(s, 2.0);
  for (; t <= 1200 * kMs; t += kStep) {
    feed.Apply(*f, m, t);
    Step(*f, t);
  }
  for (double s : Get(*f, "sensor_status")) EXPECT_EQ(s, 0.0);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(Get(*f, "filtered_surface_velocity")[2 * i], 0.1, 1e-12);
  }
}

// Guards the encoders' check (odometry_gate): a robot driving at 0.3 m/s
// along x on a belt running at 0.1 m/s, every wheel and sensor over it. Its
// wheels roll at 0.3 - 0.1 = 0.2 m/s relative to the belt, so a working
// sensor reads -0.2 m/s; a dark one (the firmware matching noise) reads
// about 0 while its quality stays high. The gate, 3 sigmas of paper 1's
// 3 cm/s, is 0.09 m/s. Expected: the working messages pass
// (|error| 0 < 0.09), the dark ones are refused (|error| 0.2 > 0.09) and
// counted; the sensors are held, then stale, and the wheels say so.
TEST(SurfaceVelocityEstimator, EncodersRefuteADarkSensor) {
  auto e = Estimator(Scene(4.0), {0, 0, 0, 0});
  SetAll(*e, "odometry_gate", 3.0);
  Motion m;
  m.vx = 0.3;
  std::vector<double> wheels;
  for (std::size_t j = 0; j < 4; ++j) {
    wheels.push_back(0.3 - 0.1);
    wheels.push_back(0.0);
  }
  SetArray(*e, "odometry_wheel_velocity", wheels);
  Feed feed;
  feed.half_width = 2.0;
  TimeNs t = 0;
  for (; t <= 1000 * kMs; t += kStep) {
    m.x = 0.3 * cosim::NsToSeconds(t);
    feed.Apply(*e, m, t);
    Step(*e, t);
  }
  for (double s : Get(*e, "sensor_status")) EXPECT_EQ(s, 0.0);
  for (double n : Get(*e, "implausible_count")) EXPECT_EQ(n, 0.0);
  EXPECT_NEAR(Get(*e, "filtered_surface_velocity")[0], 0.1, 1e-9);
  // Dark from 1.0 s: every message reads 0 (valid, quality 200).
  for (t = 1000 * kMs + kStep; t <= 1500 * kMs; t += kStep) {
    m.x = 0.3 * cosim::NsToSeconds(t);
    feed.Apply(*e, m, t);
    std::fill(feed.velocity.begin(), feed.velocity.end(), 0.0);
    SetArray(*e, "sensor_velocity", feed.velocity);
    Step(*e, t);
  }
  for (double n : Get(*e, "implausible_count")) EXPECT_EQ(n, 5.0);  // 1.1 ... 1.5 s
  for (double s : Get(*e, "sensor_status")) EXPECT_EQ(s, 1.0);
  for (double s : Get(*e, "wheel_source")) EXPECT_EQ(s, 2.0);
  // Held with the decay: 0.1 exp(-(1.5 - 1.0) / 1 s) at most (held from
  // the overdue time on).
  EXPECT_LT(Get(*e, "filtered_surface_velocity")[0], 0.1);
  // Without the check the same messages would be filtered in.
  auto off = Estimator(Scene(4.0), {0, 0, 0, 0});
  Feed feed2;
  feed2.half_width = 2.0;
  for (t = 0; t <= 1500 * kMs; t += kStep) {
    m.x = 0.3 * cosim::NsToSeconds(t);
    feed2.Apply(*off, m, t);
    if (t > 1000 * kMs) {
      std::fill(feed2.velocity.begin(), feed2.velocity.end(), 0.0);
      SetArray(*off, "sensor_velocity", feed2.velocity);
    }
    Step(*off, t);
  }
  for (double s : Get(*off, "sensor_status")) EXPECT_EQ(s, 0.0);
  for (double n : Get(*off, "implausible_count")) EXPECT_EQ(n, 0.0);
}

// Guards against state SaveState misses (filter states, message counts,
// timers, the Eq. 2 windows): a unit restored mid-run, with the robot
// turning and driving across the belt's edge, noisy measurements and one
// sensor invalid for a while, continues bit for bit like the original.
TEST(SurfaceVelocityEstimator, RestoredUnitContinuesBitForBit) {
  auto a = Estimator(Scene(1.0), {0.1, 0.2, -0.3, 1.0});
  auto b = Estimator(Scene(1.0), {0.1, 0.2, -0.3, 1.0});
  Feed feed;
  feed.mount = {0.1, 0.2, -0.3, 1.0};
  std::mt19937_64 rng(3);
  const auto motion = [](TimeNs t) {
    const double ts = cosim::NsToSeconds(t);
    return Motion{0.05 * ts, 1.0 - 0.2 * ts, 0.3 * ts, 0.05, -0.2, 0.3};
  };
  TimeNs t = 0;
  for (; t < 2510 * kMs; t += 10 * kMs) {
    feed.valid[1] = (t > 1500 * kMs && t < 2200 * kMs) ? 0.0 : 1.0;
    feed.quality[1] = feed.valid[1] * 150.0;
    feed.Apply(*a, motion(t), t, 0.03, &rng);
    Step(*a, t, 10 * kMs);
  }
  b->RestoreState(a->SaveState());
  std::mt19937_64 rng_b = rng;
  Feed feed_b = feed;
  int wheel_steps_on_belt = 0;
  for (; t < 8000 * kMs; t += 10 * kMs) {
    feed.Apply(*a, motion(t), t, 0.03, &rng);
    feed_b.Apply(*b, motion(t), t, 0.03, &rng_b);
    Step(*a, t, 10 * kMs);
    Step(*b, t, 10 * kMs);
    ASSERT_TRUE(test_helpers::SameBits(test_helpers::Outputs(*a), test_helpers::Outputs(*b)))
        << "at " << t;
    for (double s : Get(*a, "wheel_source")) wheel_steps_on_belt += s == 1.0;
  }
  // The run crossed the belt (y from 1.0 to -0.6): wheels took its estimate.
  EXPECT_GT(wheel_steps_on_belt, 100);
}

// --- The state-switch detector (paper 1 Sec. II: the line runs in only two
// states; SwitchDetector in steady_state_kalman.h). All four sensors over
// the belt's middle, the robot at rest; the belt's speed per message.

// Paper 1's figures: the steady gain and the gate g sqrt(S) of the defaults
// (switch_gate 2.5: 0.0793 m/s).
double Gain() { return SteadyStateKalman::Gain((0.01 / 3) * (0.01 / 3), 0.03 * 0.03); }
double Gate() {
  return 2.5 *
         std::sqrt(SteadyStateKalman::InnovationVariance((0.01 / 3) * (0.01 / 3), 0.03 * 0.03));
}

// Runs `e` from 0 to `until` (inclusive) on a belt whose speed at time t is
// speed(t) (read at each message), recording per step the belt's speed, the
// filtered value and the switch count of sensor 0.
struct Trace {
  std::vector<TimeNs> t;
  std::vector<double> truth, filtered, switches;
};
template <typename Speed>
Trace RunBelt(SurfaceVelocityEstimator& e, Feed& feed, TimeNs until, Speed speed,
              double sigma = 0.0, std::mt19937_64* rng = nullptr) {
  Trace out;
  Motion m;
  for (TimeNs t = 0; t <= until; t += kStep) {
    feed.belt_vx = speed(t);
    feed.Apply(e, m, t, sigma, rng);
    Step(e, t);
    out.t.push_back(t);
    out.truth.push_back(feed.belt_vx);
    out.filtered.push_back(Get(e, "filtered_surface_velocity")[0]);
    out.switches.push_back(Get(e, "switch_count")[0]);
  }
  return out;
}

// Guards against false restarts on the noise the filter is designed for:
// one hour in all (36000 messages per sensor, 4 sensors), 8 seeds of 450 s
// each, of a constant belt at 0.1 m/s measured with white noise of paper
// 1's sigma, 3 cm/s, on each component. The gate's bound: at most
// 4 Q(2.5)^3 = 9.6e-7 false restarts per message and sensor (2 sides x 2
// components), so at most 0.138 over the hour; on a constant input the
// innovations' variance is 2 r / (2 - K) < S (the gate is 2.57 of their
// sigmas) and their correlations are negative, which lowers it to 0.075
// (SwitchDetector's comment). The test allows 2 over the hour: the
// probability of 3 or more is under 4e-4 even at the 0.138 bound (Poisson).
// It can fail: with the gate at 1.5 sigma and 2 samples (4 Q(1.5)^2 = 0.018
// per message) the same noise restarts the filters, over 100 times per seed
// (0.018 x 18000 messages = 324 at white innovations); and the default
// filter's error stays the steady-state one (no restart noise): its
// variance pooled over the seeds is K r / (2 - K) within 20 % (about 720
// independent samples in the hour at the filter's time constant, relative
// sd sqrt(2 / 720) = 5 %: 4 sd). Measured over seeds 1..8: restarts 0 at
// every seed; each seed's error variance over K r / (2 - K) 0.879 / 0.972
// / 1.082 (pooled 0.976); restarts with the low gate 407 / 449 / 478 per
// seed, against the 100 asked.
TEST(SurfaceVelocityEstimator, NoSwitchOnWhiteNoiseAtThePapersSigma) {
  constexpr int kSeeds = 8;
  const TimeNs span = 450'000 * kMs;
  const double k = Gain();
  const double expected = k * 0.03 * 0.03 / (2.0 - k);
  for (const bool low_gate : {false, true}) {
    std::vector<double> restarts, variance;
    double pooled_sum2 = 0.0;
    std::int64_t pooled_n = 0;
    for (int seed = 1; seed <= kSeeds; ++seed) {
      auto e = Estimator(Scene(1.4), {0, 0, 0, 0});
      if (low_gate) {
        SetAll(*e, "switch_gate", 1.5);
        e->variables().SetValue(*e->variables().Find("switch_samples"),
                                cosim::Value{std::int64_t{2}});
        e->Initialize();
      }
      Feed feed;
      feed.half_width = 0.7;
      std::mt19937_64 rng(static_cast<std::uint64_t>(seed));
      double sum2 = 0.0;
      std::int64_t n = 0;
      for (TimeNs t = 0; t <= span; t += kStep) {
        feed.Apply(*e, Motion{}, t, 0.03, &rng);
        Step(*e, t);
        if (t >= 10'000 * kMs && t % kMessage == 0) {
          const double err = Get(*e, "filtered_surface_velocity")[0] - 0.1;
          sum2 += err * err;
          ++n;
        }
      }
      double count = 0.0;
      for (double c : Get(*e, "switch_count")) count += c;
      restarts.push_back(count);
      variance.push_back(sum2 / n / expected);
      pooled_sum2 += sum2;
      pooled_n += n;
    }
    const auto r = test_spread::Print(
        low_gate ? "restarts, gate 1.5 sigma, 2 samples" : "restarts, default gate", restarts);
    double total = 0.0;
    for (double c : restarts) total += c;
    if (!low_gate) {
      const auto v = test_spread::Print("error variance / (K r / (2 - K))", variance);
      const double pooled = pooled_sum2 / static_cast<double>(pooled_n) / expected;
      std::printf("restarts in all %.0f; pooled variance ratio %.4f\n", total, pooled);
      EXPECT_LE(total, 2.0);
      EXPECT_NEAR(pooled, 1.0, 0.2);
    } else {
      EXPECT_GT(r.min(), 100.0);
    }
  }
}

// Guards against a switch followed no faster than the fixed gain: the
// belt steps from 0 to 0.2 m/s between the messages at 2.0 and 2.1 s, and
// back to 0 between 6.0 and 6.1 s (noise-free). The innovations after a
// step of 0.2 m/s are 0.2 (1 - K)^(n - 1) = 0.200, 0.179, 0.160 (all beyond
// the gate, 0.079 m/s): at the step's 3rd message (2.3 s, 6.3 s) the
// filter restarts at the measurement, exactly 0.2 (then 0), and keeps it;
// before that it has the fixed gain's values 0.2 (1 - (1 - K)^n). With
// switch_gate 0 the same steps leave 0.2 (1 - K)^3 = 0.143 still to go.
TEST(SurfaceVelocityEstimator, StepIsFollowedAtItsThirdMessage) {
  const auto speed = [](TimeNs t) { return t > 2000 * kMs && t <= 6000 * kMs ? 0.2 : 0.0; };
  auto e = Estimator(Scene(1.4), {0, 0, 0, 0});
  Feed feed;
  feed.half_width = 0.7;
  const Trace tr = RunBelt(*e, feed, 8000 * kMs, speed);
  const double k = Gain();
  for (std::size_t j = 0; j < tr.t.size(); ++j) {
    const TimeNs t = tr.t[j];
    if (t < 2100 * kMs) {
      EXPECT_EQ(tr.filtered[j], 0.0) << t;
      EXPECT_EQ(tr.switches[j], 0.0) << t;
    } else if (t < 2300 * kMs) {
      const int n = static_cast<int>((t - 2000 * kMs) / kMessage);  // messages since the step
      EXPECT_NEAR(tr.filtered[j], 0.2 * (1.0 - std::pow(1.0 - k, n)), 1e-12) << t;
      EXPECT_EQ(tr.switches[j], 0.0) << t;
    } else if (t < 6100 * kMs) {
      EXPECT_NEAR(tr.filtered[j], 0.2, 1e-12) << t;
      EXPECT_EQ(tr.switches[j], 1.0) << t;
    } else if (t < 6300 * kMs) {
      EXPECT_EQ(tr.switches[j], 1.0) << t;
      EXPECT_GT(tr.filtered[j], 0.1) << t;
    } else {
      EXPECT_NEAR(tr.filtered[j], 0.0, 1e-12) << t;
      EXPECT_EQ(tr.switches[j], 2.0) << t;
    }
  }
  for (double c : Get(*e, "switch_count")) EXPECT_EQ(c, 2.0);
  EXPECT_GT(0.2 * std::pow(1.0 - k, 8), Gate());  // the 9th innovation still beyond
  // The runs are state: a unit restored after the step's 2nd message
  // (runs of 2 under way) restarts at the 3rd like the original.
  auto a = Estimator(Scene(1.4), {0, 0, 0, 0});
  auto b = Estimator(Scene(1.4), {0, 0, 0, 0});
  Feed feed_a;
  feed_a.half_width = 0.7;
  RunBelt(*a, feed_a, 2220 * kMs, speed);
  b->RestoreState(a->SaveState());
  Feed feed_b = feed_a;
  Motion m;
  for (TimeNs t = 2240 * kMs; t <= 2400 * kMs; t += kStep) {
    feed_a.belt_vx = feed_b.belt_vx = speed(t);
    feed_a.Apply(*a, m, t);
    feed_b.Apply(*b, m, t);
    Step(*a, t);
    Step(*b, t);
    ASSERT_TRUE(test_helpers::SameBits(test_helpers::Outputs(*a), test_helpers::Outputs(*b))) << t;
  }
  EXPECT_EQ(Get(*b, "switch_count")[0], 1.0);
  // The paper's filter alone.
  auto f = Estimator(Scene(1.4), {0, 0, 0, 0});
  SetAll(*f, "switch_gate", 0.0);
  f->Initialize();
  Feed feed_f;
  feed_f.half_width = 0.7;
  const Trace tf = RunBelt(*f, feed_f, 2300 * kMs, speed);
  EXPECT_NEAR(tf.filtered.back(), 0.2 * (1.0 - std::pow(1.0 - k, 3)), 1e-12);
  EXPECT_EQ(tf.switches.back(), 0.0);
}

// Guards against a start of the line (a ramp of 1 s, paper 1's treadmill)
// tracked only with the fixed gain's lag: the belt goes from 0 to 0.2 m/s
// over 2.0..3.0 s (0.02 m/s per message, noise-free). The fixed gain's
// innovation at the ramp's n-th message is a (1 - (1 - K)^n) / K (a = 0.02
// m/s); it passes the gate (0.079 m/s) at n = 5, so the filter restarts at
// n = 7 (2.7 s). The largest error of the output against the belt's speed
// is then that 7th innovation, 0.1028 m/s (the output holds the 6th
// message's value while the belt reaches 0.14 m/s); the ramp's last three
// messages give innovations of at most a (1 - (1 - K)^3) / K = 0.054 m/s,
// inside the gate: one restart only. With switch_gate 0 the largest error
// is the 10th innovation, 0.1276 m/s. (After the restart at 0.14 m/s the
// filter follows the remaining 0.06 m/s with the steady gain.)
TEST(SurfaceVelocityEstimator, RampIsTrackedWithOneRestart) {
  const auto speed = [](TimeNs t) {
    const double s = cosim::NsToSeconds(t);
    return s <= 2.0 ? 0.0 : (s >= 3.0 ? 0.2 : 0.2 * (s - 2.0));
  };
  const double k = Gain(), a = 0.02;
  const auto innovation = [&](int n) { return a * (1.0 - std::pow(1.0 - k, n)) / k; };
  ASSERT_LT(innovation(4), Gate());
  ASSERT_GT(innovation(5), Gate());
  const double worst_switch = innovation(7), worst_fixed = innovation(10);
  EXPECT_NEAR(worst_switch, 0.1028, 1e-4);
  EXPECT_NEAR(worst_fixed, 0.1276, 1e-4);
  double worst[2] = {0.0, 0.0};
  for (const bool on : {true, false}) {
    auto e = Estimator(Scene(1.4), {0, 0, 0, 0});
    if (!on) {
      SetAll(*e, "switch_gate", 0.0);
      e->Initialize();
    }
    Feed feed;
    feed.half_width = 0.7;
    const Trace tr = RunBelt(*e, feed, 6000 * kMs, speed);
    for (std::size_t j = 1; j < tr.t.size(); ++j) {
      // The belt at this step against the output of the step before.
      worst[on] = std::max(worst[on], speed(tr.t[j]) - tr.filtered[j - 1]);
      if (on) {
        EXPECT_EQ(tr.switches[j], tr.t[j] >= 2700 * kMs ? 1.0 : 0.0) << tr.t[j];
      } else {
        EXPECT_EQ(tr.switches[j], 0.0);
      }
    }
    if (on) {
      EXPECT_NEAR(tr.filtered[static_cast<std::size_t>(2700 * kMs / kStep)], 0.14, 1e-12);
    }
  }
  EXPECT_NEAR(worst[1], worst_switch, 1e-12);
  EXPECT_NEAR(worst[0], worst_fixed, 1e-12);
  std::printf("ramp: largest error %.4f m/s with the detector, %.4f without\n", worst[1], worst[0]);
}

// Guards against the detector changing the paper's filter when it is off:
// with switch_gate 0, on a noisy ramp that makes the default restart, each
// sensor's filtered value is exactly SteadyStateKalman::Update of its
// previous value and its raw value at every message (started at its first
// raw value), bit for bit, and switch_count stays 0.
TEST(SurfaceVelocityEstimator, GateZeroIsThePapersFilterBitForBit) {
  const auto speed = [](TimeNs t) {
    const double s = cosim::NsToSeconds(t);
    return s <= 2.0 ? 0.0 : (s >= 3.0 ? 0.2 : 0.2 * (s - 2.0));
  };
  for (const bool off : {true, false}) {
    auto e = Estimator(Scene(1.4), {0, 0, 0, 0});
    if (off) {
      SetAll(*e, "switch_gate", 0.0);
      e->Initialize();
    }
    const SteadyStateKalman kf((0.01 / 3) * (0.01 / 3), 0.03 * 0.03);
    Feed feed;
    feed.half_width = 0.7;
    std::mt19937_64 rng(9);
    Motion m;
    std::vector<double> x(8, 0.0);
    bool started = false, same = true;
    for (TimeNs t = 0; t <= 6000 * kMs; t += kStep) {
      feed.belt_vx = speed(t);
      feed.Apply(*e, m, t, 0.03, &rng);
      Step(*e, t);
      if (t == 0 || t % kMessage != 0) continue;
      const auto raw = Get(*e, "raw_surface_velocity");
      for (std::size_t i = 0; i < 8; ++i) x[i] = started ? kf.Update(x[i], raw[i]) : raw[i];
      started = true;
      same = same && test_helpers::SameBits(x, Get(*e, "filtered_surface_velocity"));
    }
    double restarts = 0.0;
    for (double c : Get(*e, "switch_count")) restarts += c;
    if (off) {
      EXPECT_TRUE(same);
      EXPECT_EQ(restarts, 0.0);
    } else {
      EXPECT_FALSE(same);
      EXPECT_GE(restarts, 4.0);
    }
  }
}

// Guards against parameters the unit would run with silently: required
// mounts unset, a stale_after that skips the hold, and per-sensor or
// per-wheel lists whose length is not the structural count (reported by
// the factory at the list's key, naming the count).
TEST(SurfaceVelocityEstimator, ParameterProblemsAreReported) {
  SurfaceVelocityEstimator u("est", 2, 3, Scene(1.0));
  auto problems = u.CheckParameters();
  std::vector<std::string> names;
  for (const auto& p : problems) names.push_back(p.variable);
  for (const char* required : {"sensor_x", "sensor_y", "sensor_yaw", "wheel_x", "wheel_y"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), required), names.end()) << required;
  }
  SetAll(u, "sensor_x", 0.3);
  SetAll(u, "sensor_y", 0.2);
  SetAll(u, "sensor_yaw", 0.0);
  SetAll(u, "wheel_x", 0.2);
  SetAll(u, "wheel_y", 0.1);
  EXPECT_TRUE(u.CheckParameters().empty());
  SetAll(u, "stale_after", 0.15);
  problems = u.CheckParameters();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].variable, "stale_after");
  EXPECT_THROW(u.Initialize(), cosim::UnitError);

  const config::UnitType* type = config::FindUnitType("surface_velocity_estimator");
  ASSERT_NE(type, nullptr);
  const models::Scene scene = Scene(1.0);
  const std::string name = "est", path = "units.est.parameters";
  const auto make = [&](const std::string& text, std::vector<config::Issue>& issues) {
    config::YamlReader reader("scenario.yaml");
    const YAML::Node params = YAML::Load(text);
    const YAML::Node model;
    const std::string model_file;
    auto unit = type->create({name, 1, reader, params, path, scene, model, model_file});
    issues = reader.issues();
    return unit;
  };
  std::vector<config::Issue> issues;
  auto ok = make("{sensors: 4, wheels: 2, sensor_x: [1, 2, 3, 4], wheel_y: [0, 1]}", issues);
  ASSERT_TRUE(ok);
  EXPECT_EQ(static_cast<SurfaceVelocityEstimator*>(ok.get())->sensor_count(), 4);
  EXPECT_EQ(static_cast<SurfaceVelocityEstimator*>(ok.get())->wheel_count(), 2);
  EXPECT_TRUE(issues.empty());

  EXPECT_FALSE(
      make("{sensors: 4, wheels: 4, sensor_yaw: [0, 1, 2], wheel_x: [1, 2, 3, 4, 5]}", issues));
  ASSERT_EQ(issues.size(), 2u);
  EXPECT_EQ(issues[0].key_path, "units.est.parameters.sensor_yaw");
  EXPECT_NE(issues[0].message.find("sensors: 4"), std::string::npos) << issues[0].message;
  EXPECT_EQ(issues[1].key_path, "units.est.parameters.wheel_x");
  EXPECT_NE(issues[1].message.find("wheels: 4"), std::string::npos) << issues[1].message;

  EXPECT_FALSE(make("{sensors: 0, wheels: 4}", issues));
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].key_path, "units.est.parameters.sensors");
  EXPECT_FALSE(make("{sensors: 4}", issues));
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].key_path, "units.est.parameters.wheels");
}

}  // namespace
}  // namespace linesim::estimation
