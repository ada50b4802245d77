#include "units/control/path_follower_unit.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <numbers>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cosim/time.h"

namespace linesim::control {
namespace {

using cosim::TimeNs;
using Mode = PathFollowerUnit::Mode;

constexpr TimeNs kPeriod = 20'000'000;
constexpr double kPeriodS = 0.02;
constexpr double kPi = std::numbers::pi;

void SetPose(PathFollowerUnit& u, double x, double y, double yaw) {
  u.variables().SetRealArray(*u.variables().Find("position"), std::vector<double>{x, y});
  u.variables().SetReal(*u.variables().Find("yaw"), yaw);
}
void SetParam(PathFollowerUnit& u, const std::string& name, double v) {
  u.variables().SetReal(*u.variables().Find(name), v);
}
// The commands as one twist: velocity_command (vx, vy), yaw_rate_command.
std::vector<double> Twist(const PathFollowerUnit& u) {
  const auto s = u.variables().GetRealArray(*u.variables().Find("velocity_command"));
  return {s[0], s[1], u.variables().GetReal(*u.variables().Find("yaw_rate_command"))};
}
double Real(const PathFollowerUnit& u, const std::string& name) {
  return u.variables().GetReal(*u.variables().Find(name));
}
bool Done(const PathFollowerUnit& u) {
  return u.variables().GetBoolean(*u.variables().Find("done"));
}

// An ideal omnidirectional robot: the base_link twist, held over a period,
// moves the pose exactly (the heading is integrated first; with the yaw
// rate zero in these tests, the translation is exact).
struct Robot {
  double x = 0, y = 0, yaw = 0;
  void Move(const std::vector<double>& twist, double dt_s) {
    const double c = std::cos(yaw), s = std::sin(yaw);
    x += (c * twist[0] - s * twist[1]) * dt_s;
    y += (s * twist[0] + c * twist[1]) * dt_s;
    yaw += twist[2] * dt_s;
  }
};

// One sample as the master runs it: pose in, outputs read, then DoStep.
std::vector<double> Sample(PathFollowerUnit& u, const Robot& r, int k) {
  SetPose(u, r.x, r.y, r.yaw);
  u.UpdateOutputs();
  const std::vector<double> twist = Twist(u);
  EXPECT_EQ(u.DoStep(k * kPeriod, kPeriod), cosim::StepResult::kOk) << u.last_error();
  return twist;
}

// Guards against the interface drifting (names, units, feedthrough on the
// position and heading: the commands depend on both, the path measures on
// the position only).
TEST(PathFollowerUnit, VariableTable) {
  PathFollowerUnit u("follow", Mode::kPath, {{0, 0}, {1, 0}});
  EXPECT_EQ(u.type_name(), "path_follower");
  const auto& v = u.variables();
  for (const char* p : {"speed", "acceleration", "heading", "k_cross", "k_position", "k_yaw",
                        "max_speed", "max_yaw_rate", "goal_tolerance"}) {
    ASSERT_TRUE(v.Find(p)) << p;
    EXPECT_EQ(v.info(*v.Find(p)).causality, cosim::Causality::kParameter) << p;
  }
  EXPECT_EQ(v.info(*v.Find("position")).size, 2u);
  EXPECT_EQ(v.info(*v.Find("position")).unit, "m");
  EXPECT_EQ(v.info(*v.Find("position")).causality, cosim::Causality::kInput);
  EXPECT_EQ(v.info(*v.Find("yaw")).unit, "rad");
  EXPECT_EQ(v.info(*v.Find("yaw")).causality, cosim::Causality::kInput);
  for (const char* o :
       {"velocity_command", "yaw_rate_command", "cross_track_error", "progress", "done"}) {
    const auto& info = v.info(*v.Find(o));
    EXPECT_EQ(info.causality, cosim::Causality::kOutput) << o;
    std::vector<std::string> deps;
    for (auto d : info.depends_on) deps.push_back(v.info(d).name);
    const bool command = std::string(o).find("command") != std::string::npos;
    const std::vector<std::string> expected = command ? std::vector<std::string>{"position", "yaw"}
                                                      : std::vector<std::string>{"position"};
    EXPECT_EQ(deps, expected) << o;
  }
  EXPECT_EQ(v.info(*v.Find("velocity_command")).size, 2u);
  EXPECT_EQ(v.info(*v.Find("velocity_command")).unit, "m/s");
  EXPECT_EQ(v.info(*v.Find("yaw_rate_command")).unit, "rad/s");
  EXPECT_EQ(v.info(*v.Find("cross_track_error")).unit, "m");
}

// Guards against a wrong sign or frame of the cross-track correction. On a
// path along +x, a robot 0.1 m to the left (+y) must be sent right at
// k_cross * 0.1 m/s in map; with the robot turned to +90 deg that map
// velocity (0, -0.1) is (-0.1, 0) in base_link (rotation by -yaw). The
// speed ramp starts at 0, so the along-track part is 0 at the first sample.
TEST(PathFollowerUnit, CrossTrackCommandIsMinusGainTimesOffsetInBaseLink) {
  for (const double yaw : {0.0, kPi / 2}) {
    PathFollowerUnit u("follow", Mode::kPath, {{0, 0}, {10, 0}});
    SetParam(u, "k_cross", 1.5);
    SetParam(u, "heading", yaw);
    SetPose(u, 2.0, 0.1, yaw);
    u.Initialize();
    EXPECT_NEAR(Real(u, "cross_track_error"), 0.1, 1e-15);
    EXPECT_NEAR(Real(u, "progress"), 2.0, 1e-15);
    const auto t = Twist(u);
    const double vx_map = 0.0, vy_map = -1.5 * 0.1;
    EXPECT_NEAR(t[0], std::cos(yaw) * vx_map + std::sin(yaw) * vy_map, 1e-15);
    EXPECT_NEAR(t[1], -std::sin(yaw) * vx_map + std::cos(yaw) * vy_map, 1e-15);
    EXPECT_EQ(t[2], 0.0);
  }
  // Right of the path: negative error, sent left.
  PathFollowerUnit u("follow", Mode::kPath, {{0, 0}, {10, 0}});
  SetPose(u, 2.0, -0.2, 0.0);
  u.Initialize();
  EXPECT_NEAR(Real(u, "cross_track_error"), -0.2, 1e-15);
  EXPECT_NEAR(Twist(u)[1], 0.2, 1e-15);  // k_cross 1
}

// Guards against a yaw command of the wrong sign or one that goes the long
// way round across +-pi: k_yaw * wrap(yaw_ref - yaw), clamped.
TEST(PathFollowerUnit, YawRateSignAndWrap) {
  PathFollowerUnit u("hold", Mode::kHold, {{0, 0}});
  SetParam(u, "k_yaw", 2.0);
  SetParam(u, "max_yaw_rate", 10.0);
  SetParam(u, "heading", 0.3);
  SetPose(u, 0, 0, 0.1);
  u.Initialize();
  EXPECT_NEAR(Twist(u)[2], 2.0 * 0.2, 1e-15);  // counter-clockwise
  SetParam(u, "heading", -3.0);
  SetPose(u, 0, 0, 3.0);  // 2 pi - 6 = 0.283 rad counter-clockwise
  u.UpdateOutputs();
  EXPECT_NEAR(Twist(u)[2], 2.0 * (2 * kPi - 6.0), 1e-12);
  SetParam(u, "max_yaw_rate", 0.5);
  SetPose(u, 0, 0, 0.0);
  SetParam(u, "heading", -1.0);
  u.UpdateOutputs();
  EXPECT_EQ(Twist(u)[2], -0.5);
}

// Guards against a follower that does not stop at the goal, overshoots it,
// or exceeds its speed and acceleration. Ideal robot, 2 m straight path
// along a diagonal, 0.3 m/s cruise, 0.3 m/s^2: the along-track speed grows
// by at most 0.3 * 0.02 m/s per sample, never exceeds 0.3 m/s, and the
// robot stops within goal_tolerance with done set and the command zero.
TEST(PathFollowerUnit, FollowsPathAndStopsAtTheGoal) {
  const double c = std::cos(0.5), s = std::sin(0.5);
  PathFollowerUnit u("follow", Mode::kPath, {{1, 1}, {1 + 2 * c, 1 + 2 * s}});
  EXPECT_NEAR(u.length_m(), 2.0, 1e-15);
  Robot r{1.0, 1.05, 0.0};
  SetPose(u, r.x, r.y, r.yaw);
  u.Initialize();
  double last_speed = 0, max_progress = -1;
  int k = 0;
  for (; k < 1000 && !Done(u); ++k) {
    const auto twist = Sample(u, r, k);
    const double speed = std::hypot(twist[0], twist[1]);
    EXPECT_LE(speed, 0.5 + 1e-12);  // max_speed
    // Along-track part, from the map direction of the path.
    const double along = twist[0] * c + twist[1] * s;
    EXPECT_LE(along, 0.3 + 1e-12);
    EXPECT_LE(along - last_speed, 0.3 * kPeriodS + 1e-12) << k;
    last_speed = along;
    max_progress = std::max(max_progress, Real(u, "progress"));
    r.Move(twist, kPeriodS);
  }
  ASSERT_TRUE(Done(u)) << "not done after " << k << " samples";
  EXPECT_LE(std::hypot(r.x - (1 + 2 * c), r.y - (1 + 2 * s)), 0.02);
  EXPECT_LE(max_progress, 2.0 + 1e-9);  // never past the goal
  // Minimum time: ramp 1 s (0.15 m) each way and 1.7 m at 0.3 m/s = 7.7 s;
  // the k_position tail adds some. A follower that crawls fails this.
  EXPECT_LT(k * kPeriodS, 10.0);
  // Once done, the command is zero and stays zero.
  for (int j = 0; j < 5; ++j) {
    const auto twist = Sample(u, r, k + j);
    EXPECT_EQ(twist, (std::vector<double>{0, 0, 0}));
    EXPECT_TRUE(Done(u));
  }
}

// Guards against wrong corner handling: on an L path the progress is the
// arc length of the nearest point (1 m leg, then along the second leg).
TEST(PathFollowerUnit, ProgressAlongAPolyline) {
  PathFollowerUnit u("follow", Mode::kPath, {{0, 0}, {1, 0}, {1, 2}});
  SetPose(u, 1.1, 0.5, 0.0);
  u.Initialize();
  EXPECT_NEAR(Real(u, "progress"), 1.5, 1e-15);
  EXPECT_NEAR(Real(u, "cross_track_error"), -0.1, 1e-15);  // right of +y
  EXPECT_NEAR(u.length_m(), 3.0, 1e-15);
}

// Guards against a hold controller of the wrong sign or gain. With an ideal
// robot and the command held over each period, the offset decays exactly
// geometrically: e_{n+1} = (1 - k T) e_n (analytic, while below max_speed).
TEST(PathFollowerUnit, HoldReturnsToThePointGeometrically) {
  PathFollowerUnit u("hold", Mode::kHold, {{2.0, -1.0}});
  SetParam(u, "k_position", 2.0);
  Robot r{2.1, -1.05, 0.7};
  SetParam(u, "heading", 0.7);
  SetPose(u, r.x, r.y, r.yaw);
  u.Initialize();
  const double e0 = std::hypot(0.1, 0.05);
  EXPECT_NEAR(Real(u, "cross_track_error"), e0, 1e-15);
  EXPECT_FALSE(Done(u));
  for (int k = 0; k < 50; ++k) {
    Sample(u, r, k);
    r.Move(Twist(u), kPeriodS);
  }
  const double expected = e0 * std::pow(1.0 - 2.0 * kPeriodS, 50);
  EXPECT_NEAR(std::hypot(r.x - 2.0, r.y + 1.0), expected, 1e-12);
  SetPose(u, r.x, r.y, r.yaw);
  u.UpdateOutputs();
  EXPECT_TRUE(Done(u));  // 0.112 * 0.96^50 = 0.015 m < 0.02 m
}

// Guards against a restored unit drifting from the original (ramp or done
// missing from the save).
TEST(PathFollowerUnit, SaveStepRestoreStepIsBitForBit) {
  const auto run = [](PathFollowerUnit& u, Robot r, int from, int to) {
    std::vector<double> out;
    for (int k = from; k < to; ++k) {
      const auto twist = Sample(u, r, k);
      out.insert(out.end(), twist.begin(), twist.end());
      out.push_back(Real(u, "progress"));
      r.Move(twist, kPeriodS);
    }
    return out;
  };
  PathFollowerUnit u("follow", Mode::kPath, {{0, 0}, {0.5, 0}, {0.5, 0.5}});
  Robot r{0, 0.02, 0.1};
  SetPose(u, r.x, r.y, r.yaw);
  u.Initialize();
  for (int k = 0; k < 20; ++k) r.Move(Sample(u, r, k), kPeriodS);
  const cosim::UnitState saved = u.SaveState();
  const auto first = run(u, r, 20, 200);
  u.RestoreState(saved);
  const auto second = run(u, r, 20, 200);
  PathFollowerUnit fresh("follow", Mode::kPath, {{0, 0}, {0.5, 0}, {0.5, 0.5}});
  fresh.RestoreState(saved);
  const auto third = run(fresh, r, 20, 200);
  ASSERT_EQ(first.size(), second.size());
  EXPECT_EQ(std::memcmp(first.data(), second.data(), first.size() * sizeof(double)), 0);
  EXPECT_EQ(std::memcmp(first.data(), third.data(), first.size() * sizeof(double)), 0);
}

// Guards the unit's own check of its internal state (the variable count
// matches, so only RestoreInternal can refuse): the ramp speed and done.
TEST(PathFollowerUnit, RestoreRefusesTruncatedInternalState) {
  PathFollowerUnit u("follow", Mode::kPath, {{0, 0}, {1, 0}});
  u.Initialize();
  const cosim::UnitState saved = u.SaveState();
  cosim::UnitState no_reals = saved;
  no_reals.reals.clear();
  cosim::UnitState no_integers = saved;
  no_integers.integers.clear();
  for (const auto* bad : {&no_reals, &no_integers}) {
    try {
      u.RestoreState(*bad);
      ADD_FAILURE() << "restored a truncated state";
    } catch (const cosim::UnitError& e) {
      EXPECT_NE(std::string(e.what()).find("expected 1 and 1"), std::string::npos) << e.what();
    }
  }
  EXPECT_NO_THROW(u.RestoreState(saved));
}

// Guards against paths that cannot be followed and gains that would
// divide by zero or run away being accepted before time zero.
TEST(PathFollowerUnit, CheckParametersRejectsBadValues) {
  PathFollowerUnit ok("ok", Mode::kPath, {{0, 0}, {1, 0}});
  EXPECT_TRUE(ok.CheckParameters().empty());
  PathFollowerUnit one("one", Mode::kPath, {{0, 0}});
  ASSERT_EQ(one.CheckParameters().size(), 1u);
  EXPECT_EQ(one.CheckParameters()[0].variable, "waypoints");
  EXPECT_THROW(one.Initialize(), cosim::UnitError);
  PathFollowerUnit repeat("repeat", Mode::kPath, {{0, 0}, {1, 0}, {1, 0}});
  ASSERT_EQ(repeat.CheckParameters().size(), 1u);
  EXPECT_EQ(repeat.CheckParameters()[0].index, 2u);
  // A non-finite waypoint is reported once: the segment after it is judged
  // by its own ends (here 1 m long), the repeat after that still is.
  PathFollowerUnit nan("nan", Mode::kPath, {{0, 0}, {NAN, 0}, {1, 0}, {1, 0}});
  const auto nan_problems = nan.CheckParameters();
  ASSERT_EQ(nan_problems.size(), 2u);
  EXPECT_EQ(nan_problems[0].index, 1u);
  EXPECT_NE(nan_problems[0].message.find("must be finite, got (nan, 0)"), std::string::npos)
      << nan_problems[0].message;
  EXPECT_EQ(nan_problems[1].index, 3u);
  EXPECT_NE(nan_problems[1].message.find("repeats the previous waypoint"), std::string::npos)
      << nan_problems[1].message;
  PathFollowerUnit none("none", Mode::kHold, {});
  EXPECT_EQ(none.CheckParameters().size(), 1u);
  PathFollowerUnit bad("bad", Mode::kHold, {{0, 0}});
  SetParam(bad, "speed", 0.0);
  SetParam(bad, "k_cross", -1.0);
  SetParam(bad, "goal_tolerance", NAN);
  const auto problems = bad.CheckParameters();
  ASSERT_EQ(problems.size(), 3u);
  EXPECT_EQ(problems[0].variable, "speed");
  EXPECT_EQ(problems[1].variable, "k_cross");
  EXPECT_EQ(problems[2].variable, "goal_tolerance");
  try {
    bad.Initialize();
    FAIL() << "bad parameters accepted";
  } catch (const cosim::UnitError& e) {
    EXPECT_NE(std::string(e.what()).find("unit 'bad'"), std::string::npos) << e.what();
  }
}

// Guards against a NaN pose (a lost estimator) turning into a command.
TEST(PathFollowerUnit, NonFinitePoseFailsTheStep) {
  PathFollowerUnit u("hold", Mode::kHold, {{0, 0}});
  u.Initialize();
  SetPose(u, 0, NAN, 0);
  EXPECT_EQ(u.DoStep(0, kPeriod), cosim::StepResult::kError);
  EXPECT_NE(u.last_error().find("position[1]"), std::string::npos) << u.last_error();
}

}  // namespace
}  // namespace linesim::control

