#include "units/motors/dc_motor_unit.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "cosim/master.h"
#include "cosim/system.h"
#include "cosim/time.h"
#include "models/dc_motor_params.h"
#include "tests/cosim/test_units.h"
#include "tests/units/test_helpers.h"

namespace linesim::motors {
namespace {

using cosim::TimeNs;
using Vec2 = Eigen::Vector2d;
using Mat2 = Eigen::Matrix2d;
using test_helpers::Get;
using test_helpers::Outputs;
using test_helpers::SameBits;
using test_helpers::SetAll;
using test_helpers::SetArray;

constexpr TimeNs kMs = 1'000'000;

// ---------------------------------------------------------------------------
// Closed-form reference for one motor in full mode. State x = (i, w_rotor):
//   x' = A x + c,  A = [[-R/L, -k_t/L], [k_t/J, -b/J]],
//   c = (V/L, tau_load/(eta N J)),  J = J_rotor + J_load/(eta N^2).
// With constant inputs the exact solution is the matrix exponential of the
// augmented system (cosim::test_units::ExactZohStep, shared with the cosim
// tests), not a numerical integration.
struct Motor {
  // The unit's defaults (maxon RE 40 148877 datasheet, checked against the
  // datasheet in DefaultsAreTheMaxonRe40DataSheet).
  double r = models::DcMotorParams{}.resistance_ohm;
  double l = models::DcMotorParams{}.inductance_h;
  double kt = models::DcMotorParams{}.torque_constant_nm_per_a;
  double j = models::DcMotorParams{}.rotor_inertia_kgm2;
  double b = models::DcMotorParams{}.viscous_friction_nms_per_rad;
  double n = 1.0, eta = 1.0, j_load = 0.0;

  double JEff() const { return j + j_load / (eta * n * n); }
  Mat2 A() const {
    Mat2 a;
    a << -r / l, -kt / l, kt / JEff(), -b / JEff();
    return a;
  }
  Vec2 C(double volt, double tau_load) const { return {volt / l, tau_load / (eta * n * JEff())}; }
};

class Reference {
 public:
  explicit Reference(const Motor& m) : m_(m) {}
  /// State (i, w_rotor) after `t_s` seconds from x0 with constant inputs.
  Vec2 Advance(const Vec2& x0, double volt, double tau_load, double t_s) const {
    return cosim::test_units::ExactZohStep<2>(m_.A(), m_.C(volt, tau_load), x0, t_s);
  }

