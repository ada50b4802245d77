#include "units/control/drive_rate_loop.h"

#include <gtest/gtest.h>

#include <vector>

namespace linesim::control {
namespace {

DriveRateLoop::Gains TestGains() {
  DriveRateLoop::Gains g;
  g.feedforward = 0.5;
  g.acceleration_feedforward = 0.1;
  g.kp = 0.5;
  g.ki = 5.0;
  g.max_rate = 10.0;
  g.max_acceleration = 20.0;
  return g;
}

TEST(ClampSymmetric, LimitsBothSigns) {
  EXPECT_EQ(ClampSymmetric(3.0, 2.0), 2.0);
  EXPECT_EQ(ClampSymmetric(-3.0, 2.0), -2.0);
  EXPECT_EQ(ClampSymmetric(1.5, 2.0), 1.5);
  EXPECT_EQ(ClampSymmetric(-1.5, 2.0), -1.5);
}

// The reference ramps at max_acceleration towards the set point, which is
// limited to max_rate; the voltage feeds the mean reference over the period
// and its slope.
TEST(DriveRateLoop, RampsTowardsLimitedSetPoint) {
  DriveRateLoop loop(1);
  loop.gains = TestGains();
  EXPECT_EQ(loop.Voltage(0, 0.0, 0.0), 0.0);
  const double dt = 0.1;
  loop.Step(0, 100.0, 0.0, 0.0, dt, 24.0);
  EXPECT_EQ(loop.reference(0), 0.0);  // the new reference applies one sample later
  loop.Step(0, 100.0, 0.0, dt, dt, 24.0);
  EXPECT_DOUBLE_EQ(loop.reference(0), 2.0);
  for (int k = 0; k < 10; ++k) loop.Step(0, 100.0, loop.reference(0), dt, dt, 24.0);
  EXPECT_DOUBLE_EQ(loop.reference(0), 10.0);
  // At the limit the reference holds: no slope, feedforward on the rate.
  EXPECT_DOUBLE_EQ(loop.Voltage(0, 10.0, dt), 0.5 * 10.0);
}

// While the output saturates in the error's direction the integral holds.
TEST(DriveRateLoop, IntegralStopsWhileSaturated) {
  DriveRateLoop loop(1);
  loop.gains = TestGains();
  const double dt = 0.1;
  loop.Step(0, 10.0, 0.0, 0.0, dt, 24.0);
  loop.Step(0, 10.0, 0.0, dt, dt, 24.0);  // reference 2, next 4
  std::vector<double> before;
  loop.AppendState(before);
  // Measured far behind: the voltage exceeds a 1 V supply, error positive.
  loop.Step(0, 10.0, -100.0, dt, dt, 1.0);
  std::vector<double> after;
  loop.AppendState(after);
  EXPECT_EQ(after[2], before[2]);
}

TEST(DriveRateLoop, SaveRestoreIsBitForBit) {
  DriveRateLoop a(2);
  a.gains = TestGains();
  for (int k = 0; k < 5; ++k) {
    a.Step(0, 3.0, 0.1 * k, 0.02, 0.02, 24.0);
    a.Step(1, -7.0, -0.3 * k, 0.02, 0.02, 24.0);
  }
  std::vector<double> saved{42.0};
  a.AppendState(saved);
  ASSERT_EQ(saved.size(), 1 + DriveRateLoop::kStatePerChannel * 2);
  DriveRateLoop b(2);
  b.gains = TestGains();
  EXPECT_EQ(b.RestoreState(saved.cbegin() + 1), saved.cend());
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(a.Voltage(i, 0.7, 0.02), b.Voltage(i, 0.7, 0.02));
    a.Step(i, 1.0, 0.7, 0.02, 0.02, 24.0);
    b.Step(i, 1.0, 0.7, 0.02, 0.02, 24.0);
  }
  std::vector<double> sa, sb;
  a.AppendState(sa);
  b.AppendState(sb);
  EXPECT_EQ(sa, sb);
}

}  // namespace
}  // namespace linesim::control