namespace linesim::control {
namespace {

using Base = PathFollowerUnit::Base;

// A differential-drive (unicycle) robot moved exactly by a forward speed v
// and yaw rate w held over dt: along the arc of radius v / w.
struct Unicycle {
  double x = 0, y = 0, yaw = 0;
  void Move(double v, double w, double dt_s) {
    if (w == 0.0) {
      x += v * std::cos(yaw) * dt_s;
      y += v * std::sin(yaw) * dt_s;
    } else {
      x += v / w * (std::sin(yaw + w * dt_s) - std::sin(yaw));
      y -= v / w * (std::cos(yaw + w * dt_s) - std::cos(yaw));
    }
    yaw = std::remainder(yaw + w * dt_s, 2.0 * kPi);
  }
};

std::vector<double> Sample(PathFollowerUnit& u, const Unicycle& r, int k) {
  SetPose(u, r.x, r.y, r.yaw);
  u.UpdateOutputs();
  const std::vector<double> twist = Twist(u);
  EXPECT_EQ(u.DoStep(k * kPeriod, kPeriod), cosim::StepResult::kOk) << u.last_error();
  return twist;
}

// Guards the interface of the differential base: its extra parameter, and
// a command that never asks for sideways motion.
TEST(PathFollowerUnitDifferential, VariableTableAndRange) {
  PathFollowerUnit omni("f", Mode::kPath, {{0, 0}, {1, 0}});
  EXPECT_FALSE(omni.variables().Find("turn_in_place_angle"));
  EXPECT_EQ(omni.base(), Base::kOmnidirectional);
  PathFollowerUnit u("f", Mode::kPath, {{0, 0}, {1, 0}}, Base::kDifferential);
  ASSERT_TRUE(u.variables().Find("turn_in_place_angle"));
  EXPECT_EQ(Real(u, "turn_in_place_angle"), 0.5);
  EXPECT_TRUE(u.CheckParameters().empty());
  SetParam(u, "turn_in_place_angle", kPi / 2);
  const auto problems = u.CheckParameters();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].variable, "turn_in_place_angle");
  // Declared with the parameter (the table's rule), not in CheckParameters.
  const auto& v = u.variables();
  EXPECT_EQ(v.info(*v.Find("speed")).rule.Text(), "> 0");
  EXPECT_EQ(v.info(*v.Find("heading")).rule.Text(), "finite");
  // The differential base turns only by the yaw rate: k_yaw and
  // max_yaw_rate must be > 0 (0 froze it); the omnidirectional base may
  // switch its heading loop off.
  EXPECT_EQ(v.info(*v.Find("k_yaw")).rule.Text(), "> 0");
  EXPECT_EQ(v.info(*v.Find("max_yaw_rate")).rule.Text(), "> 0");
  EXPECT_EQ(omni.variables().info(*omni.variables().Find("k_yaw")).rule.Text(), ">= 0");
  EXPECT_EQ(omni.variables().info(*omni.variables().Find("max_yaw_rate")).rule.Text(), ">= 0");
  // turn_in_place_angle in (0, pi/2): at 0 the robot never drives.
  const cosim::Rule& angle = v.info(*v.Find("turn_in_place_angle")).rule;
  ASSERT_TRUE(angle.Violation(kPi / 2));
  EXPECT_EQ(angle.Violation(kPi / 2)->rfind("must be in (0, ", 0), 0u) << *angle.Violation(kPi / 2);
  ASSERT_TRUE(angle.Violation(0.0));
  EXPECT_EQ(angle.Violation(0.0)->rfind("must be in (0, ", 0), 0u) << *angle.Violation(0.0);
  EXPECT_FALSE(angle.Violation(1e-3));
  PathFollowerUnit frozen("f", Mode::kPath, {{0, 0}, {1, 0}}, Base::kDifferential);
  SetParam(frozen, "turn_in_place_angle", 0.0);
  SetParam(frozen, "k_yaw", 0.0);
  SetParam(frozen, "max_yaw_rate", 0.0);
  std::vector<std::string> refused;
  for (const auto& p : frozen.CheckParameters()) refused.push_back(p.variable);
  std::sort(refused.begin(), refused.end());
  EXPECT_EQ(refused, (std::vector<std::string>{"k_yaw", "max_yaw_rate", "turn_in_place_angle"}));
  EXPECT_THROW(frozen.Initialize(), cosim::UnitError);
  PathFollowerUnit omni_off("f", Mode::kPath, {{0, 0}, {1, 0}});
  SetParam(omni_off, "k_yaw", 0.0);
  SetParam(omni_off, "max_yaw_rate", 0.0);
  EXPECT_TRUE(omni_off.CheckParameters().empty());
}

