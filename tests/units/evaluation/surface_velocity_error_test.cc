#include "units/evaluation/surface_velocity_error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "tests/units/test_helpers.h"

namespace linesim::evaluation {
namespace {

using test_helpers::Get;
using test_helpers::SetArray;

constexpr double kPi = std::numbers::pi;

// A 4 x 2 m belt along map x at the origin, as a treadmill under the robot.
models::Belt Treadmill() {
  models::Belt b;
  b.name = "treadmill";
  b.area = {0.0, 0.0, 4.0, 2.0, 0.0};
  return b;
}

void Set(cosim::Unit& u, const std::string& name, double v) {
  u.variables().SetReal(*u.variables().Find(name), v);
}

// Two sensors at opposite corners, the second turned by 90 deg.
std::unique_ptr<SurfaceVelocityErrorUnit> TwoSensors() {
  auto u = std::make_unique<SurfaceVelocityErrorUnit>("e", 2, Treadmill());
  SetArray(*u, "mount_x", {0.5, -0.5});
  SetArray(*u, "mount_y", {0.25, -0.25});
  SetArray(*u, "mount_yaw", {0.0, kPi / 2});
  return u;
}

// Guards against a wrong frame in Eq. 2. Expected by kinematics: a robot
// at rest turned by yaw over a belt moving at 0.2 m/s along x sees the
// surface move at R(-(yaw + mount_yaw)) (0.2, 0) in each sensor frame; made
// absolute again this is 0.2 m/s along the belt, error 0.
TEST(SurfaceVelocityError, StandingRobotSeesTheBeltSpeed) {
  for (double yaw : {0.0, 0.7, -2.0}) {
    auto u = TwoSensors();
    Set(*u, "yaw", yaw);
    Set(*u, "reference", 0.2);
    std::vector<double> m;
    for (double mount_yaw : {0.0, kPi / 2}) {
      const double a = yaw + mount_yaw;
      m.push_back(std::cos(a) * 0.2);
      m.push_back(-std::sin(a) * 0.2);
    }
    SetArray(*u, "measured", m);
    u->Initialize();
    ASSERT_EQ(u->DoStep(0, 1'000'000), cosim::StepResult::kOk);
    for (int k = 0; k < 2; ++k) {
      EXPECT_NEAR(Get(*u, "surface_speed")[k], 0.2, 1e-12);
      EXPECT_NEAR(Get(*u, "error")[k], 0.0, 1e-12);
      EXPECT_EQ(Get(*u, "over_belt")[k], 1.0);
    }
  }
}

// Guards against leaving out omega x r. Expected: a robot turning in place
// at w over a still belt: the floor under the sensor at r moves at
// -(w ez x r) relative to it; Eq. 2 adds the sensor's own w ez x r back, so
// the absolute surface speed is 0.
TEST(SurfaceVelocityError, TurningRobotOverStillBeltReadsZero) {
  auto u = TwoSensors();
  const double w = 0.8;
  Set(*u, "yaw_rate", w);
  // Sensor 0 at (0.5, 0.25), frame = base_link: relative surface velocity
  // -(w ez x r) = -w (-0.25, 0.5) = (0.2, -0.4).
  // Sensor 1 at (-0.5, -0.25): -w (0.25, -0.5) = (-0.2, 0.4) in base_link,
  // in its frame (turned +90 deg): (0.4, 0.2).
  SetArray(*u, "measured", {0.2, -0.4, 0.4, 0.2});
  u->Initialize();
  ASSERT_EQ(u->DoStep(0, 1'000'000), cosim::StepResult::kOk);
  for (int k = 0; k < 2; ++k) EXPECT_NEAR(Get(*u, "surface_speed")[k], 0.0, 1e-12);
}

// Guards against counting sensors that are off the belt and against a
// wrong running mean. Expected by definition: errors 0.1 and 0.3 over two
// steps on one sensor give sqrt((0.01 + 0.09) / 2); a sensor off the belt
// adds nothing.
TEST(SurfaceVelocityError, RmseOverSensorsOverTheBelt) {
  auto u = TwoSensors();
  // The robot at x = 1.7: sensor 0 at x = 2.2 is past the belt's end (2 m).
  SetArray(*u, "position", {1.7, 0.0});
  Set(*u, "reference", 0.0);
  u->Initialize();
  SetArray(*u, "measured", {0.5, 0.0, 0.0, -0.1});
  ASSERT_EQ(u->DoStep(0, 1'000'000), cosim::StepResult::kOk);
  EXPECT_EQ(Get(*u, "over_belt")[0], 0.0);
  EXPECT_EQ(Get(*u, "error")[0], 0.0);
  SetArray(*u, "measured", {0.5, 0.0, 0.0, -0.3});
  ASSERT_EQ(u->DoStep(1'000'000, 1'000'000), cosim::StepResult::kOk);
  EXPECT_NEAR(Get(*u, "rmse")[0], std::sqrt((0.01 + 0.09) / 2), 1e-12);
  EXPECT_EQ(Get(*u, "samples")[0], 2.0);
}

// Guards the declared feedthrough: surface_speed depends directly on the
// inputs, so UpdateOutputs must show the inputs just set (the master reads
// it before the step), not the previous step's. Expected as in the first
// test: 0.2 m/s along the belt from a standing robot.
TEST(SurfaceVelocityError, OutputsFollowTheInputsBeforeTheStep) {
  auto u = TwoSensors();
  u->Initialize();
  EXPECT_EQ(Get(*u, "surface_speed")[0], 0.0);
  SetArray(*u, "measured", {0.2, 0.0, 0.0, -0.2});
  u->UpdateOutputs();
  EXPECT_NEAR(Get(*u, "surface_speed")[0], 0.2, 1e-12);
  EXPECT_NEAR(Get(*u, "surface_speed")[1], 0.2, 1e-12);
  EXPECT_EQ(Get(*u, "samples")[0], 0.0);  // nothing counted before a step
}

// The estimate's error is counted over the same samples as the raw one.
// Expected by hand: the belt runs along map x at 0.2 m/s (reference); both
// sensors over it; estimates (0.25, 0) and (0.1, 7) in map give speeds
// 0.25 and 0.1 along x, errors 0.05 and -0.1: rms = sqrt((0.0025 + 0.01) / 2).
TEST(SurfaceVelocityError, EstimatedVelocityHasItsOwnRmse) {
  SurfaceVelocityErrorUnit u("e", 2, Treadmill(), true);
  SetArray(u, "mount_x", {0.5, -0.5});
  SetArray(u, "mount_y", {0.25, -0.25});
  SetArray(u, "mount_yaw", {0.0, kPi / 2});
  Set(u, "reference", 0.2);
  SetArray(u, "estimated", {0.25, 0.0, 0.1, 7.0});
  u.Initialize();
  ASSERT_EQ(u.DoStep(0, 1'000'000), cosim::StepResult::kOk);
  EXPECT_NEAR(Get(u, "estimated_speed")[0], 0.25, 1e-15);
  EXPECT_NEAR(Get(u, "estimated_speed")[1], 0.1, 1e-15);
  EXPECT_NEAR(Get(u, "rmse_estimated")[0], std::sqrt((0.0025 + 0.01) / 2), 1e-15);
  // Without `estimated` there is no such input.
  EXPECT_FALSE(TwoSensors()->variables().Find("estimated").has_value());
}

TEST(SurfaceVelocityError, MountsAreRequired) {
  SurfaceVelocityErrorUnit u("e", 1, Treadmill());
  EXPECT_EQ(u.CheckParameters().size(), 3u);
  EXPECT_THROW(SurfaceVelocityErrorUnit("e", 0, Treadmill()), cosim::UnitError);
}

// Plateaus and settling (issue 21 item 2): one sensor over the belt, robot
// at rest; the reference is 0 until 2 s, ramps to 0.2 m/s over 1 s, holds;
// the estimate follows it as a first-order lag of 0.5 s and the raw reads
// the reference + 0.01 m/s. Plateau samples (reference within 1 cm/s of
// its level for 1 s): t < 2 s after the first 1 s, and t >= 3 s + 1 s; the
// raw error there is 0.01 exactly, the filtered error on the off plateau 0.
// Settling: the lag behind a ramp of slope a with time constant tau is
// a tau (1 - e^(-t/tau)), at the ramp's end 0.2 * 0.5 (1 - e^-2) = 0.0865,
// then decays as e^(-(t - 3)/tau): below 0.02 m/s after tau ln(0.0865 /
// 0.02) = 0.732 s, so the estimate is last off by more than 2 cm/s at
// 3.732 s; the switch was seen where the reference had moved 1 cm/s, at
// 2.05 s: settling 1.682 s (to the 1 ms step).
TEST(SurfaceVelocityError, PlateauRmseAndSettlingTime) {
  SurfaceVelocityErrorUnit u("e", 1, Treadmill(), true);
  SetArray(u, "mount_x", {0.0});
  SetArray(u, "mount_y", {0.0});
  SetArray(u, "mount_yaw", {0.0});
  u.Initialize();
  const double tau = 0.5, dt = 0.001;
  double est = 0.0;
  for (int k = 0; k < 6000; ++k) {
    const double t = k * dt;
    const double ref = t < 2.0 ? 0.0 : (t < 3.0 ? 0.2 * (t - 2.0) : 0.2);
    Set(u, "reference", ref);
    SetArray(u, "measured", {ref + 0.01, 0.0});
    SetArray(u, "estimated", {est, 0.0});
    ASSERT_EQ(u.DoStep(static_cast<cosim::TimeNs>(k) * 1'000'000, 1'000'000),
              cosim::StepResult::kOk);
    est += (ref - est) * (1.0 - std::exp(-dt / tau));
  }
  EXPECT_NEAR(Get(u, "rmse_plateau")[0], 0.01, 1e-12);
  // The filtered error on the plateaus: 0 on the off plateau (t in [1,
  // 2.05): 1050 samples), the lag 0.0865 e^(-(t - 3)/tau) on the on plateau,
  // which starts 1 s after the reference's last step of 1 cm/s, between
  // 2.95 and 3 s: the mean square is between those of the two starts.
  auto rms_from = [&](double start) {
    const double on = 0.0865 * 0.0865 * tau / 2.0 *
                      (std::exp(-2.0 * (start - 3.0) / tau) - std::exp(-2.0 * 3.0 / tau));
    return std::sqrt(on / ((6.0 - start) + 1.05) / 1.0);
  };
  EXPECT_GT(Get(u, "rmse_plateau_estimated")[0], rms_from(4.0) * 0.99);
  EXPECT_LT(Get(u, "rmse_plateau_estimated")[0], rms_from(3.95) * 1.01);
  EXPECT_EQ(Get(u, "switches")[0], 1.0);
  EXPECT_NEAR(Get(u, "settling_time")[0], 1.682, 0.003);
}

// Guards the settling of the belt's estimate (the mean over the sensors
// over the belt, what the wheels get) rather than of each sensor's: two
// sensors over the belt whose estimates follow the reference as before but
// scatter +-0.03 m/s in opposite directions (noise no filter takes out of
// one sensor) settle as the mean does, 1.682 s; and the line-on plateau
// RMSE holds the samples with the reference beyond 1 cm/s only: the raw
// reads reference + 0.01, but + 0.03 while the line is off, so the on
// plateau's raw RMSE is 0.01 and the whole plateau's larger.
TEST(SurfaceVelocityError, SettlingFollowsTheBeltsEstimateAndOnPlateauIsTheLineOn) {
  SurfaceVelocityErrorUnit u("e", 2, Treadmill(), true);
  SetArray(u, "mount_x", {0.1, -0.1});
  SetArray(u, "mount_y", {0.0, 0.0});
  SetArray(u, "mount_yaw", {0.0, 0.0});
  u.Initialize();
  const double tau = 0.5, dt = 0.001;
  double est = 0.0;
  for (int k = 0; k < 6000; ++k) {
    const double t = k * dt;
    const double ref = t < 2.0 ? 0.0 : (t < 3.0 ? 0.2 * (t - 2.0) : 0.2);
    const double scatter = (k % 2 ? 0.03 : -0.03);
    const double raw = ref + (ref > 0.01 ? 0.01 : 0.03);
    Set(u, "reference", ref);
    SetArray(u, "measured", {raw, 0.0, raw, 0.0});
    SetArray(u, "estimated", {est + scatter, 0.0, est - scatter, 0.0});
    ASSERT_EQ(u.DoStep(static_cast<cosim::TimeNs>(k) * 1'000'000, 1'000'000),
              cosim::StepResult::kOk);
    est += (ref - est) * (1.0 - std::exp(-dt / tau));
  }
  EXPECT_NEAR(Get(u, "settling_time")[0], 1.682, 0.003);
  EXPECT_NEAR(Get(u, "rmse_plateau_on")[0], 0.01, 1e-12);
  EXPECT_GT(Get(u, "rmse_plateau")[0], 0.015);
}

}  // namespace
}  // namespace linesim::evaluation