 private:
  Motor m_;
};

void ApplyParams(DcMotorUnit& u, const std::vector<Motor>& ms) {
  const auto put = [&](const char* name, auto field) {
    std::vector<double> v;
    for (const Motor& m : ms) v.push_back(m.*field);
    SetArray(u, name, v);
  };
  put("resistance", &Motor::r);
  put("inductance", &Motor::l);
  put("torque_constant", &Motor::kt);
  put("rotor_inertia", &Motor::j);
  put("viscous_friction", &Motor::b);
  put("gear_ratio", &Motor::n);
  put("gear_efficiency", &Motor::eta);
  if (u.mode() == MotorMode::kFull) put("load_inertia", &Motor::j_load);
}

struct MaxError {
  double current_err = 0, current_max = 0, speed_err = 0, speed_max = 0;
  void Add(double i, double i_ref, double w, double w_ref) {
    current_err = std::max(current_err, std::abs(i - i_ref));
    current_max = std::max(current_max, std::abs(i_ref));
    speed_err = std::max(speed_err, std::abs(w - w_ref));
    speed_max = std::max(speed_max, std::abs(w_ref));
  }
  double current() const { return current_err / current_max; }
  double speed() const { return speed_err / speed_max; }
};

// The acceptance bound of the brief: 1e-4 of the largest magnitude.
constexpr double kMaxRelError = 1e-4;

// One motor, full mode, constant inputs, from rest: every communication
// point against the closed form.
MaxError RunStepResponse(const Motor& m, double volt, double tau_load, TimeNs dt, TimeNs duration,
                         std::int64_t* restarts = nullptr) {
  DcMotorUnit u("m", 1, MotorMode::kFull);
  ApplyParams(u, {m});
  u.Initialize();
  SetAll(u, "voltage", volt);
  SetAll(u, "load_torque", tau_load);
  const Reference ref(m);
  MaxError e;
  for (TimeNs t = 0; t < duration; t += dt) {
    EXPECT_EQ(u.DoStep(t, dt), cosim::StepResult::kOk) << u.last_error();
    const Vec2 x = ref.Advance({0, 0}, volt, tau_load, cosim::NsToSeconds(t + dt));
    e.Add(Get(u, "current")[0], x[0], Get(u, "speed")[0], x[1] / m.n);
    // torque is defined as eta N (k_t i - b w_rotor) of the unit's own state.
    const double i = Get(u, "current")[0], w_r = Get(u, "speed")[0] * m.n;
    EXPECT_NEAR(Get(u, "torque")[0], m.eta * m.n * (m.kt * i - m.b * w_r),
                1e-12 * std::abs(m.eta * m.n * m.kt * e.current_max));
  }
  if (restarts) *restarts = u.cvode_restarts();
  return e;
}

// ---------------------------------------------------------------------------
// (a) Guards against wrong equations, signs, gear/efficiency reflection and
// an integrator that is not accurate enough at the default tolerances.
// Numbers: maxon RE 40 148877 data sheet (the DcMotorParams defaults), 24 V.
TEST(DcMotorUnit, StepResponseBareMotorMatchesClosedForm) {
  const Motor m;
  for (TimeNs dt : {1 * kMs, 10 * kMs}) {
    std::int64_t restarts = 0;
    const MaxError e = RunStepResponse(m, 24.0, 0.0, dt, 50 * kMs, &restarts);
    std::cout << "bare RE 40, 24 V, dt " << cosim::FormatSeconds(dt) << " s: max rel error current "
              << e.current() << ", speed " << e.speed() << "\n";
    EXPECT_LE(e.current(), kMaxRelError);
    EXPECT_LE(e.speed(), kMaxRelError);
    // Constant inputs: one start, never a restart (the cheap path).
    EXPECT_EQ(restarts, 1);
  }
}

// Guards against a silent wrong result (issue: hardening): an inductance of
// 1e-300 H (L / R = 3e-300 s) or a supply of 1e300 V leave CVODE unable to
// take a step of any size a double can hold around t; it used to report
// success with the current frozen at 0. The step now fails, naming the
// time and the time constants.
TEST(DcMotorUnit, AStepCvodeCannotResolveFailsInsteadOfFreezing) {
  for (const auto& [inductance, volt] : {std::pair{1e-300, 24.0}, std::pair{0.0823e-3, 1e300}}) {
    Motor m;
    m.l = inductance;
    DcMotorUnit u("m", 1, MotorMode::kFull);
    ApplyParams(u, {m});
    u.Initialize();
    SetAll(u, "voltage", volt);
    SetAll(u, "load_torque", 0.0);
    EXPECT_EQ(u.DoStep(0, kMs), cosim::StepResult::kError) << inductance << " H, " << volt << " V";
    EXPECT_NE(u.last_error().find("CVODE did not integrate the step from 0 s"), std::string::npos)
        << u.last_error();
    EXPECT_NE(u.last_error().find("L / R"), std::string::npos) << u.last_error();
  }
  // The data sheet's motor at 24 V integrates as before.
  DcMotorUnit ok("m", 1, MotorMode::kFull);
  ApplyParams(ok, {Motor{}});
  ok.Initialize();
  SetAll(ok, "voltage", 24.0);
  SetAll(ok, "load_torque", 0.0);
  EXPECT_EQ(ok.DoStep(0, kMs), cosim::StepResult::kOk) << ok.last_error();
}

// Gear 21 and efficiency 0.75 (raw3_drive.yaml) with a load inertia and a
// constant load torque: a robot held against gravity on the van ramp, i.e.
// -5 N.m at the wheel (braking), and 0.01 kg.m^2 at the output.
TEST(DcMotorUnit, StepResponseGearedWithLoadTorqueMatchesClosedForm) {
  Motor m;
  m.n = 21.0;
  m.eta = 0.75;
  m.j_load = 0.01;
  for (TimeNs dt : {1 * kMs, 10 * kMs}) {
    const MaxError e = RunStepResponse(m, 24.0, -5.0, dt, 50 * kMs);
    std::cout << "RE 40, gear 21, eta 0.75, load -5 N.m, dt " << cosim::FormatSeconds(dt)
              << " s: max rel error current " << e.current() << ", speed " << e.speed() << "\n";
    EXPECT_LE(e.current(), kMaxRelError);
    EXPECT_LE(e.speed(), kMaxRelError);
  }
}

// Guards against a wrong steady state (friction or back-EMF terms). From the
// model, d/dt = 0 gives w = k_t V / (R b + k_t^2): the data-sheet relation
// w0 = V / k_t less the friction effect. The data sheet's no-load speed is
// 7580 rpm at 24 V; the model must agree to maxon's rounding (0.5 %).
TEST(DcMotorUnit, NoLoadSteadyStateSpeed) {
  const Motor m;
  DcMotorUnit u("m", 1, MotorMode::kFull);
  u.Initialize();
  SetAll(u, "voltage", 24.0);
  // 0.3 s is 64 mechanical time constants (R J / k_t^2 = 4.7 ms).
  for (TimeNs t = 0; t < 300 * kMs; t += 10 * kMs)
    ASSERT_EQ(u.DoStep(t, 10 * kMs), cosim::StepResult::kOk);
  const double w_model = m.kt * 24.0 / (m.r * m.b + m.kt * m.kt);
  EXPECT_NEAR(Get(u, "speed")[0], w_model, 1e-6 * w_model);
  EXPECT_LT(w_model, 24.0 / m.kt);
  const double w_datasheet = 7580.0 * 2.0 * std::numbers::pi / 60.0;
  EXPECT_NEAR(Get(u, "speed")[0], w_datasheet, 0.005 * w_datasheet);
  // Steady current balances friction only: I0 = b w / k_t, 137 mA on the sheet.
  EXPECT_NEAR(Get(u, "current")[0], m.b * w_model / m.kt, 1e-6);
  EXPECT_NEAR(Get(u, "current")[0], 0.137, 0.005 * 0.137);
}

// ---------------------------------------------------------------------------
// (b) Guards against missing or wrong restarts at input discontinuities
// (stale held inputs, CVODE stepping across the jump with old history) and
// against restarting when nothing changed. Reference: the closed form,
// restarted from its own state at each jump.
TEST(DcMotorUnit, VoltageStepsAtCommunicationPointsMatchPiecewiseClosedForm) {
  Motor m;
  m.n = 21.0;
  m.eta = 0.75;
  m.j_load = 0.01;
  struct Segment {
    TimeNs until;
    double volt;
  };
  // 0 V, then +24 V, then -12 V (a reversal), on 10 ms multiples so both
  // step sizes see the jumps at communication points.
  const std::vector<Segment> segments = {{10 * kMs, 0.0}, {40 * kMs, 24.0}, {80 * kMs, -12.0}};
  const double tau_load = -2.0;
  for (TimeNs dt : {1 * kMs, 10 * kMs}) {
    DcMotorUnit u("m", 1, MotorMode::kFull);
    ApplyParams(u, {m});
    u.Initialize();
    SetAll(u, "load_torque", tau_load);
    const Reference ref(m);
    Vec2 x_start(0, 0);
    TimeNs seg_start = 0;
    MaxError e;
    for (TimeNs t = 0; t < segments.back().until; t += dt) {
      const auto seg = std::find_if(segments.begin(), segments.end(),
                                    [&](const Segment& s) { return t < s.until; });
      const TimeNs seg_begin = seg == segments.begin() ? 0 : std::prev(seg)->until;
      if (seg_begin != seg_start) {
        x_start = ref.Advance(x_start, std::prev(seg)->volt, tau_load,
                              cosim::NsToSeconds(seg_begin - seg_start));
        seg_start = seg_begin;
      }
      SetAll(u, "voltage", seg->volt);
      ASSERT_EQ(u.DoStep(t, dt), cosim::StepResult::kOk) << u.last_error();
      const Vec2 x =
          ref.Advance(x_start, seg->volt, tau_load, cosim::NsToSeconds(t + dt - seg_start));
      e.Add(Get(u, "current")[0], x[0], Get(u, "speed")[0], x[1] / m.n);
    }
    std::cout << "voltage steps 0 -> 24 -> -12 V, dt " << cosim::FormatSeconds(dt)
              << " s: max rel error current " << e.current() << ", speed " << e.speed()
              << ", restarts " << u.cvode_restarts() << "\n";
    EXPECT_LE(e.current(), kMaxRelError);
    EXPECT_LE(e.speed(), kMaxRelError);
    // First step plus the two jumps, nothing else.
    EXPECT_EQ(u.cvode_restarts(), 3);
  }
}

// ---------------------------------------------------------------------------
// (c) Guards against a wrong current-only model (back-EMF from the shaft
// speed input through the gear ratio) and wrong feedthrough torque.
// Analytic: L di/dt = V - R i - k_t N w gives
//   i(t) = i_ss + (i0 - i_ss) exp(-t R / L),  i_ss = (V - k_t N w) / R.
TEST(DcMotorUnit, CurrentOnlyConvergesExponentially) {
  const Motor m;
  const double n = 21.0, eta = 0.75, w_shaft = 20.0, volt = 24.0, i0 = 5.0;
  DcMotorUnit u("m", 1, MotorMode::kCurrentOnly);
  SetAll(u, "gear_ratio", n);
  SetAll(u, "gear_efficiency", eta);
  SetAll(u, "initial_current", i0);
  SetAll(u, "shaft_speed", w_shaft);
  SetAll(u, "voltage", volt);
  u.Initialize();
  EXPECT_EQ(Get(u, "current")[0], i0);
  const double i_ss = (volt - m.kt * n * w_shaft) / m.r;
  const double tau_e = m.l / m.r;  // 0.275 ms
  double err = 0, max_i = std::abs(i0);
  // 0.1 ms steps over 3 ms (11 electrical time constants), then 1 ms steps.
  TimeNs t = 0;
  const auto check = [&]() {
    const double ref = i_ss + (i0 - i_ss) * std::exp(-cosim::NsToSeconds(t) / tau_e);
    err = std::max(err, std::abs(Get(u, "current")[0] - ref));
    max_i = std::max(max_i, std::abs(ref));
    const double i = Get(u, "current")[0];
    EXPECT_NEAR(Get(u, "torque")[0], eta * n * (m.kt * i - m.b * n * w_shaft), 1e-9);
  };
  for (; t < 3 * kMs;) {
    ASSERT_EQ(u.DoStep(t, kMs / 10), cosim::StepResult::kOk);
    t += kMs / 10;
    check();
  }
  for (; t < 20 * kMs;) {
    ASSERT_EQ(u.DoStep(t, kMs), cosim::StepResult::kOk);
    t += kMs;
    check();
  }
  EXPECT_LE(err / max_i, kMaxRelError);
  EXPECT_NEAR(Get(u, "current")[0], i_ss, 1e-6 * std::abs(i_ss));
}

// Guards the FMI feedthrough contract in current-only mode: after a new
// shaft speed is set at a communication point, UpdateOutputs makes the
// torque follow it at once (torque = eta N (k_t i - b N w), the model's own
// output equation), without advancing the current.
TEST(DcMotorUnit, CurrentOnlyTorqueFollowsNewShaftSpeedOnUpdate) {
  const Motor m;
  const double n = 21.0, eta = 0.75;
  DcMotorUnit u("m", 1, MotorMode::kCurrentOnly);
  SetAll(u, "gear_ratio", n);
  SetAll(u, "gear_efficiency", eta);
  SetAll(u, "voltage", 24.0);
  u.Initialize();
  ASSERT_EQ(u.DoStep(0, kMs), cosim::StepResult::kOk);
  const double i = Get(u, "current")[0];
  SetAll(u, "shaft_speed", 30.0);
  u.UpdateOutputs();
  EXPECT_EQ(Get(u, "current")[0], i);
  EXPECT_NEAR(Get(u, "torque")[0], eta * n * (m.kt * i - m.b * n * 30.0), 1e-12);
}

// Guards the torque-speed line a physics unit applies implicitly: with the
// current settled at shaft speed w (L / R = 0.28 ms, 20 ms of 1 ms steps),
// the line passes through the steady torque there and its slope is the
// steady line's, so it gives the steady torque at any other speed w2:
// eta N (k_t (V - k_t N w2) / R - b N w2) (the model's equations at di/dt = 0).
TEST(DcMotorUnit, CurrentOnlyLineIsTheSteadyTorqueSpeedLine) {
  const Motor m;
  const double n = 21.0, eta = 0.75, v = 24.0;
  const auto steady = [&](double w) {
    return eta * n * (m.kt * (v - m.kt * n * w) / m.r - m.b * n * w);
  };
  for (const char* hold : {"zero_order", "first_order"}) {
    SCOPED_TRACE(hold);
    DcMotorUnit u("m", 1, MotorMode::kCurrentOnly);
    SetAll(u, "gear_ratio", n);
    SetAll(u, "gear_efficiency", eta);
    u.variables().SetString(*u.variables().Find("shaft_speed_hold"), hold);
    SetAll(u, "voltage", v);
    SetAll(u, "shaft_speed", 10.0);
    u.Initialize();
    EXPECT_EQ(Get(u, "line_rate")[0], 10.0);
    EXPECT_NEAR(Get(u, "line_slope")[0], -eta * n * n * (m.b + m.kt * m.kt / m.r), 1e-12);
    for (cosim::TimeNs t = 0; t < 20 * kMs; t += kMs) {
      ASSERT_EQ(u.DoStep(t, kMs), cosim::StepResult::kOk);
    }
    EXPECT_EQ(Get(u, "line_rate")[0], 10.0);
    for (const double w2 : {0.0, 10.0, 25.0}) {
      const double on_line =
          Get(u, "line_torque")[0] + Get(u, "line_slope")[0] * (w2 - Get(u, "line_rate")[0]);
      EXPECT_NEAR(on_line, steady(w2), 1e-6 * std::abs(steady(0.0)));
    }
  }
}

// ---------------------------------------------------------------------------
// (d) Guards against motors of one instance leaking into each other (state
// or parameter indexing, Jacobian blocks). Each must match its own
// single-motor closed form. Parameters set through the table as a loader
// would: SetValue with a list, SetRealArray, SetValue with a scalar.
TEST(DcMotorUnit, SeveralMotorsEachMatchTheirOwnClosedForm) {
  std::vector<Motor> ms(3);
  ms[1].n = 21.0;
  ms[1].eta = 0.75;
  ms[1].j_load = 0.01;
  ms[2].n = 4.0;
  ms[2].eta = 0.9;
  ms[2].j_load = 0.002;
  const std::vector<double> volts = {24.0, -12.0, 6.0};
  const std::vector<double> loads = {0.0, -5.0, 0.5};

  DcMotorUnit u("three", 3, MotorMode::kFull);
  auto& v = u.variables();
  v.SetValue(*v.Find("gear_ratio"), cosim::Value{std::vector<double>{1.0, 21.0, 4.0}});
  v.SetRealArray(*v.Find("gear_efficiency"), std::vector<double>{1.0, 0.75, 0.9});
  v.SetRealArray(*v.Find("load_inertia"), std::vector<double>{0.0, 0.01, 0.002});
  v.SetValue(*v.Find("resistance"), cosim::Value{0.299});
  u.Initialize();
  SetArray(u, "voltage", volts);
  SetArray(u, "load_torque", loads);

  std::vector<MaxError> e(3);
  const TimeNs dt = kMs;
  for (TimeNs t = 0; t < 50 * kMs; t += dt) {
    ASSERT_EQ(u.DoStep(t, dt), cosim::StepResult::kOk) << u.last_error();
    const auto cur = Get(u, "current");
    const auto spd = Get(u, "speed");
    for (std::size_t k = 0; k < 3; ++k) {
      const Vec2 x =
          Reference(ms[k]).Advance({0, 0}, volts[k], loads[k], cosim::NsToSeconds(t + dt));
      e[k].Add(cur[k], x[0], spd[k], x[1] / ms[k].n);
    }
  }
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_LE(e[k].current(), kMaxRelError) << "motor " << k;
    EXPECT_LE(e[k].speed(), kMaxRelError) << "motor " << k;
  }
}

// ---------------------------------------------------------------------------
// (e) Guards against a restored unit drifting from the original (CVODE
// history not reset, held inputs or counters leaking across a restore).
// Compared bit for bit.
// Steps k = from..to-1. Inputs follow a 7-step cycle: each input jumps at
// some steps and holds at others, so both paths (restart, continue) occur.
// Steps 5, 6, 20 have the same inputs, so neither the step after the save
// (6) nor the step after the restore (6 again, after 20) sees an input
// change: only the save/restore logic itself can force their restarts.
std::vector<std::vector<double>> Drive(DcMotorUnit& u, int from, int to, TimeNs dt) {
  std::vector<std::vector<double>> out;
  for (int k = from; k < to; ++k) {
    const int p = k % 7;
    const double volt = p < 3 ? 24.0 : -6.0;
    SetArray(u, "voltage", {volt, 0.5 * volt});
    if (u.mode() == MotorMode::kFull) {
      SetArray(u, "load_torque", {p < 5 ? 0.0 : -0.05, 0.0});
    } else {
      const double w = 0.5 * ((p + 1) / 2);
      SetArray(u, "shaft_speed", {w, -0.5 * w});
    }
    EXPECT_EQ(u.DoStep(k * dt, dt), cosim::StepResult::kOk) << u.last_error();
    out.push_back(Outputs(u));
  }
  return out;
}

void CheckSaveRestoreBitForBit(MotorMode mode, const std::string& hold = "zero_order") {
  const TimeNs dt = kMs;
  DcMotorUnit u("m", 2, mode);
  SetArray(u, "gear_ratio", {1.0, 21.0});
  if (mode == MotorMode::kCurrentOnly) {
    u.variables().SetString(*u.variables().Find("shaft_speed_hold"), hold);
  }
  u.Initialize();
  Drive(u, 0, 6, dt);
  const cosim::UnitState saved = u.SaveState();
  const auto first = Drive(u, 6, 21, dt);
  u.RestoreState(saved);
  const auto second = Drive(u, 6, 21, dt);
  ASSERT_EQ(first.size(), second.size());
  for (std::size_t k = 0; k < first.size(); ++k) {
    EXPECT_TRUE(SameBits(first[k], second[k])) << "step " << 6 + k;
  }
  // A fresh unit restored from the same state continues identically too.
  DcMotorUnit fresh("m", 2, mode);
  fresh.RestoreState(saved);  // parameters, the hold among them, come back too
  const auto third = Drive(fresh, 6, 21, dt);
  for (std::size_t k = 0; k < first.size(); ++k) {
    EXPECT_TRUE(SameBits(first[k], third[k])) << "step " << 6 + k;
  }
  // Outputs come back as they were saved, before any step.
  u.RestoreState(saved);
  DcMotorUnit probe("m", 2, mode);
  probe.RestoreState(saved);
  EXPECT_TRUE(SameBits(Outputs(u), Outputs(probe)));
}

TEST(DcMotorUnit, SaveStepRestoreStepIsBitForBitFullMode) {
  CheckSaveRestoreBitForBit(MotorMode::kFull);
}

TEST(DcMotorUnit, SaveStepRestoreStepIsBitForBitCurrentOnly) {
  CheckSaveRestoreBitForBit(MotorMode::kCurrentOnly);
}

// Guards against the first-order hold's previous sample (which sets the next
// slope) being left out of the saved state.
TEST(DcMotorUnit, SaveStepRestoreStepIsBitForBitCurrentOnlyFirstOrderHold) {
  CheckSaveRestoreBitForBit(MotorMode::kCurrentOnly, "first_order");
}

// Guards the first-order hold's slope across a restore into a fresh unit:
// the shaft speed ramps, so the slope at the first step after the save
// (from the saved previous sample) is not zero; a unit that lost that
// sample would hold to zero order there and drift off bit by bit.
TEST(DcMotorUnit, FreshUnitRestoredUnderFirstOrderHoldKeepsTheSlope) {
  const auto make = [] {
    auto u = std::make_unique<DcMotorUnit>("m", 1, MotorMode::kCurrentOnly);
    u->variables().SetString(*u->variables().Find("shaft_speed_hold"), "first_order");
    SetAll(*u, "gear_ratio", 21.0);
    SetAll(*u, "voltage", 12.0);
    return u;
  };
  const auto step = [](DcMotorUnit& u, int k) {
    SetAll(u, "shaft_speed", 0.5 * k);  // a ramp: every step has a slope
    EXPECT_EQ(u.DoStep(k * kMs, kMs), cosim::StepResult::kOk) << u.last_error();
    return Get(u, "current")[0];
  };
  auto original = make();
  original->Initialize();
  for (int k = 0; k < 5; ++k) step(*original, k);
  const cosim::UnitState saved = original->SaveState();
  auto fresh = make();
  fresh->RestoreState(saved);
  for (int k = 5; k < 15; ++k) {
    const double a = step(*original, k), b = step(*fresh, k);
    EXPECT_EQ(std::memcmp(&a, &b, sizeof a), 0) << "step " << k << ": " << a << " vs " << b;
  }
}

// Current-only motor driven by a continuously varying shaft speed
// w(t) = A sin(W t) sampled every 1 ms, against the exact solution of the
// continuous problem L i' = V - R i - k N w(t), i(0) = 0:
//   i(t) = V/R + i_p(t) - (V/R + i_p(0)) exp(-t R/L),
//   i_p(t) = -(k N A / (R^2 + L^2 W^2)) (R sin Wt - L W cos Wt).
// Guards the first-order hold: it must be far closer to the continuous
// solution than the zero-order hold (whose lag is half a step), restart
// CVODE only for the voltage, and stay so at the loose tolerance the robot
// scenarios use.
TEST(DcMotorUnit, FirstOrderHoldTracksAContinuouslyVaryingShaftSpeed) {
  const models::DcMotorParams p;
  const double n = 21.0, amplitude = 10.0, omega = 2.0 * std::numbers::pi, volts = 12.0;
  const double r = p.resistance_ohm, l = p.inductance_h, k = p.torque_constant_nm_per_a;
  const auto exact = [&](double t) {
    const double z2 = r * r + l * l * omega * omega;
    const auto ip = [&](double s) {
      return -(k * n * amplitude / z2) *
             (r * std::sin(omega * s) - l * omega * std::cos(omega * s));
    };
    return volts / r + ip(t) - (volts / r + ip(0.0)) * std::exp(-t * r / l);
  };
  struct Result {
    double max_error;
    std::int64_t restarts;
  };
  const auto run = [&](const std::string& hold, double rel_tol, double abs_tol = 1e-10) {
    DcMotorUnit u("m", 1, MotorMode::kCurrentOnly);
    SetAll(u, "gear_ratio", n);
    SetAll(u, "gear_efficiency", 1.0);
    SetAll(u, "viscous_friction", 0.0);
    SetAll(u, "rel_tol", rel_tol);
    SetAll(u, "abs_tol", abs_tol);
    u.variables().SetString(*u.variables().Find("shaft_speed_hold"), hold);
    SetAll(u, "voltage", volts);
    u.Initialize();
    double worst = 0.0;
    // Skip the first 5 ms (the electrical start transient, where both holds
    // see the same first sample).
    for (int step = 0; step < 1000; ++step) {
      const double t = step * 1e-3;
      SetAll(u, "shaft_speed", amplitude * std::sin(omega * t));
      EXPECT_EQ(u.DoStep(step * kMs, kMs), cosim::StepResult::kOk) << u.last_error();
      if (step >= 5) worst = std::max(worst, std::abs(Get(u, "current")[0] - exact(t + 1e-3)));
    }
    return Result{worst, u.cvode_restarts()};
  };
  const Result zoh = run("zero_order", 1e-8);
  const Result foh = run("first_order", 1e-8);
  const Result foh_loose = run("first_order", 1e-3, 1e-4);  // models/robots/raw3.yaml
  std::cout << "max |current error| over 1 s: zero-order " << zoh.max_error << " A ("
            << zoh.restarts << " restarts), first-order " << foh.max_error << " A (" << foh.restarts
            << "), first-order rel_tol 1e-3 abs_tol 1e-4 " << foh_loose.max_error << " A ("
            << foh_loose.restarts << ")\n";
  // Zero-order lag of half a step: about k N A W (h/2) / R = 0.067 A.
  EXPECT_GT(zoh.max_error, 0.03);
  EXPECT_LT(foh.max_error, 0.1 * zoh.max_error);
  // models/robots/raw3.yaml justifies its loose tolerances by this: under
  // 1 % of the zero-order hold's error.
  EXPECT_LT(foh_loose.max_error, 0.01 * zoh.max_error);
  EXPECT_EQ(foh.restarts, 1);  // the voltage never changes after the start
  EXPECT_EQ(zoh.restarts, 1000);
}

// Guards against a state from a different unit layout being accepted.
TEST(DcMotorUnit, RestoreRejectsStateOfAnotherLayout) {
  DcMotorUnit a("a", 2, MotorMode::kCurrentOnly);
  a.Initialize();
  DcMotorUnit b("a", 2, MotorMode::kFull);
  EXPECT_ANY_THROW(b.RestoreState(a.SaveState()));
}

// Guards the unit's own check of its internal state (same layout, one real
// short): the variable-table check above does not reach it.
TEST(DcMotorUnit, RestoreRefusesTruncatedInternalState) {
  DcMotorUnit a("a", 2, MotorMode::kFull);
  a.Initialize();
  cosim::UnitState state = a.SaveState();
  state.reals.pop_back();
  DcMotorUnit b("a", 2, MotorMode::kFull);
  try {
    b.RestoreState(state);
    FAIL() << "a truncated state was restored";
  } catch (const cosim::UnitError& e) {
    EXPECT_NE(std::string(e.what()).find("saved state has"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------------------
// (f) Guards against bad parameters reaching CVODE (division by zero, a
// gearbox that creates energy) and against vague messages.
TEST(DcMotorUnit, InvalidParametersThrowNamingUnitVariableElementAndValue) {
  {
    DcMotorUnit u("left_drive", 1, MotorMode::kFull);
    SetAll(u, "resistance", 0.0);
    try {
      u.Initialize();
      FAIL() << "R = 0 accepted";
    } catch (const cosim::UnitError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("left_drive"), std::string::npos) << msg;
      EXPECT_NE(msg.find("resistance[0]"), std::string::npos) << msg;
      EXPECT_NE(msg.find("got 0"), std::string::npos) << msg;
    }
  }
  {
    DcMotorUnit u("steer", 2, MotorMode::kCurrentOnly);
    SetArray(u, "gear_efficiency", {0.9, 1.5});
    try {
      u.Initialize();
      FAIL() << "efficiency 1.5 accepted";
    } catch (const cosim::UnitError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("steer"), std::string::npos) << msg;
      EXPECT_NE(msg.find("gear_efficiency[1]"), std::string::npos) << msg;
      EXPECT_NE(msg.find("1.5"), std::string::npos) << msg;
    }
  }
  EXPECT_THROW(DcMotorUnit("none", 0, MotorMode::kFull), cosim::UnitError);
}

// Guards against a loader seeing only the first bad value, or none before
// time zero: CheckParameters lists every one with its element index.
TEST(DcMotorUnit, CheckParametersListsEveryProblem) {
  DcMotorUnit u("m", 3, MotorMode::kFull);
  EXPECT_TRUE(u.CheckParameters().empty());
  SetArray(u, "resistance", {0.299, -1.0, 0.299});
  SetArray(u, "gear_efficiency", {1.0, 1.0, 0.0});
  SetAll(u, "load_inertia", -0.5);
  const auto problems = u.CheckParameters();
  ASSERT_EQ(problems.size(), 5u);
  EXPECT_EQ(problems[0].variable, "resistance");
  EXPECT_EQ(problems[0].index, 1u);
  EXPECT_EQ(problems[0].message, "must be > 0, got -1");
  EXPECT_EQ(problems[1].variable, "gear_efficiency");
  EXPECT_EQ(problems[1].index, 2u);
  EXPECT_EQ(problems[1].message, "must be in (0, 1], got 0");
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(problems[2 + k].variable, "load_inertia");
    EXPECT_EQ(problems[2 + k].index, k);
  }
  EXPECT_THROW(u.Initialize(), cosim::UnitError);
}

// Guards the rules the motor declares with its parameters (what inspect
// prints and what the loader and sweeps check before running): the physical
// quantities of the model equations that divide or scale must be > 0, the
// efficiency is a fraction in (0, 1], the hold one of its two algorithms.
TEST(DcMotorUnit, DeclaresTheRangeOfEveryParameter) {
  const std::vector<std::pair<std::string, std::string>> full = {{"resistance", "> 0"},
                                                                 {"inductance", "> 0"},
                                                                 {"torque_constant", "> 0"},
                                                                 {"rotor_inertia", "> 0"},
                                                                 {"viscous_friction", ">= 0"},
                                                                 {"gear_ratio", "> 0"},
                                                                 {"gear_efficiency", "(0, 1]"},
                                                                 {"initial_current", "finite"},
                                                                 {"load_inertia", ">= 0"},
                                                                 {"initial_speed", "finite"},
                                                                 {"rel_tol", "> 0"},
                                                                 {"abs_tol", "> 0"}};
  DcMotorUnit u("m", 2, MotorMode::kFull);
  for (const auto& [name, rule] : full) {
    EXPECT_EQ(u.variables().info(*u.variables().Find(name)).rule.Text(), rule) << name;
  }
  DcMotorUnit c("c", 1, MotorMode::kCurrentOnly);
  const auto hold = *c.variables().Find("shaft_speed_hold");
  EXPECT_EQ(c.variables().info(hold).rule.Text(), "one of: zero_order, first_order");
  c.variables().SetString(hold, "second_order");
  const auto problems = c.CheckParameters();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].message, "must be one of: zero_order, first_order, got 'second_order'");
}