// Guards the differential law on an L-shaped path (0,0) -> (2,0) -> (2,2),
// the robot starting on the path but facing +90 deg (across it), defaults
// (speed 0.3 m/s, ramp 0.3 m/s^2, k_yaw 1/s, max_yaw_rate 0.5 rad/s,
// turn_in_place_angle 0.5 rad):
//  - it first turns in place: not a millimetre of motion while the heading
//    error exceeds 0.5 rad, and at once the command is [0, 0], -0.5 rad/s;
//  - the 90 deg corner is turned in place: the heading passes 45 deg within
//    2 cm of the corner (the robot passes it by at most one sample's travel,
//    0.3 m/s * 20 ms = 6 mm, before the heading error exceeds 0.5 rad);
//  - the cross-track error stays below the bound of the worst lateral drift
//    after a turn in place, without the cross-track feedback (which only
//    reduces it): the heading error decays from 0.5 rad as 0.5 exp(-t)
//    (k_yaw h, below the rate limit) while the speed ramps as 0.3 t up to
//    0.3 m/s at 1 s, so e <= int 0.3 min(t, 1) 0.5 exp(-t) dt
//    = 0.15 (1 - 1/e) = 0.095 m, plus the 6 mm corner overshoot: 0.101 m;
//  - it reaches the goal (done latches within goal_tolerance) and stops.
TEST(PathFollowerUnitDifferential, FollowsAnLShapedPathTurningInPlaceAtTheCorner) {
  PathFollowerUnit u("f", Mode::kPath, {{0, 0}, {2, 0}, {2, 2}}, Base::kDifferential);
  Unicycle r;
  r.yaw = kPi / 2;
  SetPose(u, r.x, r.y, r.yaw);
  u.Initialize();
  const auto first = Twist(u);
  EXPECT_EQ(first, (std::vector<double>{0.0, 0.0, -0.5}));
  double worst_cross = 0.0, corner_distance = -1.0, start_drift = 0.0;
  bool corner_turned_in_place = false, turned_at_start = false;
  int k = 0;
  for (; k < 3000 && !Done(u); ++k) {
    const auto cmd = Sample(u, r, k);
    ASSERT_EQ(cmd[1], 0.0) << k;  // never sideways
    worst_cross = std::max(worst_cross, std::abs(Real(u, "cross_track_error")));
    if (!turned_at_start) {
      if (std::abs(r.yaw) > 0.5) start_drift = std::max(start_drift, std::hypot(r.x, r.y));
      turned_at_start = std::abs(r.yaw) <= 0.5;
    }
    const double yaw_before = r.yaw;
    r.Move(cmd[0], cmd[2], kPeriodS);
    if (corner_distance < 0 && r.x > 1.0 && yaw_before < kPi / 4 && r.yaw >= kPi / 4) {
      corner_distance = std::hypot(r.x - 2.0, r.y);
      corner_turned_in_place = cmd[0] == 0.0;
    }
  }
  std::cout << "differential L path: done after " << k * kPeriodS << " s, worst cross-track "
            << worst_cross << " m, heading 45 deg at " << corner_distance << " m from the corner\n";
  EXPECT_EQ(start_drift, 0.0);
  EXPECT_TRUE(Done(u));
  EXPECT_LE(std::hypot(r.x - 2.0, r.y - 2.0), Real(u, "goal_tolerance"));
  EXPECT_GE(corner_distance, 0.0);
  EXPECT_LT(corner_distance, 0.02);
  EXPECT_TRUE(corner_turned_in_place);
  EXPECT_LT(worst_cross, 0.101);
  // 4 m at 0.3 m/s is 13.3 s; two turns at most 0.5 rad/s (pi/2 each) 6.3 s,
  // ramps and the final approach add a few seconds: well inside 30 s.
  EXPECT_LT(k * kPeriodS, 30.0);
  const auto stop = Sample(u, r, k);
  EXPECT_EQ(stop, (std::vector<double>{0.0, 0.0, 0.0}));
}

