// The S300's field evaluation and the safety function against their
// definitions (SICK 8010948) and the closed form of a constant-deceleration
// stop.
#include "units/safety/safety_field_unit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "../test_helpers.h"

namespace linesim::safety {
namespace {

using test_helpers::Get;
using test_helpers::SetAll;
using test_helpers::SetArray;

constexpr cosim::TimeNs kStep = 20'000'000;  // the Rob@Work 3's 20 ms control cycle
constexpr double kDeg = std::numbers::pi / 180.0;

// The S300 example field of models/sensors/sick_s300.yaml (0.6 m deep, 0.8 m
// wide) as protective field; a warning field 1.2 m deep, 1.6 m wide.
SafetyFieldUnit::FieldSet Fields() {
  return {1e9,
          {{0.05, -0.4}, {0.6, -0.4}, {0.6, 0.4}, {0.05, 0.4}},
          {{0.05, -0.8}, {1.2, -0.8}, {1.2, 0.8}, {0.05, 0.8}}};
}

// The S300's 541 ranges with a leg (radius 0.045 m) at (x, 0) of the
// scanner frame: the beams that meet it read the circle's range, the others
// no echo (0).
std::vector<double> Leg(double x) {
  std::vector<double> r(541, 0.0);
  for (int i = 0; i < 541; ++i) {
    const double a = -135.0 * kDeg + i * 0.5 * kDeg;
    const double b = x * std::cos(a);
    const double disc = b * b - (x * x - 0.045 * 0.045);
    if (disc >= 0.0) r[static_cast<std::size_t>(i)] = b - std::sqrt(disc);
  }
  return r;
}

struct Driven {
  SafetyFieldUnit u{"safety", 541, {Fields()}};
  double scans = 0.0;
  cosim::TimeNs t = 0;
  Driven(double command) {
    SetArray(u, "velocity_command", {command, 0.0});
    u.Setup(0, 0);
    u.Initialize();
  }
  // One control step; a new scan with these ranges first when given.
  void Step(const std::vector<double>* ranges) {
    if (ranges) {
      SetArray(u, "ranges", *ranges);
      SetAll(u, "scan_count", ++scans);
    }
    ASSERT_EQ(u.DoStep(t, kStep), cosim::StepResult::kOk) << u.last_error();
    t += kStep;
  }
};

// Guards against a stop on one scan, or none: a leg 0.5 m ahead (inside the
// protective field) trips it on the second scan in succession (multiple
// sampling 2: the S300's 80 ms basic response time at 40 ms per scan,
// 8010948), and from there the speed falls at 1 m/s^2 (the braking limit):
// 0.3 - 0.02 k m/s after k steps, standing after 15 (or 16, should
// 0.3 - 15 * 0.02 round above 0).
TEST(SafetyField, ProtectiveFieldStopsAfterTwoScansAtTheBrakingLimit) {
  Driven d(0.3);
  const auto inside = Leg(0.5);
  d.Step(&inside);
  EXPECT_EQ(Get(d.u, "protective_clear")[0], 1.0);
  EXPECT_EQ(Get(d.u, "velocity_command_out")[0], 0.3);
  d.Step(&inside);
  EXPECT_EQ(Get(d.u, "protective_clear")[0], 0.0);
  EXPECT_EQ(Get(d.u, "protective_stops")[0], 1.0);
  EXPECT_NEAR(Get(d.u, "velocity_command_out")[0], 0.28, 1e-12);
  for (int k = 2; k <= 16; ++k) {
    d.Step(k % 2 == 0 ? &inside : nullptr);  // a scan every 40 ms
    EXPECT_NEAR(Get(d.u, "velocity_command_out")[0], std::max(0.0, 0.3 - 0.02 * k), 1e-12);
  }
  EXPECT_EQ(Get(d.u, "velocity_command_out")[0], 0.0);
  EXPECT_EQ(Get(d.u, "yaw_rate_command_out")[0], 0.0);
  EXPECT_EQ(Get(d.u, "protective_stops")[0], 1.0);  // one infringement, one stop
}

// Guards against a resume before the restart delay or a jump back to full
// speed: once the field is clear (a scan without the leg), the robot stands
// for restart_delay (2 s = 100 steps), then the cap rises at 0.5 m/s^2.
TEST(SafetyField, ResumesAfterTheRestartDelay) {
  Driven d(0.3);
  const auto inside = Leg(0.5), clear = Leg(3.0);
  for (int k = 0; k < 20; ++k) d.Step(k % 2 == 0 ? &inside : nullptr);
  ASSERT_EQ(Get(d.u, "velocity_command_out")[0], 0.0);
  d.Step(&clear);
  EXPECT_EQ(Get(d.u, "protective_clear")[0], 1.0);
  for (int k = 1; k < 99; ++k) {
    d.Step(k % 2 == 0 ? &clear : nullptr);
    ASSERT_EQ(Get(d.u, "velocity_command_out")[0], 0.0) << "step " << k;
  }
  d.Step(nullptr);  // the 100th clear step: 2 s
  EXPECT_NEAR(Get(d.u, "velocity_command_out")[0], 0.01, 1e-12);
  for (int k = 0; k < 40; ++k) d.Step(nullptr);
  EXPECT_EQ(Get(d.u, "velocity_command_out")[0], 0.3);  // the cap is lifted
  EXPECT_EQ(Get(d.u, "speed_cap")[0], -1.0);
  // Standing from 15 steps after the trip (16 should 0.3 - 15 * 0.02 round
  // above 0) until the delay's end: 103 or 104 steps of 20 ms.
  EXPECT_NEAR(Get(d.u, "time_stopped")[0], 0.02 * 103.5, 0.01 + 1e-9);
}

// Guards against counting a person's legs instead of stops: legs walking
// out of the field break it again on alternate scans while the robot
// stands; that extends the stop (its restart delay starts again), it is
// not another one. After the delay has run out, a new infringement is.
TEST(SafetyField, AnInfringementDuringAStopExtendsIt) {
  Driven d(0.3);
  const auto inside = Leg(0.5), clear = Leg(3.0);
  for (int k = 0; k < 20; ++k) d.Step(k % 2 == 0 ? &inside : nullptr);
  ASSERT_EQ(Get(d.u, "velocity_command_out")[0], 0.0);
  for (int k = 0; k < 10; ++k) {  // clear, broken, clear, ...: 2 scans each
    const auto& ranges = (k / 2) % 2 == 0 ? clear : inside;
    d.Step(&ranges);
    d.Step(nullptr);
  }
  EXPECT_EQ(Get(d.u, "protective_stops")[0], 1.0);
  EXPECT_EQ(Get(d.u, "velocity_command_out")[0], 0.0);
  for (int k = 0; k < 150; ++k) d.Step(k % 2 == 0 ? &clear : nullptr);  // 3 s > 2 s delay
  ASSERT_GT(Get(d.u, "velocity_command_out")[0], 0.0);
  d.Step(&inside);
  d.Step(&inside);
  EXPECT_EQ(Get(d.u, "protective_stops")[0], 2.0);
}

// Guards against the warning field stopping the robot or not acting: a leg
// 1.0 m ahead (outside the protective field, inside the warning field)
// brings 0.5 m/s down to warning_speed (0.3 m/s) at 1 m/s^2; a leg 1.5 m
// ahead (outside both) changes nothing, bit for bit.
TEST(SafetyField, WarningFieldSlowsOutsideNothing) {
  Driven d(0.5);
  const auto warn = Leg(1.0);
  for (int k = 0; k < 30; ++k) d.Step(k % 2 == 0 ? &warn : nullptr);
  EXPECT_EQ(Get(d.u, "protective_clear")[0], 1.0);
  EXPECT_EQ(Get(d.u, "warning_clear")[0], 0.0);
  EXPECT_NEAR(Get(d.u, "velocity_command_out")[0], 0.3, 1e-12);
  EXPECT_EQ(Get(d.u, "protective_stops")[0], 0.0);

  Driven e(0.5);
  SetAll(e.u, "yaw_rate_command", 0.123);
  const auto outside = Leg(1.5);
  for (int k = 0; k < 30; ++k) {
    e.Step(k % 2 == 0 ? &outside : nullptr);
    ASSERT_EQ(Get(e.u, "velocity_command_out")[0], 0.5);
    ASSERT_EQ(Get(e.u, "yaw_rate_command_out")[0], 0.123);
  }
  EXPECT_EQ(Get(e.u, "warning_clear")[0], 1.0);
}

// Guards against field sets that do not switch with speed (8010948:
// monitoring cases by the vehicle's speed): below 0.2 m/s a 0.3 m deep
// protective field, above it 0.6 m; a leg at 0.45 m trips only the fast one.
TEST(SafetyField, FieldSetSwitchesWithSpeed) {
  const SafetyFieldUnit::FieldSet slow{
      0.2, {{0.05, -0.4}, {0.3, -0.4}, {0.3, 0.4}, {0.05, 0.4}}, {}};
  const SafetyFieldUnit::FieldSet fast{
      1e9, {{0.05, -0.4}, {0.6, -0.4}, {0.6, 0.4}, {0.05, 0.4}}, {}};
  const auto leg = Leg(0.45);
  for (const double speed : {0.1, 0.5}) {
    SafetyFieldUnit u("safety", 541, {slow, fast});
    SetArray(u, "velocity_command", {speed, 0.0});
    u.Setup(0, 0);
    u.Initialize();
    cosim::TimeNs t = 0;
    for (int k = 1; k <= 3; ++k) {
      SetArray(u, "ranges", leg);
      SetAll(u, "scan_count", k);
      ASSERT_EQ(u.DoStep(t, kStep), cosim::StepResult::kOk);
      t += kStep;
    }
    EXPECT_EQ(Get(u, "field_set")[0], speed < 0.2 ? 0.0 : 1.0);
    EXPECT_EQ(Get(u, "protective_clear")[0], speed < 0.2 ? 1.0 : 0.0) << speed;
  }
}

// Guards issue 37: a restart_delay of 9.2e9 s or more overflowed its
// conversion to nanoseconds (llround(9.3e18) is not an int64) and the robot
// restarted at once, as with a delay of 0. Such a value is refused before
// the run, naming the limit; the longest delay linesim represents holds the
// robot (no restart within a run).
TEST(SafetyField, RestartDelayIsATimeWithinTheLimit) {
  Driven d(0.3);
  const auto ref = *d.u.variables().Find("restart_delay");
  for (double bad : {9.3e9, 1e10, -1.0, std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::infinity()}) {
    d.u.variables().SetReal(ref, bad);
    const auto problems = d.u.CheckParameters();
    ASSERT_EQ(problems.size(), 1u) << bad;
    EXPECT_EQ(problems[0].variable, "restart_delay");
  }
  d.u.variables().SetReal(ref, 1e10);
  EXPECT_NE(d.u.CheckParameters()[0].message.find("4.6e9 s is the longest time"),
            std::string::npos);

  Driven held(0.3);
  held.u.variables().SetReal(ref, cosim::kMaxTimeSeconds);
  held.u.Initialize();
  const auto inside = Leg(0.5), clear = Leg(3.0);
  for (int k = 0; k < 20; ++k) held.Step(k % 2 == 0 ? &inside : nullptr);
  ASSERT_EQ(Get(held.u, "velocity_command_out")[0], 0.0);
  for (int k = 0; k < 500; ++k) held.Step(k % 2 == 0 ? &clear : nullptr);  // 10 s clear
  EXPECT_EQ(Get(held.u, "velocity_command_out")[0], 0.0);
}

// Guards issue 37: a collinear or zero-area protective field was accepted
// and silently disabled the stop (no beam point is ever inside a line):
// refused, as a self-intersecting one and a degenerate warning field are.
TEST(SafetyField, RefusesDegenerateFields) {
  const auto refused = [](SafetyFieldUnit::FieldSet set, const std::string& text) {
    try {
      SafetyFieldUnit u("safety", 541, {std::move(set)});
    } catch (const cosim::UnitError& e) {
      return std::string(e.what()).find(text) != std::string::npos;
    }
    return false;
  };
  EXPECT_TRUE(refused({1e9, {{0.1, 0}, {0.5, 0}, {0.9, 0}}, {}}, "protective field has zero area"));
  EXPECT_TRUE(refused({1e9, {{0, 0}, {1, 1}, {1, 0}, {0, 1}}, {}}, "self-intersecting"));
  EXPECT_TRUE(refused({1e9, {{0, 0}, {1, 0}}, {}}, "at least 3 corners"));
  EXPECT_TRUE(refused({1e9, Fields().protective, {{0, 0}, {1, 0}, {2, 0}}}, "warning field"));
  EXPECT_FALSE(refused(Fields(), ""));
}

TEST(SafetyField, InsidePolygon) {
  const std::vector<std::array<double, 2>> tri = {{0, 0}, {1, 0}, {0, 1}};
  EXPECT_TRUE(SafetyFieldUnit::Inside(tri, 0.2, 0.2));
  EXPECT_FALSE(SafetyFieldUnit::Inside(tri, 0.6, 0.6));
}

}  // namespace
}  // namespace linesim::safety