// Guards against SUNDIALS failures being lost or reported without context:
// a relative tolerance below machine precision makes CVode refuse.
TEST(DcMotorUnit, SundialsFailureNamesUnitFunctionTimeAndFlag) {
  DcMotorUnit u("m", 1, MotorMode::kFull);
  SetAll(u, "voltage", 24.0);
  u.variables().SetReal(*u.variables().Find("rel_tol"), 1e-30);
  u.variables().SetReal(*u.variables().Find("abs_tol"), 1e-30);
  u.Initialize();
  try {
    u.DoStep(5 * kMs, kMs);
    FAIL() << "no error";
  } catch (const cosim::UnitError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("unit 'm'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("CVode"), std::string::npos) << msg;
    EXPECT_NE(msg.find("t = 0.005 s"), std::string::npos) << msg;
    EXPECT_NE(msg.find("CV_TOO_MUCH_ACC"), std::string::npos) << msg;
  }
}

// Guards the "name the variable" contract of a numerical failure: with a
// finite but absurd voltage on motor 1 (1e308 V over 0.0823 mH, so di/dt
// overflows to inf), the error names current[1], not motor 0.
TEST(DcMotorUnit, IntegratorFailureNamesTheStateToBlame) {
  DcMotorUnit u("m", 2, MotorMode::kFull);
  u.Initialize();
  SetArray(u, "voltage", {1.0, 1e308});
  try {
    u.DoStep(0, kMs);
    FAIL() << "no error";
  } catch (const cosim::UnitError& e) {
    EXPECT_NE(std::string(e.what()).find("the derivative of current[1] is inf"), std::string::npos)
        << e.what();
  }
}

// Guards against a NaN input silently poisoning the integrator.
TEST(DcMotorUnit, NonFiniteInputFailsTheStep) {
  DcMotorUnit u("m", 2, MotorMode::kFull);
  u.Initialize();
  SetArray(u, "voltage", {1.0, std::nan("")});
  EXPECT_EQ(u.DoStep(0, kMs), cosim::StepResult::kError);
  EXPECT_NE(u.last_error().find("voltage[1]"), std::string::npos) << u.last_error();
}

// ---------------------------------------------------------------------------
// Guards against current-only mode being unusable in a loop with the physics
// (depends_on wrong, so the master reports an algebraic loop or orders the
// units badly; torque / shaft_speed sign or gear conventions inconsistent).
// A test-local rigid load J dw/dt = torque closes the loop through the
// master. The coupled system is the full-mode model with the load inertia
// and no rotor inertia (current-only torque excludes it), so it must follow
// that closed form to within the coupling error of the 0.2 ms steps.
class RigidLoad : public cosim::Unit {
 public:
  explicit RigidLoad(double inertia) : cosim::Unit("rigid_load", "wheel"), inertia_(inertia) {
    variables().Parameter("inertia", "kg.m2", &inertia_, "inertia of the output shaft");
    variables().Input("torque", "N.m", &torque_, "driving torque");
    variables().Output("speed", "rad/s", &speed_, "shaft speed", {});
  }
  cosim::StepResult DoStep(TimeNs, TimeNs dt) override {
    speed_ += torque_ * cosim::NsToSeconds(dt) / inertia_;
    return cosim::StepResult::kOk;
  }

 private:
  double inertia_;
  double torque_ = 0;
  double speed_ = 0;
};

TEST(DcMotorUnit, CurrentOnlyInALoopThroughTheMasterFollowsFullModel) {
  // A quarter of the 120 kg Rob@Work 3 on an 80 mm wheel (paper 1, Table I; raw3-1 Platform.ini): m
  // r^2.
  const double j_wheel = 30.0 * 0.08 * 0.08;
  Motor m;
  m.n = 21.0;
  m.eta = 0.75;
  m.j = 0.0;
  m.j_load = j_wheel;
  cosim::System system;
  auto motor = std::make_unique<DcMotorUnit>("motors", 1, MotorMode::kCurrentOnly);
  SetAll(*motor, "gear_ratio", m.n);
  SetAll(*motor, "gear_efficiency", m.eta);
  SetAll(*motor, "voltage", 24.0);
  system.Add(std::move(motor));
  system.Add(std::make_unique<RigidLoad>(j_wheel));
  system.Connect("motors.torque[0]", "wheel.torque");
  system.Connect("wheel.speed", "motors.shaft_speed[0]");
  cosim::MasterOptions opt;
  opt.base_step = kMs / 5;
  opt.stop = 500 * kMs;  // 2.6 mechanical time constants
  cosim::Master master(system, opt);
  master.Start();
  const Reference ref(m);
  double err = 0, max_w = 0;
  while (master.Step()) {
    const Vec2 x = ref.Advance({0, 0}, 24.0, 0.0, cosim::NsToSeconds(master.time()));
    const double w = system.unit(1).variables().GetReal(*system.unit(1).variables().Find("speed"));
    err = std::max(err, std::abs(w - x[1] / m.n));
    max_w = std::max(max_w, std::abs(x[1] / m.n));
  }
  const cosim::RunResult result = master.Finish();
  ASSERT_TRUE(result.ok) << result.ErrorText();
  EXPECT_EQ(result.end_time, opt.stop);
  std::cout << "current-only + rigid load via master: max rel speed error " << err / max_w << "\n";
  // The load is integrated by explicit Euler with the torque held over each
  // h = 0.2 ms step: for the coupled lag of time constant
  // tau = J / (eta N^2 k_t^2 / R) = 0.192 / 1.009 = 0.19 s its relative error
  // is about h / (2 tau) = 5.3e-4; allow four times that.
  EXPECT_LE(err / max_w, 2e-3);
}

// ---------------------------------------------------------------------------
// (g) Guards against the variable table drifting from the interface other
// units and scenario files are written against.
struct Expected {
  std::string name;
  cosim::Causality causality;
  std::string unit;
  std::vector<std::string> depends_on;
};

void CheckTable(const DcMotorUnit& u, const std::vector<Expected>& expected) {
  const auto& infos = u.variables().infos();
  ASSERT_EQ(infos.size(), expected.size());
  for (const Expected& e : expected) {
    const auto ref = u.variables().Find(e.name);
    ASSERT_TRUE(ref) << e.name;
    const auto& info = u.variables().info(*ref);
    EXPECT_EQ(info.causality, e.causality) << e.name;
    EXPECT_EQ(info.unit, e.unit) << e.name;
    const bool scalar = e.name == "rel_tol" || e.name == "abs_tol";
    const bool text = e.name == "shaft_speed_hold";
    EXPECT_EQ(info.type, text     ? cosim::VarType::kString
                         : scalar ? cosim::VarType::kReal
                                  : cosim::VarType::kRealArray)
        << e.name;
    if (!scalar && !text) {
      EXPECT_EQ(info.size, static_cast<std::size_t>(u.count())) << e.name;
    }
    if (info.causality == cosim::Causality::kParameter) {
      EXPECT_EQ(info.variability, cosim::Variability::kFixed) << e.name;
    }
    std::vector<std::string> deps;
    for (auto d : info.depends_on) deps.push_back(u.variables().info(d).name);
    EXPECT_EQ(deps, e.depends_on) << e.name;
  }
}

TEST(DcMotorUnit, VariableTableFullMode) {
  using C = cosim::Causality;
  DcMotorUnit u("m", 4, MotorMode::kFull);
  EXPECT_EQ(u.type_name(), "dc_motor");
  CheckTable(u, {{"resistance", C::kParameter, "Ohm", {}},
                 {"inductance", C::kParameter, "H", {}},
                 {"torque_constant", C::kParameter, "N.m/A", {}},
                 {"rotor_inertia", C::kParameter, "kg.m2", {}},
                 {"viscous_friction", C::kParameter, "N.m.s/rad", {}},
                 {"gear_ratio", C::kParameter, "1", {}},
                 {"gear_efficiency", C::kParameter, "1", {}},
                 {"initial_current", C::kParameter, "A", {}},
                 {"load_inertia", C::kParameter, "kg.m2", {}},
                 {"initial_speed", C::kParameter, "rad/s", {}},
                 {"rel_tol", C::kParameter, "1", {}},
                 {"abs_tol", C::kParameter, "1", {}},
                 {"voltage", C::kInput, "V", {}},
                 {"load_torque", C::kInput, "N.m", {}},
                 {"current", C::kOutput, "A", {}},
                 {"speed", C::kOutput, "rad/s", {}},
                 {"torque", C::kOutput, "N.m", {}}});
}

TEST(DcMotorUnit, VariableTableCurrentOnlyMode) {
  using C = cosim::Causality;
  DcMotorUnit u("m", 2, MotorMode::kCurrentOnly);
  CheckTable(u, {{"resistance", C::kParameter, "Ohm", {}},
                 {"inductance", C::kParameter, "H", {}},
                 {"torque_constant", C::kParameter, "N.m/A", {}},
                 {"rotor_inertia", C::kParameter, "kg.m2", {}},
                 {"viscous_friction", C::kParameter, "N.m.s/rad", {}},
                 {"gear_ratio", C::kParameter, "1", {}},
                 {"gear_efficiency", C::kParameter, "1", {}},
                 {"initial_current", C::kParameter, "A", {}},
                 {"shaft_speed_hold", C::kParameter, "", {}},
                 {"rel_tol", C::kParameter, "1", {}},
                 {"abs_tol", C::kParameter, "1", {}},
                 {"voltage", C::kInput, "V", {}},
                 {"shaft_speed", C::kInput, "rad/s", {}},
                 {"current", C::kOutput, "A", {}},
                 {"torque", C::kOutput, "N.m", {"shaft_speed"}},
                 {"line_torque", C::kOutput, "N.m", {}},
                 {"line_rate", C::kOutput, "rad/s", {}},
                 {"line_slope", C::kOutput, "N.m.s/rad", {}}});
}

// Guards against the defaults drifting from the data sheet they cite.
TEST(DcMotorUnit, DefaultsAreTheMaxonRe40DataSheet) {
  const models::DcMotorParams p;
  EXPECT_DOUBLE_EQ(p.resistance_ohm, 0.299);
  EXPECT_DOUBLE_EQ(p.inductance_h, 0.0823e-3);
  EXPECT_DOUBLE_EQ(p.torque_constant_nm_per_a, 0.0302);
  EXPECT_DOUBLE_EQ(p.rotor_inertia_kgm2, 142e-3 * 1e-4);  // 142 g.cm^2
  EXPECT_NEAR(p.viscous_friction_nms_per_rad, 5.2e-6, 0.05e-6);
  // Speed constant 317 rpm/V is the same constant as k_t, to rounding.
  EXPECT_NEAR(1.0 / (317.0 * 2.0 * std::numbers::pi / 60.0), p.torque_constant_nm_per_a, 2e-4);
}

}  // namespace
}  // namespace linesim::motors