// Guards the corner law of the differential base on a U path (0,0) ->
// (3,0) -> (3,3) -> (0,3), two 90 deg left corners (sharp: more than the
// 0.5 rad turn_in_place_angle), at the Husky's 0.5 m/s, 0.3 m/s^2, with a
// non-oscillating heading loop (k_yaw 2/s >= 4 k_cross, k_cross 0.5/s) and
// the exact unicycle:
//  - the along-track speed comes down as sqrt(2 a D) before each corner, D
//    the distance to it: the robot stops AT the corner. Sampled at T, one
//    step from D moves at most sqrt(2 a D) T, whose worst excess over D is
//    at D = a T^2 / 2: the robot passes a corner by at most a T^2 / 2 =
//    0.06 mm (measured along the segment it arrives on, while it turns);
//  - it turns in place onto the next tangent (a committed segment: the aim
//    does not flip with the nearest segment) and drives on: one turn in
//    place per corner, and from its start to the next corner's the yaw-rate
//    command changes sign at most once (the critically damped cross-track
//    loop corrects the drift after the turn without overshoot; none before
//    the first corner: it starts on the path, facing along it);
//  - it arrives (done) in less than the time of 9 m at 0.5 m/s (18 s), two
//    ramps down and up (2 x 1.67 s x 2, 6.7 s) and two quarter turns at the
//    2 rad/s limit and the 2/s heading gain (about 2 x 1.6 s), plus margin.
TEST(PathFollowerUnitDifferential, StopsAtSharpCornersAndTurnsWithoutHunting) {
  PathFollowerUnit u("f", Mode::kPath, {{0, 0}, {3, 0}, {3, 3}, {0, 3}}, Base::kDifferential);
  SetParam(u, "speed", 0.5);
  SetParam(u, "max_speed", 1.0);
  SetParam(u, "acceleration", 0.3);
  SetParam(u, "k_yaw", 2.0);
  SetParam(u, "k_cross", 0.5);
  SetParam(u, "max_yaw_rate", 2.0);
  Unicycle r;
  SetPose(u, r.x, r.y, r.yaw);
  u.Initialize();
  const double bound = 0.5 * 0.3 * kPeriodS * kPeriodS;
  double overshoot1 = -1.0, overshoot2 = -1.0, last_rate = 0.0;
  // Sign changes of the yaw-rate command per corner: from the start of a
  // turn in place to the start of the next one (the first turn's own sign
  // against the last correction of the leg before is not hunting).
  std::vector<int> changes;
  int k = 0;
  bool was_turning = false;
  for (; k < 3000 && !Done(u); ++k) {
    const auto cmd = Sample(u, r, k);
    const bool turning = cmd[0] == 0.0 && cmd[2] != 0.0;
    if (turning && !was_turning && k > 0) {
      changes.push_back(0);
      last_rate = 0.0;
    }
    was_turning = turning;
    if (turning) {
      if (r.y < 1.5) overshoot1 = std::max(overshoot1, r.x - 3.0);
      else overshoot2 = std::max(overshoot2, r.y - 3.0);
    }
    if (cmd[2] != 0.0) {
      if (last_rate != 0.0 && (cmd[2] > 0) != (last_rate > 0)) {
        ASSERT_FALSE(changes.empty()) << "the yaw rate changed sign before the first corner";
        ++changes.back();
      }
      last_rate = cmd[2];
    }
    r.Move(cmd[0], cmd[2], kPeriodS);
  }
  std::cout << "differential U path: done after " << k * kPeriodS << " s, corner overshoots "
            << overshoot1 << ", " << overshoot2 << " m, yaw-rate sign changes per corner";
  for (const int c : changes) std::cout << " " << c;
  std::cout << "\n";
  ASSERT_TRUE(Done(u));
  EXPECT_LE(std::hypot(r.x, r.y - 3.0), Real(u, "goal_tolerance"));
  EXPECT_GT(overshoot1, -0.001);  // it did turn in place at the corner, not before it
  EXPECT_GT(overshoot2, -0.001);
  EXPECT_LE(overshoot1, bound + 1e-12);
  EXPECT_LE(overshoot2, bound + 1e-12);
  ASSERT_EQ(changes.size(), 2u);  // one turn in place per corner
  for (const int c : changes) EXPECT_LE(c, 1);
  EXPECT_LT(k * kPeriodS, 32.0);
}

