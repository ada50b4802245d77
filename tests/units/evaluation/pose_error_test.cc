#include "units/evaluation/pose_error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "tests/units/test_helpers.h"

namespace linesim::evaluation {
namespace {

using test_helpers::Get;
using test_helpers::SetArray;

constexpr double kPi = std::numbers::pi;
constexpr cosim::TimeNs kStep = 10'000'000;

void Set(cosim::Unit& u, const std::string& name, double v) {
  u.variables().SetReal(*u.variables().Find(name), v);
}

// Expected by hand: errors (3, 4) m -> 5 m and (0, 0) -> 0: max 5,
// rms sqrt(25 / 2); yaw errors 0.1 and -0.3: max 0.3, rms sqrt(0.1 / 2).
TEST(PoseError, MaximumAndRootMeanSquareOverTheRun) {
  PoseErrorUnit u("e");
  u.Initialize();
  SetArray(u, "true_position", {1.0, 2.0});
  SetArray(u, "estimated_position", {4.0, 6.0});
  Set(u, "true_yaw", 0.5);
  Set(u, "estimated_yaw", 0.6);
  ASSERT_EQ(u.DoStep(0, kStep), cosim::StepResult::kOk);
  EXPECT_NEAR(Get(u, "position_error")[0], 5.0, 1e-15);
  SetArray(u, "estimated_position", {1.0, 2.0});
  Set(u, "estimated_yaw", 0.2);
  ASSERT_EQ(u.DoStep(kStep, kStep), cosim::StepResult::kOk);
  EXPECT_NEAR(Get(u, "max_position_error")[0], 5.0, 1e-15);
  EXPECT_NEAR(Get(u, "rms_position_error")[0], std::sqrt(12.5), 1e-14);
  EXPECT_NEAR(Get(u, "max_yaw_error")[0], 0.3, 1e-15);
  EXPECT_NEAR(Get(u, "rms_yaw_error")[0], std::sqrt((0.01 + 0.09) / 2), 1e-15);
}

// Guards the wrap: headings 179 deg and -179 deg are 2 deg apart, not 358.
TEST(PoseError, YawErrorIsWrapped) {
  PoseErrorUnit u("e");
  Set(u, "true_yaw", kPi - 0.01);
  Set(u, "estimated_yaw", -kPi + 0.01);
  u.Initialize();
  EXPECT_NEAR(Get(u, "yaw_error")[0], 0.02, 1e-12);
  Set(u, "true_yaw", -kPi + 0.01);
  Set(u, "estimated_yaw", kPi - 0.01);
  u.UpdateOutputs();
  EXPECT_NEAR(Get(u, "yaw_error")[0], -0.02, 1e-12);
}

// A restored unit continues with the statistics it had when saved.
TEST(PoseError, RestoredUnitContinuesTheStatistics) {
  PoseErrorUnit u("e");
  u.Initialize();
  SetArray(u, "estimated_position", {0.3, 0.0});
  ASSERT_EQ(u.DoStep(0, kStep), cosim::StepResult::kOk);
  const cosim::UnitState saved = u.SaveState();
  SetArray(u, "estimated_position", {0.0, 0.0});
  ASSERT_EQ(u.DoStep(kStep, kStep), cosim::StepResult::kOk);
  const double rms = Get(u, "rms_position_error")[0];
  u.RestoreState(saved);  // restores the inputs too
  SetArray(u, "estimated_position", {0.0, 0.0});
  ASSERT_EQ(u.DoStep(kStep, kStep), cosim::StepResult::kOk);
  EXPECT_EQ(Get(u, "rms_position_error")[0], rms);
  EXPECT_NEAR(rms, std::sqrt(0.09 / 2), 1e-15);
}

}  // namespace
}  // namespace linesim::evaluation
