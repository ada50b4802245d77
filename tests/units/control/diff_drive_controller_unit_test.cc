#include "units/control/diff_drive_controller_unit.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cosim/master.h"
#include "cosim/system.h"
#include "cosim/time.h"
#include "tests/units/test_helpers.h"
#include "units/motors/dc_motor_unit.h"

namespace linesim::control {
namespace {

using cosim::TimeNs;
using test_helpers::Get;
using test_helpers::Outputs;
using test_helpers::SameBits;
using test_helpers::SetAll;
using test_helpers::SetArray;

constexpr TimeNs kMs = 1'000'000;
constexpr TimeNs kPeriod = 20 * kMs;  // sampled like the swerve controller
constexpr double kPeriodS = 0.02;

// Husky A200 (Clearpath URDF: wheel radius 0.1651 m, wheel separation
// 0.5708 m; husky_control ROS diff-drive config: wheel separation
// multiplier 1.875, 3.0 m/s^2) with the drive motor of
// models/motors/husky_drive.yaml: the maxon RE 40 148877 stand-in (k_t =
// k_e = 30.2 mNm/A, R 0.299 Ohm, rotor 142 g.cm^2; maxon data sheet)
// behind a 79:1 gear of efficiency 0.7 (ASSUMPTIONS, see that file).
constexpr double kRadius = 0.1651;
constexpr double kTrack = 0.5708 * 1.875;
constexpr double kKe = 30.2e-3, kOhm = 0.299, kRotor = 142e-7, kGear = 79.0, kEta = 0.7;
// Joint inertia per side, as the drive-train model computes it (load plus
// the rotor reflected, eta N^2 J_rotor = 0.0620 kg.m^2): half the 50 kg
// robot on the wheel radius, 25 r^2 = 0.6815 kg.m^2 (straight driving).
constexpr double kLoad = 25.0 * kRadius * kRadius;
constexpr double kJoint = kLoad + kEta * kGear * kGear * kRotor;
constexpr double kFeedforward = kKe * kGear;                                // k_e N = 2.386 V.s/rad
constexpr double kAccelFeedforward = kJoint * kOhm / (kEta * kGear * kKe);  // 0.133 V.s^2/rad
// Back-EMF damping at the wheel, eta N^2 k_t k_e / R = 13.3 N.m.s, and the
// mechanical time constant J / B = 56 ms.
constexpr double kDamping = kEta * kGear * kGear * kKe * kKe / kOhm;
constexpr double kTau = kJoint / kDamping;
// Gains for the 20 ms sample (ZOH model of the drive: a = exp(-T / tau) =
// 0.70 per sample, rad/s per volt 1 / (k_e N)): kp 2 V.s/rad puts the
// proportional pole at a - (1 - a) kp / (k_e N) = 0.45 loaded and -0.72 for
// a wheel in the air (J about 0.1 kg.m^2, a = 0.06), both stable; ki 10 V/rad
// adds the integrator pole near 0.95 per sample (loaded).
constexpr double kKp = 2.0, kKi = 10.0;
constexpr double kMaxRate = 8.0;                    // 1.32 m/s at the rim, below no-load 10.1 rad/s
constexpr double kMaxAcceleration = 3.0 / kRadius;  // 3.0 m/s^2 at the rim (ROS config)

void SetHusky(cosim::Unit& u) {
  SetAll(u, "wheel_radius", kRadius);
  SetAll(u, "effective_track", kTrack);
  SetAll(u, "drive_feedforward", kFeedforward);
  SetAll(u, "drive_acceleration_feedforward", kAccelFeedforward);
  SetAll(u, "drive_kp", kKp);
  SetAll(u, "drive_ki", kKi);
  SetAll(u, "max_rate", kMaxRate);
  SetAll(u, "max_acceleration", kMaxAcceleration);
  SetAll(u, "max_voltage", 24.0);
}

struct HuskyController : DiffDriveControllerUnit {
  explicit HuskyController(std::string name = "ctl") : DiffDriveControllerUnit(std::move(name)) {
    SetHusky(*this);
  }
};

void SetCommand(cosim::Unit& u, double v, double omega) {
  SetArray(u, "velocity_command", {v, 0.0});
  SetAll(u, "yaw_rate_command", omega);
}

void Sample(DiffDriveControllerUnit& u, TimeNs t) {
  u.UpdateOutputs();
  ASSERT_EQ(u.DoStep(t, kPeriod), cosim::StepResult::kOk) << u.last_error();
}

// Guards the interface the loader and the robot assembly are written
// against (names, units, sizes, feedthrough).
TEST(DiffDriveControllerUnit, VariableTable) {
  DiffDriveControllerUnit u("ctl");
  EXPECT_EQ(u.type_name(), "diff_drive_controller");
  using C = cosim::Causality;
  const std::vector<test_helpers::ExpectedVariable> expected = {
      {"wheel_radius", C::kParameter, "m", 0, {}},
      {"effective_track", C::kParameter, "m", 0, {}},
      {"drive_feedforward", C::kParameter, "V.s/rad", 0, {}},
      {"drive_acceleration_feedforward", C::kParameter, "V.s2/rad", 0, {}},
      {"drive_kp", C::kParameter, "V.s/rad", 0, {}},
      {"drive_ki", C::kParameter, "V/rad", 0, {}},
      {"max_rate", C::kParameter, "rad/s", 0, {}},
      {"max_acceleration", C::kParameter, "rad/s2", 0, {}},
      {"max_voltage", C::kParameter, "V", 0, {}},
      {"velocity_command", C::kInput, "m/s", 2, {}},
      {"yaw_rate_command", C::kInput, "rad/s", 0, {}},
      {"drive_rate", C::kInput, "rad/s", 2, {}},
      {"drive_voltage", C::kOutput, "V", 2, {"drive_rate"}},
      {"drive_rate_target", C::kOutput, "rad/s", 2, {}}};
  test_helpers::ExpectTable(u, expected);
}

// Guards against a robot description that forgets a parameter: none has a
// default, each is named, and Initialize refuses the unit.
TEST(DiffDriveControllerUnit, MissingParametersAreRefusedByName) {
  DiffDriveControllerUnit u("base");
  const std::vector<std::string> required = {
      "wheel_radius", "effective_track", "drive_feedforward", "drive_acceleration_feedforward",
      "drive_kp",     "drive_ki",        "max_rate",          "max_acceleration",
      "max_voltage"};
  const auto problems = u.CheckParameters();
  ASSERT_EQ(problems.size(), required.size());
  for (std::size_t k = 0; k < required.size(); ++k) {
    EXPECT_EQ(problems[k].variable, required[k]);
    EXPECT_EQ(problems[k].message, "must be set (robot-specific: no default)");
  }
  try {
    u.Initialize();
    FAIL() << "unset parameters accepted";
  } catch (const cosim::UnitError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("unit 'base'"), std::string::npos) << what;
    for (const auto& name : required) EXPECT_NE(what.find(name), std::string::npos) << name;
  }
  SetHusky(u);
  EXPECT_TRUE(u.CheckParameters().empty());
  SetAll(u, "effective_track", 0.0);
  SetAll(u, "drive_ki", -1.0);
  const auto bad = u.CheckParameters();
  ASSERT_EQ(bad.size(), 2u);
  EXPECT_EQ(bad[0].variable, "effective_track");
  EXPECT_EQ(bad[0].message, "must be > 0, got 0");
  EXPECT_EQ(bad[1].variable, "drive_ki");
  EXPECT_EQ(bad[1].message, "must be >= 0, got -1");
  EXPECT_EQ(u.variables().info(*u.variables().Find("drive_ki")).rule.Text(), "required, >= 0");
}

// Guards the kinematics (signs, sides, effective track) against the
// analytic wheel rates w = (v -+ omega T / 2) / r: 0.5 m/s and 0.4 rad/s
// with T = 1.070 m, r = 0.1651 m give 1.732 and 4.325 rad/s, reached after
// the ramp (4.325 rad/s at 18.2 rad/s^2 is 12 samples, plus one of delay).
// The sideways command is ignored.
TEST(DiffDriveControllerUnit, KinematicsAreTheAnalyticWheelRates) {
  HuskyController u;
  u.Initialize();
  SetArray(u, "velocity_command", {0.5, 0.3});
  SetAll(u, "yaw_rate_command", 0.4);
  for (int k = 0; k < 20; ++k) Sample(u, k * kPeriod);
  const auto w = Get(u, "drive_rate_target");
  EXPECT_NEAR(w[0], (0.5 - 0.2 * kTrack) / kRadius, 1e-12);
  EXPECT_NEAR(w[1], (0.5 + 0.2 * kTrack) / kRadius, 1e-12);
  // Turning in place: opposite rates, omega T / (2 r).
  SetCommand(u, 0.0, -1.0);
  for (int k = 20; k < 60; ++k) Sample(u, k * kPeriod);
  const auto spin = Get(u, "drive_rate_target");
  EXPECT_NEAR(spin[0], 0.5 * kTrack / kRadius, 1e-12);
  EXPECT_NEAR(spin[1], -0.5 * kTrack / kRadius, 1e-12);
}

// Guards against distorting a too fast command: both sides are scaled by
// one factor, so the faster runs at max_rate and the ratio (the curvature)
// is kept; and the ramp never exceeds max_acceleration per sample.
TEST(DiffDriveControllerUnit, TooFastCommandKeepsItsCurvature) {
  HuskyController u;
  u.Initialize();
  SetCommand(u, 1.5, 1.0);
  std::vector<double> left = {0.0};
  for (int k = 0; k < 60; ++k) {
    Sample(u, k * kPeriod);
    left.push_back(Get(u, "drive_rate_target")[0]);
  }
  for (std::size_t k = 1; k < left.size(); ++k) {
    EXPECT_LE(std::abs(left[k] - left[k - 1]), kMaxAcceleration * kPeriodS + 1e-12) << k;
  }
  const auto w = Get(u, "drive_rate_target");
  const double wl = (1.5 - 0.5 * kTrack) / kRadius, wr = (1.5 + 0.5 * kTrack) / kRadius;
  EXPECT_NEAR(w[1], kMaxRate, 1e-12);
  EXPECT_NEAR(w[0], kMaxRate * wl / wr, 1e-12);
}

// Guards the FMI feedthrough contract: UpdateOutputs reflects a new
// measured rate at once (-kp times it with a zero reference) and changes no
// state.
TEST(DiffDriveControllerUnit, UpdateOutputsIsPure) {
  HuskyController a, b;
  a.Initialize();
  b.Initialize();
  for (auto* u : {&a, &b}) {
    SetArray(*u, "drive_rate", {1.0, -0.5});
    SetCommand(*u, 0.3, 0.1);
  }
  b.UpdateOutputs();
  b.UpdateOutputs();
  EXPECT_NEAR(Get(b, "drive_voltage")[0], -kKp * 1.0, 1e-15);
  EXPECT_NEAR(Get(b, "drive_voltage")[1], kKp * 0.5, 1e-15);
  EXPECT_EQ(a.SaveState().reals, b.SaveState().reals);
  for (int k = 0; k < 5; ++k) {
    Sample(a, k * kPeriod);
    b.UpdateOutputs();
    Sample(b, k * kPeriod);
  }
  EXPECT_TRUE(SameBits(Outputs(a), Outputs(b)));
}

// Guards saturation and anti-windup on blocked wheels (measured rate 0).
// The outputs stop at 24 V. The integral last grew when the unsaturated
// output, ff w + kp e + ki I (e = w = 0.3 m/s / r = 1.817 rad/s, the ramp
// long over), was at most 24 V, so once the wheels run at their target
// (e = 0) the voltage is at most
//   ff w + ki (I + e T) <= 24 - kp e + ki e T = 24 - 3.634 + 0.363 = 20.73 V,
// where a wound-up integrator (3 s of 1.8 rad/s error, 54 V at ki 10) would
// hold 24 V.
TEST(DiffDriveControllerUnit, SaturationAndAntiWindupOnBlockedWheels) {
  HuskyController u;
  u.Initialize();
  SetCommand(u, 0.3, 0.0);
  for (int k = 0; k < 150; ++k) Sample(u, k * kPeriod);
  for (double v : Get(u, "drive_voltage")) EXPECT_EQ(v, 24.0);
  const double w = 0.3 / kRadius;
  SetAll(u, "drive_rate", w);
  u.UpdateOutputs();
  for (double v : Get(u, "drive_voltage")) {
    EXPECT_LE(v, 24.0 - kKp * w + kKi * w * kPeriodS + 1e-9);
    EXPECT_GT(v, kFeedforward * w);  // the integral still holds some push
  }
  // Backwards: the negative limit.
  HuskyController back;
  back.Initialize();
  SetCommand(back, -0.6, 0.0);
  for (int k = 0; k < 50; ++k) Sample(back, k * kPeriod);
  for (double v : Get(back, "drive_voltage")) EXPECT_EQ(v, -24.0);
}

// Closed loop with the real DC motors (CVODE, full mode) through the
// master: controller at 20 ms, motors at 1 ms, each motor driving a pure
// inertia (half the Husky on the wheel radius) through the 79:1 gear.
struct Trace {
  std::vector<double> time_s, left, right;
};

Trace RunClosedLoop(double v, double omega, TimeNs duration) {
  cosim::System system;
  auto ctl = std::make_unique<HuskyController>();
  SetCommand(*ctl, v, omega);
  system.Add(std::move(ctl), kPeriod);
  auto drive = std::make_unique<motors::DcMotorUnit>("drive", 2, motors::MotorMode::kFull);
  SetAll(*drive, "gear_ratio", kGear);
  SetAll(*drive, "gear_efficiency", kEta);
  SetAll(*drive, "load_inertia", kLoad);
  system.Add(std::move(drive));
  system.Connect("ctl.drive_voltage", "drive.voltage");
  system.Connect("drive.speed", "ctl.drive_rate");
  cosim::MasterOptions options;
  options.base_step = kMs;
  options.stop = duration;
  options.profile = false;
  cosim::Master master(system, options);
  master.Start();
  Trace trace;
  while (master.Step()) {
    trace.time_s.push_back(cosim::NsToSeconds(master.time()));
    const auto w = Get(system.unit(1), "speed");
    trace.left.push_back(w[0]);
    trace.right.push_back(w[1]);
  }
  const cosim::RunResult result = master.Finish();
  EXPECT_TRUE(result.ok) << result.ErrorText();
  return trace;
}

// Guards against an unstable, overshooting or offset drive loop. 1.0 m/s
// (the Husky's top speed) is 6.057 rad/s, a 0.33 s ramp at 18.17 rad/s^2.
// With exact feedforwards the motor (first order at the wheel, tau =
// J / B = 56 ms) driven by the ramp's mean rate over each period leads the
// ramp inside a period by alpha t (T - t) / (2 tau), at most
// alpha T^2 / (8 tau) = 0.0163 rad/s (0.27 % of goal) at mid-period; the
// last period of the ramp leaves at most that lead as overshoot (the
// inductance, L/R = 0.28 ms, and the friction only slow the motor).
// No steady error: within 0.01 % at 2 s (integral action, pure inertia).
TEST(DiffDriveControllerUnit, ClosedLoopReachesTopSpeedWithoutOvershootOrOffset) {
  const double goal = 1.0 / kRadius;
  const double alpha = kMaxAcceleration;
  const double lead_bound = alpha * kPeriodS * kPeriodS / (8.0 * kTau);
  const Trace tr = RunClosedLoop(1.0, 0.0, 2000 * kMs);
  double peak = 0.0;
  for (std::size_t k = 0; k < tr.time_s.size(); ++k) {
    peak = std::max({peak, tr.left[k], tr.right[k]});
    EXPECT_EQ(tr.left[k], tr.right[k]) << tr.time_s[k];  // straight: both sides alike
  }
  std::cout << "husky drive 1.0 m/s: overshoot " << peak - goal << " rad/s (bound " << lead_bound
            << "), final error " << tr.left.back() - goal << " rad/s\n";
  EXPECT_LE(peak, goal + lead_bound);
  EXPECT_NEAR(tr.left.back(), goal, 1e-4 * goal);
  // Following the ramp: within 2 % of the reference's end value from
  // 0.4 s (ramp 0.33 s plus one sample of delay) on.
  for (std::size_t k = 0; k < tr.time_s.size(); ++k) {
    if (tr.time_s[k] >= 0.4) {
      EXPECT_NEAR(tr.left[k], goal, 0.02 * goal) << tr.time_s[k];
    }
  }
}

// A turn: the two sides reach their analytic rates (0.5 m/s, 0.5 rad/s),
// in opposite senses of the difference, without offset.
TEST(DiffDriveControllerUnit, ClosedLoopTurnReachesBothSideRates) {
  const Trace tr = RunClosedLoop(0.5, 0.5, 2000 * kMs);
  const double wl = (0.5 - 0.25 * kTrack) / kRadius, wr = (0.5 + 0.25 * kTrack) / kRadius;
  EXPECT_NEAR(tr.left.back(), wl, 1e-4 * wr);
  EXPECT_NEAR(tr.right.back(), wr, 1e-4 * wr);
}

// Guards against a restored unit drifting from the original (a state
// member missing from the save): scripted inputs, outputs bit for bit.
std::vector<std::vector<double>> Script(DiffDriveControllerUnit& u, int from, int to) {
  std::vector<std::vector<double>> out;
  for (int k = from; k < to; ++k) {
    const int p = k % 7;
    SetCommand(u, p < 3 ? 0.8 : -0.4, 0.3 * (p % 3 - 1));
    SetArray(u, "drive_rate", {0.4 * p, -0.3 * p + 1.0});
    u.UpdateOutputs();
    out.push_back(Outputs(u));
    EXPECT_EQ(u.DoStep(k * kPeriod, kPeriod), cosim::StepResult::kOk) << u.last_error();
    out.push_back(Outputs(u));
  }
  return out;
}

TEST(DiffDriveControllerUnit, SaveStepRestoreStepIsBitForBit) {
  HuskyController u;
  u.Initialize();
  Script(u, 0, 9);
  const cosim::UnitState saved = u.SaveState();
  const auto first = Script(u, 9, 40);
  u.RestoreState(saved);
  const auto second = Script(u, 9, 40);
  HuskyController fresh;
  fresh.RestoreState(saved);
  const auto third = Script(fresh, 9, 40);
  ASSERT_EQ(first.size(), second.size());
  for (std::size_t k = 0; k < first.size(); ++k) {
    EXPECT_TRUE(SameBits(first[k], second[k])) << k;
    EXPECT_TRUE(SameBits(first[k], third[k])) << k;
  }
  cosim::UnitState short_reals = saved;
  short_reals.reals.pop_back();
  try {
    u.RestoreState(short_reals);
    ADD_FAILURE() << "restored a truncated state";
  } catch (const cosim::UnitError& e) {
    EXPECT_NE(std::string(e.what()).find("expected 7 and 0"), std::string::npos) << e.what();
  }
}

// Guards against a NaN measurement silently poisoning the integrals.
TEST(DiffDriveControllerUnit, NonFiniteInputFailsTheStep) {
  HuskyController u;
  u.Initialize();
  SetArray(u, "drive_rate", {0.0, NAN});
  EXPECT_EQ(u.DoStep(0, kPeriod), cosim::StepResult::kError);
  EXPECT_NE(u.last_error().find("drive_rate[1]"), std::string::npos) << u.last_error();
}

}  // namespace
}  // namespace linesim::control