// Guards against the flip of the aim at a corner when the commanded speed is
// small: at rest a hair past the corner of an L path and to the left of
// the second leg's line, facing along the first leg, the aim is the second
// leg's tangent (+y, corrected by k_cross e), not the nearest segment's
// direction of the moment; the command is a turn in place to the left, and
// moving the robot by micrometres around the corner does not change its sign.
TEST(PathFollowerUnitDifferential, AimAtTheCornerDoesNotFlip) {
  PathFollowerUnit u("f", Mode::kPath, {{0, 0}, {2, 0}, {2, 2}}, Base::kDifferential);
  Unicycle r;
  SetPose(u, r.x, r.y, r.yaw);
  u.Initialize();
  int k = 0;
  // Drive to the corner.
  for (; k < 10 || (k < 2000 && Twist(u)[0] != 0.0); ++k) {
    const auto cmd = Sample(u, r, k);
    r.Move(cmd[0], cmd[2], kPeriodS);
  }
  ASSERT_NEAR(r.x, 2.0, 1e-3);
  for (const double dx : {-2e-6, -1e-6, 0.0, 1e-6, 2e-6}) {
    for (const double dy : {-2e-6, 0.0, 2e-6}) {
      SetPose(u, r.x + dx, r.y + dy, r.yaw);
      u.UpdateOutputs();
      EXPECT_EQ(Twist(u)[0], 0.0);
      EXPECT_GT(Twist(u)[2], 0.0) << dx << " " << dy;
    }
  }
}

