#include "units/sensors/wheel_encoder_unit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "tests/units/test_helpers.h"

namespace linesim::sensors {
namespace {

using cosim::Causality;
using cosim::TimeNs;
using test_helpers::Get;
using test_helpers::SetAll;
using test_helpers::SetArray;

constexpr TimeNs kMs = 1'000'000;
constexpr double kTwoPi = 2.0 * std::numbers::pi;
// The controller cycle of both robots (docs/references.md): the encoder is
// read once per 20 ms.
constexpr TimeNs kCycle = 20 * kMs;

// Husky A200: 78,000 encoder ticks per metre (Clearpath Husky user manual)
// on a 0.1651 m wheel (husky_description URDF): 78000 * 2 pi * 0.1651 =
// 80913.6 counts per wheel revolution. (Cross-check: a 1024-count encoder on
// the motor through the 79:1 gearhead gives 1024 * 79 / (2 pi 0.1651) =
// 77983 ticks per metre.)
const double kHuskyCpr = 78000.0 * kTwoPi * 0.1651;
// Rob@Work 3, ASSUMPTION (its encoders are not published): a 1024-count
// encoder decoded x4 (4096 counts per motor revolution) on the maxon RE 40
// stand-in motors, times the drive gear 21 and the steering belt 4
// (raw3-1 configuration): 86016 and 16384 counts per joint revolution.
constexpr double kRaw3DriveCpr = 4096.0 * 21.0;
constexpr double kRaw3SteerCpr = 4096.0 * 4.0;

void Start(WheelEncoderUnit& u) {
  u.Setup(0, 1000 * 1000 * kMs);
  u.Initialize();
}

// One sample as the master takes it: new inputs, outputs, then the step.
std::vector<double> Sample(WheelEncoderUnit& u, TimeNs t, const std::vector<double>& angle) {
  SetArray(u, "angle", angle);
  u.UpdateOutputs();
  const auto counts = Get(u, "counts");
  EXPECT_EQ(u.DoStep(t, kCycle), cosim::StepResult::kOk);
  return counts;
}

TEST(WheelEncoderUnit, DeclaresItsVariables) {
  WheelEncoderUnit u("enc", 8);
  test_helpers::ExpectTable(u, {{"counts_per_revolution", Causality::kParameter, "1", 8},
                                {"hysteresis", Causality::kParameter, "1", 0},
                                {"angle", Causality::kInput, "rad", 8},
                                {"counts", Causality::kOutput, "1", 8, {"angle"}},
                                {"rate", Causality::kOutput, "rad/s", 8, {"angle"}}});
}

// Guards the counting law: an ideal decoder holds floor(angle * cpr / 2 pi)
// (its definition), up and down through zero, for each channel's own cpr.
TEST(WheelEncoderUnit, CountsAreTheFloorOfTheAngleInCountsBothWays) {
  WheelEncoderUnit u("enc", 2);
  SetArray(u, "counts_per_revolution", {kHuskyCpr, kRaw3SteerCpr});
  SetArray(u, "angle", {0.0, 0.0});
  Start(u);
  TimeNs t = 0;
  std::vector<double> angles;
  // Up to 1.3 rad, down to -2.1 rad, up to -0.4 rad, in uneven steps.
  for (double a = 0.0; a < 1.3; a += 0.0123) angles.push_back(a);
  for (double a = 1.3; a > -2.1; a -= 0.0377) angles.push_back(a);
  for (double a = -2.1; a < -0.4; a += 0.00071) angles.push_back(a);
  bool saw_negative = false;
  for (double a : angles) {
    const auto counts = Sample(u, t, {a, -a});
    EXPECT_EQ(counts[0], std::floor(a * kHuskyCpr / kTwoPi)) << "angle " << a;
    EXPECT_EQ(counts[1], std::floor(-a * kRaw3SteerCpr / kTwoPi)) << "angle " << -a;
    saw_negative = saw_negative || counts[0] < 0.0;
    t += kCycle;
  }
  EXPECT_TRUE(saw_negative);
}

// Guards the Husky's calibration: 1 m of rolling without slip is
// 1 / 0.1651 rad of wheel and reads 78,000 ticks (manual), to the count.
TEST(WheelEncoderUnit, HuskyReads78000TicksPerMetre) {
  WheelEncoderUnit u("enc", 1);
  SetAll(u, "counts_per_revolution", kHuskyCpr);
  Start(u);
  TimeNs t = 0;
  for (int metres = 1; metres <= 10; ++metres) {
    const auto counts = Sample(u, t, {metres / 0.1651});
    EXPECT_NEAR(counts[0], 78000.0 * metres, 1.0) << metres << " m";
    t += kCycle;
  }
}

// Guards the rate: the count difference over the 20 ms sample times
// 2 pi / cpr, exactly (a driver's computation), hence within one count's
// quantum 2 pi / cpr / dt of the true rate, and 0 at the first sample.
TEST(WheelEncoderUnit, RateIsTheCountDifferenceOverTheSampleInterval) {
  WheelEncoderUnit u("enc", 1);
  SetAll(u, "counts_per_revolution", kRaw3DriveCpr);
  Start(u);
  const double omega = 5.0;  // rad/s, about 0.4 m/s on the 0.08 m wheel
  const double quantum = kTwoPi / kRaw3DriveCpr / 0.02;
  double previous = 0.0;
  for (int k = 0; k < 200; ++k) {
    const TimeNs t = k * kCycle;
    SetArray(u, "angle", {-omega * cosim::NsToSeconds(t)});  // turning backwards
    u.UpdateOutputs();
    const double counts = Get(u, "counts")[0];
    const double rate = Get(u, "rate")[0];
    if (k == 0) {
      EXPECT_EQ(rate, 0.0);
    } else {
      EXPECT_DOUBLE_EQ(rate, (counts - previous) * kTwoPi / kRaw3DriveCpr / 0.02);
      EXPECT_NEAR(rate, -omega, quantum * 1.0000001);
    }
    previous = counts;
    ASSERT_EQ(u.DoStep(t, kCycle), cosim::StepResult::kOk);
  }
}

// Guards the sampling instant under a Gauss-Seidel master, which hands a
// unit its sources' end-of-step values right before DoStep: the count
// committed is the one sampled at the communication point, so the next rate
// spans the whole 20 ms (the ramp's exact rate within one count's quantum),
// not the 19 ms left after a 1 ms source step.
TEST(WheelEncoderUnit, CommitsTheSampleTakenAtTheCommunicationPoint) {
  WheelEncoderUnit u("enc", 1);
  SetAll(u, "counts_per_revolution", kRaw3DriveCpr);
  Start(u);
  const double omega = 5.0;
  const double quantum = kTwoPi / kRaw3DriveCpr / 0.02;
  double sum = 0.0;
  const int n = 500;
  for (int k = 0; k <= n; ++k) {
    const double t_s = 0.02 * k;
    SetArray(u, "angle", {omega * t_s});
    u.UpdateOutputs();
    if (k > 0) {
      EXPECT_NEAR(Get(u, "rate")[0], omega, quantum * 1.0000001) << k;
      sum += Get(u, "rate")[0];
    }
    SetArray(u, "angle", {omega * (t_s + 0.001)});  // the source's value at t + 1 ms
    ASSERT_EQ(u.DoStep(k * kCycle, kCycle), cosim::StepResult::kOk);
  }
  // The mean telescopes: (c_n - c_0) over n intervals, within one count.
  EXPECT_NEAR(sum / n, omega, quantum / n * 1.0000001);
}

// Guards the hysteresis model: after counting up past an edge, a shaft that
// falls back less than `hysteresis` counts keeps the count; beyond, it
// counts down. With 0 it would drop at once (floor).
TEST(WheelEncoderUnit, HysteresisHoldsTheCountNearAnEdge) {
  WheelEncoderUnit u("enc", 1);
  const double cpr = 1000.0;
  SetAll(u, "counts_per_revolution", cpr);
  SetAll(u, "hysteresis", 0.3);
  Start(u);
  const auto angle = [&](double counts) { return counts * kTwoPi / cpr; };
  EXPECT_EQ(Sample(u, 0, {angle(5.1)})[0], 5.0);
  EXPECT_EQ(Sample(u, kCycle, {angle(4.8)})[0], 5.0);      // 0.2 below the edge at 5
  EXPECT_EQ(Sample(u, 2 * kCycle, {angle(4.65)})[0], 4.0);  // 0.35 below: down
  EXPECT_EQ(Sample(u, 3 * kCycle, {angle(4.95)})[0], 4.0);  // up only at the next edge
  EXPECT_EQ(Sample(u, 4 * kCycle, {angle(5.05)})[0], 5.0);
}

TEST(WheelEncoderUnit, ScalarCountsPerRevolutionIsBroadcast) {
  WheelEncoderUnit u("enc", 3);
  SetAll(u, "counts_per_revolution", 4096.0);
  SetArray(u, "angle", {kTwoPi, -kTwoPi, 0.5 * kTwoPi});
  Start(u);
  u.UpdateOutputs();
  EXPECT_EQ(Get(u, "counts"), (std::vector<double>{4096.0, -4096.0, 2048.0}));
}

TEST(WheelEncoderUnit, RefusesBadParameters) {
  EXPECT_THROW(WheelEncoderUnit("enc", 0), cosim::UnitError);
  {
    WheelEncoderUnit u("enc", 2);
    try {
      Start(u);
      ADD_FAILURE() << "no counts_per_revolution accepted";
    } catch (const cosim::UnitError& e) {
      EXPECT_NE(std::string(e.what()).find("counts_per_revolution"), std::string::npos)
          << e.what();
    }
  }
  WheelEncoderUnit u("enc", 2);
  SetArray(u, "counts_per_revolution", {4096.0, -1.0});
  SetAll(u, "hysteresis", 1.0);
  const auto problems = u.CheckParameters();
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0].variable, "counts_per_revolution");
  EXPECT_EQ(problems[0].index, 1u);
  EXPECT_EQ(problems[1].variable, "hysteresis");
}

