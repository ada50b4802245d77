#include "units/evaluation/final_pose_error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "tests/units/test_helpers.h"

namespace linesim::evaluation {
namespace {

using test_helpers::Get;
using test_helpers::SetArray;

constexpr cosim::TimeNs kStep = 10'000'000;  // 10 ms
constexpr double kDeg = std::numbers::pi / 180.0;

void Set(cosim::Unit& u, const std::string& name, double v) {
  u.variables().SetReal(*u.variables().Find(name), v);
}
void SetBool(cosim::Unit& u, const std::string& name, bool v) {
  u.variables().SetBoolean(*u.variables().Find(name), v);
}
bool GetBool(const cosim::Unit& u, const std::string& name) {
  return u.variables().GetBoolean(*u.variables().Find(name));
}

// The work pose of paper 2's van bay, settle 0.5 s, a run of 10 s.
void Make(FinalPoseErrorUnit& u, double stop_s = 10.0) {
  Set(u, "target_x", 5.9);
  Set(u, "target_y", 0.0);
  Set(u, "target_yaw", 0.0);
  Set(u, "settle_time", 0.5);
  u.Setup(0, static_cast<cosim::TimeNs>(stop_s * 1e9));
  u.Initialize();
}

// Steps from `from` to `to` (ns), returning the last result.
cosim::StepResult StepUntil(FinalPoseErrorUnit& u, cosim::TimeNs from, cosim::TimeNs to) {
  cosim::StepResult r = cosim::StepResult::kOk;
  for (cosim::TimeNs t = from; t < to && r == cosim::StepResult::kOk; t += kStep) {
    r = u.DoStep(t, kStep);
  }
  return r;
}

// Known offsets by hand: truth (5.912, -0.004, 1 deg) against (5.9, 0, 0):
// +12 mm, -4 mm, +1 deg; beacons (5.915, -0.001, 1.2 deg): +15 mm, -1 mm,
// +1.2 deg, own error hypot(3, 3) mm and +0.2 deg. `done` at 1 s, taken at
// 1.5 s; later motion changes nothing.
TEST(FinalPoseError, SignedErrorsOnceSettled) {
  FinalPoseErrorUnit u("final");
  Make(u);
  SetArray(u, "position", {5.912, -0.004});
  Set(u, "yaw", 1.0 * kDeg);
  SetArray(u, "beacon_position", {5.915, -0.001});
  Set(u, "beacon_yaw", 1.2 * kDeg);
  SetBool(u, "beacon_valid", true);
  ASSERT_EQ(StepUntil(u, 0, 1'000'000'000), cosim::StepResult::kOk);
  EXPECT_FALSE(GetBool(u, "measured"));
  SetBool(u, "done", true);
  ASSERT_EQ(StepUntil(u, 1'000'000'000, 1'490'000'000), cosim::StepResult::kOk);
  EXPECT_FALSE(GetBool(u, "measured"));  // 0.49 s after done
  ASSERT_EQ(StepUntil(u, 1'490'000'000, 1'510'000'000), cosim::StepResult::kOk);
  ASSERT_TRUE(GetBool(u, "measured"));
  ASSERT_TRUE(GetBool(u, "beacon_measured"));
  EXPECT_DOUBLE_EQ(Get(u, "done_time")[0], 1.0);
  EXPECT_NEAR(Get(u, "error_x")[0], 0.012, 1e-12);
  EXPECT_NEAR(Get(u, "error_y")[0], -0.004, 1e-12);
  EXPECT_NEAR(Get(u, "error_yaw")[0], 1.0, 1e-12);
  EXPECT_NEAR(Get(u, "beacon_error_x")[0], 0.015, 1e-12);
  EXPECT_NEAR(Get(u, "beacon_error_y")[0], -0.001, 1e-12);
  EXPECT_NEAR(Get(u, "beacon_error_yaw")[0], 1.2, 1e-12);
  EXPECT_NEAR(Get(u, "beacon_self_error_position")[0], std::hypot(0.003, 0.003), 1e-12);
  EXPECT_NEAR(Get(u, "beacon_self_error_x")[0], 0.003, 1e-12);
  EXPECT_NEAR(Get(u, "beacon_self_error_y")[0], 0.003, 1e-12);
  EXPECT_NEAR(Get(u, "beacon_self_error_yaw")[0], 0.2, 1e-12);
  // Later the robot is pushed: the final pose stays.
  SetArray(u, "position", {6.5, 0.3});
  Set(u, "yaw", -0.4);
  ASSERT_EQ(StepUntil(u, 1'510'000'000, 10'000'000'000), cosim::StepResult::kOk);
  EXPECT_NEAR(Get(u, "error_x")[0], 0.012, 1e-12);
  EXPECT_NEAR(Get(u, "error_yaw")[0], 1.0, 1e-12);
}

// Yaw is wrapped: 359 deg against 0 is -1 deg.
TEST(FinalPoseError, YawWrapped) {
  FinalPoseErrorUnit u("final");
  Make(u);
  SetArray(u, "position", {5.9, 0.0});
  Set(u, "yaw", 359.0 * kDeg);
  SetArray(u, "beacon_position", {5.9, 0.0});
  Set(u, "beacon_yaw", -358.0 * kDeg);
  SetBool(u, "beacon_valid", true);
  SetBool(u, "done", true);
  ASSERT_EQ(StepUntil(u, 0, 600'000'000), cosim::StepResult::kOk);
  EXPECT_NEAR(Get(u, "error_yaw")[0], -1.0, 1e-9);
  EXPECT_NEAR(Get(u, "beacon_error_yaw")[0], 2.0, 1e-9);
  EXPECT_NEAR(Get(u, "beacon_self_error_yaw")[0], 3.0, 1e-9);
}

// The beacon errors wait for a valid beacon pose after the settle time.
TEST(FinalPoseError, BeaconErrorsWaitForAValidPose) {
  FinalPoseErrorUnit u("final");
  Make(u);
  SetArray(u, "position", {5.9, 0.0});
  SetArray(u, "beacon_position", {0.0, 0.0});  // not valid yet
  SetBool(u, "done", true);
  ASSERT_EQ(StepUntil(u, 0, 1'000'000'000), cosim::StepResult::kOk);
  EXPECT_TRUE(GetBool(u, "measured"));
  EXPECT_FALSE(GetBool(u, "beacon_measured"));
  EXPECT_EQ(Get(u, "beacon_error_x")[0], 0.0);
  SetArray(u, "beacon_position", {5.903, 0.0});
  SetBool(u, "beacon_valid", true);
  ASSERT_EQ(StepUntil(u, 1'000'000'000, 1'010'000'000), cosim::StepResult::kOk);
  EXPECT_TRUE(GetBool(u, "beacon_measured"));
  EXPECT_NEAR(Get(u, "beacon_error_x")[0], 0.003, 1e-12);
}

// A run that never finished its route reports no error of 0: its last step
// fails (the run is failed, a sweep leaves its metrics empty), unless
// fail_if_unmeasured is false, where `measured` stays 0.
TEST(FinalPoseError, NeverDoneFailsTheRunInsteadOfReportingZero) {
  {
    FinalPoseErrorUnit u("final");
    Make(u, 2.0);
    SetArray(u, "position", {3.0, 0.0});
    EXPECT_EQ(StepUntil(u, 0, 1'990'000'000), cosim::StepResult::kOk);
    EXPECT_EQ(u.DoStep(1'990'000'000, kStep), cosim::StepResult::kError);
    EXPECT_NE(u.last_error().find("never finished"), std::string::npos) << u.last_error();
  }
  {
    FinalPoseErrorUnit u("final");
    SetBool(u, "fail_if_unmeasured", false);
    Make(u, 2.0);
    SetArray(u, "position", {3.0, 0.0});
    EXPECT_EQ(StepUntil(u, 0, 2'000'000'000), cosim::StepResult::kOk);
    EXPECT_FALSE(GetBool(u, "measured"));
  }
  {
    // Done, but the beacons never valid: fails naming the beacons.
    FinalPoseErrorUnit u("final");
    Make(u, 2.0);
    SetBool(u, "done", true);
    EXPECT_EQ(StepUntil(u, 0, 1'990'000'000), cosim::StepResult::kOk);
    EXPECT_TRUE(GetBool(u, "measured"));
    EXPECT_EQ(u.DoStep(1'990'000'000, kStep), cosim::StepResult::kError);
    EXPECT_NE(u.last_error().find("beacons"), std::string::npos) << u.last_error();
  }
  {
    // Without a beacon system (beacons: false) the true pose is enough.
    FinalPoseErrorUnit u("final");
    SetBool(u, "beacons", false);
    Make(u, 2.0);
    SetBool(u, "done", true);
    EXPECT_EQ(StepUntil(u, 0, 2'000'000'000), cosim::StepResult::kOk);
    EXPECT_TRUE(GetBool(u, "measured"));
    EXPECT_FALSE(GetBool(u, "beacon_measured"));
  }
}

// Guards Save/Restore: the done time and the taken values survive.
TEST(FinalPoseError, RestoredUnitContinues) {
  FinalPoseErrorUnit a("final");
  Make(a);
  SetArray(a, "position", {5.91, 0.0});
  SetBool(a, "done", true);
  ASSERT_EQ(StepUntil(a, 0, 300'000'000), cosim::StepResult::kOk);
  const cosim::UnitState s = a.SaveState();
  FinalPoseErrorUnit b("final");
  Make(b);
  b.RestoreState(s);
  ASSERT_EQ(StepUntil(b, 300'000'000, 600'000'000), cosim::StepResult::kOk);
  EXPECT_TRUE(GetBool(b, "measured"));
  EXPECT_NEAR(Get(b, "error_x")[0], 0.01, 1e-12);
  EXPECT_DOUBLE_EQ(Get(b, "done_time")[0], 0.0);
}

TEST(FinalPoseError, TargetIsRequired) {
  FinalPoseErrorUnit u("final");
  EXPECT_THROW(u.Initialize(), cosim::UnitError);
}

}  // namespace
}  // namespace linesim::evaluation