// Follows a path with one 0.3 rad corner at (2, 0) with the exact unicycle
// (turn_in_place_angle as given, else its default) and returns the slowest
// forward command within 0.2 m of the corner; the goal must be reached.
double SlowestNearAGentleCorner(std::optional<double> turn_in_place_angle) {
  const double c = std::cos(0.3), s = std::sin(0.3);
  PathFollowerUnit u("f", Mode::kPath, {{0, 0}, {2, 0}, {2 + 2 * c, 2 * s}}, Base::kDifferential);
  if (turn_in_place_angle) SetParam(u, "turn_in_place_angle", *turn_in_place_angle);
  Unicycle r;
  SetPose(u, r.x, r.y, r.yaw);
  u.Initialize();
  double slowest = 1.0;
  for (int k = 0; k < 3000 && !Done(u); ++k) {
    const auto cmd = Sample(u, r, k);
    if (std::hypot(r.x - 2.0, r.y) < 0.2) slowest = std::min(slowest, cmd[0]);
    r.Move(cmd[0], cmd[2], kPeriodS);
  }
  EXPECT_TRUE(Done(u));
  return slowest;
}

// Guards the other side of the corner rule: a gentle corner (0.3 rad, less
// than the 0.5 rad turn_in_place_angle) is driven through without stopping
// or turning in place. The speed dips (the ramp continues from v cos h,
// which settles at a T / (1 - cos h) = 0.13 m/s for a standing 0.3 rad
// error, here briefly: 0.2 m/s) but stays above half the 0.3 m/s cruise.
TEST(PathFollowerUnitDifferential, DrivesThroughAGentleCorner) {
  EXPECT_GT(SlowestNearAGentleCorner(std::nullopt), 0.15);
}