// Guards SaveInternal/RestoreInternal: a unit restored mid-run (into a new
// unit) gives the same counts and rates bit for bit as the original.
TEST(WheelEncoderUnit, RestoredUnitContinuesIdentically) {
  const auto make = [] {
    auto u = std::make_unique<WheelEncoderUnit>("enc", 2);
    SetArray(*u, "counts_per_revolution", {kRaw3DriveCpr, kRaw3SteerCpr});
    SetAll(*u, "hysteresis", 0.25);
    Start(*u);
    return u;
  };
  const auto angle = [](int k) {
    return std::vector<double>{std::sin(0.05 * k) * 3.0, std::cos(0.031 * k)};
  };
  auto a = make();
  for (int k = 0; k < 50; ++k) Sample(*a, k * kCycle, angle(k));
  const cosim::UnitState saved = a->SaveState();
  auto b = make();
  b->RestoreState(saved);
  for (int k = 50; k < 150; ++k) {
    SetArray(*a, "angle", angle(k));
    SetArray(*b, "angle", angle(k));
    a->UpdateOutputs();
    b->UpdateOutputs();
    ASSERT_TRUE(test_helpers::SameBits(test_helpers::Outputs(*a), test_helpers::Outputs(*b)))
        << "sample " << k;
    ASSERT_EQ(a->DoStep(k * kCycle, kCycle), cosim::StepResult::kOk);
    ASSERT_EQ(b->DoStep(k * kCycle, kCycle), cosim::StepResult::kOk);
  }
}

}  // namespace
}  // namespace linesim::sensors