// Guards the table of sharp corners (computed once, not per step): it
// follows turn_in_place_angle as set before Initialize. The same 0.3 rad
// corner is sharp for a 0.2 rad turn_in_place_angle: the robot stops at
// it (within a T^2 / 2 sample of it, the forward command is 0 there) and
// turns in place, where at 0.5 rad it drove through.
TEST(PathFollowerUnitDifferential, SharpCornersFollowTheAngleSetBeforeInitialize) {
  EXPECT_EQ(SlowestNearAGentleCorner(0.2), 0.0);
}

// Guards the saved state of the differential base: the active segment is
// saved and restored (a restored unit continues bit for bit through a
// corner), and a segment that is not one of the path is refused.
TEST(PathFollowerUnitDifferential, SaveStepRestoreStepThroughACorner) {
  const std::vector<std::array<double, 2>> path = {{0, 0}, {0.5, 0}, {0.5, 0.5}, {0, 0.5}};
  const auto run = [](PathFollowerUnit& u, Unicycle r, int from, int to) {
    std::vector<double> out;
    for (int k = from; k < to; ++k) {
      const auto cmd = Sample(u, r, k);
      out.insert(out.end(), cmd.begin(), cmd.end());
      r.Move(cmd[0], cmd[2], kPeriodS);
    }
    return out;
  };
  PathFollowerUnit u("f", Mode::kPath, path, Base::kDifferential);
  Unicycle r;
  SetPose(u, r.x, r.y, r.yaw);
  u.Initialize();
  for (int k = 0; k < 300; ++k) {  // past the first corner
    const auto cmd = Sample(u, r, k);
    r.Move(cmd[0], cmd[2], kPeriodS);
  }
  ASSERT_GT(r.yaw, 1.0);
  const cosim::UnitState saved = u.SaveState();
  ASSERT_EQ(saved.integers.size(), 2u);
  EXPECT_EQ(saved.integers[1], 1);  // on the second segment
  const auto first = run(u, r, 300, 600);
  PathFollowerUnit fresh("f", Mode::kPath, path, Base::kDifferential);
  fresh.RestoreState(saved);
  const auto second = run(fresh, r, 300, 600);
  ASSERT_EQ(first.size(), second.size());
  EXPECT_EQ(std::memcmp(first.data(), second.data(), first.size() * sizeof(double)), 0);
  cosim::UnitState bad = saved;
  bad.integers[1] = 3;  // three segments: 0, 1, 2
  EXPECT_THROW(fresh.RestoreState(bad), cosim::UnitError);
}

// Guards the differential base past the goal, path (0,0) -> (2,0), the
// robot 0.3 m beyond the goal facing away from it (defaults): the aim
// points back at the goal, so the robot turns round in place (no motion
// while the heading error exceeds turn_in_place_angle) and drives FORWARDS
// to the goal: the forward command is never negative (the law once drove
// the turned robot backwards, away from the goal, and never finished), the
// robot never gets farther from the goal than at the start, and done
// latches within goal_tolerance of it.
TEST(PathFollowerUnitDifferential, PastTheGoalTurnsRoundAndDrivesToIt) {
  PathFollowerUnit u("f", Mode::kPath, {{0, 0}, {2, 0}}, Base::kDifferential);
  Unicycle r;
  r.x = 2.3;
  SetPose(u, r.x, r.y, r.yaw);
  u.Initialize();
  EXPECT_EQ(Twist(u)[0], 0.0);  // turn in place first
  double farthest = 0.0;
  int k = 0;
  for (; k < 3000 && !Done(u); ++k) {
    const auto cmd = Sample(u, r, k);
    ASSERT_GE(cmd[0], 0.0) << k;
    r.Move(cmd[0], cmd[2], kPeriodS);
    farthest = std::max(farthest, std::hypot(r.x - 2.0, r.y));
  }
  std::cout << "differential past the goal: done after " << k * kPeriodS << " s at (" << r.x
            << ", " << r.y << ")\n";
  ASSERT_TRUE(Done(u));
  EXPECT_LE(std::hypot(r.x - 2.0, r.y), Real(u, "goal_tolerance"));
  EXPECT_LE(farthest, 0.3 + 1e-9);
  // A half turn at the 0.5 rad/s limit (6.3 s) and 0.3 m: well inside 15 s.
  EXPECT_LT(k * kPeriodS, 15.0);
}

// Guards the differential base beside the goal, path (0,0) -> (2,0): a
// robot whose projection reaches the goal's perpendicular with a sideways
// offset beyond goal_tolerance must still reach the goal (the approach
// speed once depended on the distance left ALONG the path only: 0 on the
// perpendicular, the robot stalled at (2.000, 0.068) and done never
// latched). On the last segment the speed is limited by the straight-line
// distance to the goal, and near it the aim points at the goal. Two starts:
// 0.3 m left of the path 0.4 m before the goal, and exactly on the goal's
// perpendicular 0.1 m to the side; both finish forwards, within 10 s.
TEST(PathFollowerUnitDifferential, BesideTheGoalStillReachesIt) {
  for (const auto& [x0, y0] : {std::pair{1.6, 0.3}, std::pair{2.0, 0.1}}) {
    PathFollowerUnit u("f", Mode::kPath, {{0, 0}, {2, 0}}, Base::kDifferential);
    Unicycle r;
    r.x = x0;
    r.y = y0;
    SetPose(u, r.x, r.y, r.yaw);
    u.Initialize();
    int k = 0;
    for (; k < 3000 && !Done(u); ++k) {
      const auto cmd = Sample(u, r, k);
      ASSERT_GE(cmd[0], 0.0) << k;
      r.Move(cmd[0], cmd[2], kPeriodS);
    }
    std::cout << "differential beside the goal from (" << x0 << ", " << y0 << "): done after "
              << k * kPeriodS << " s at (" << r.x << ", " << r.y << ")\n";
    ASSERT_TRUE(Done(u)) << x0 << ", " << y0 << ": stopped at (" << r.x << ", " << r.y << ")";
    EXPECT_LE(std::hypot(r.x - 2.0, r.y), Real(u, "goal_tolerance"));
    EXPECT_LT(k * kPeriodS, 10.0);
    EXPECT_EQ(Sample(u, r, k), (std::vector<double>{0.0, 0.0, 0.0}));
  }
}

// Guards the hold law of the differential base: a point behind is reached
// backing up without turning (the nearer heading), a point to the side by
// a turn in place and a drive; inside goal_tolerance the robot stops.
TEST(PathFollowerUnitDifferential, HoldBacksUpOrTurnsThenStops) {
  {
    PathFollowerUnit u("h", Mode::kHold, {{-0.5, 0.0}}, Base::kDifferential);
    Unicycle r;
    SetPose(u, r.x, r.y, r.yaw);
    u.Initialize();
    // -k_position * 0.5 m: straight back at 0.5 m/s (max_speed 0.5).
    EXPECT_EQ(Twist(u), (std::vector<double>{-0.5, 0.0, 0.0}));
    int k = 0;
    for (; k < 500 && !Done(u); ++k) {
      const auto cmd = Sample(u, r, k);
      r.Move(cmd[0], cmd[2], kPeriodS);
    }
    EXPECT_TRUE(Done(u));
    EXPECT_EQ(r.yaw, 0.0);
    EXPECT_NEAR(r.x, -0.5, Real(u, "goal_tolerance"));
  }
  PathFollowerUnit u("h", Mode::kHold, {{0.0, 0.5}}, Base::kDifferential);
  Unicycle r;
  SetPose(u, r.x, r.y, r.yaw);
  u.Initialize();
  EXPECT_EQ(Twist(u), (std::vector<double>{0.0, 0.0, 0.5}));  // turn in place, 90 deg left
  int k = 0;
  for (; k < 1000 && !Done(u); ++k) {
    const auto cmd = Sample(u, r, k);
    r.Move(cmd[0], cmd[2], kPeriodS);
  }
  ASSERT_TRUE(Done(u));
  EXPECT_LE(std::hypot(r.x, r.y - 0.5), Real(u, "goal_tolerance"));
  EXPECT_EQ(Sample(u, r, k), (std::vector<double>{0.0, 0.0, 0.0}));
}

}  // namespace
}  // namespace linesim::control
