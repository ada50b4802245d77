#include "units/control/route_follower_unit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include "cosim/time.h"

namespace linesim::control {
namespace {

using cosim::TimeNs;
using models::PolynomialSegment;

constexpr TimeNs kPeriod = 20'000'000;
constexpr double kPeriodS = 0.02;
constexpr double kPi = std::numbers::pi;

// A straight segment from (x0, y0) to (x1, y1).
PolynomialSegment Line(double x0, double y0, double x1, double y1, int map = 0) {
  return {{x0, x1 - x0}, {y0, y1 - y0}, map};
}

void SetPose(RouteFollowerUnit& u, double x, double y, double yaw) {
  u.variables().SetRealArray(*u.variables().Find("position"), std::vector<double>{x, y});
  u.variables().SetReal(*u.variables().Find("yaw"), yaw);
}
void SetParam(RouteFollowerUnit& u, const std::string& name, double v) {
  u.variables().SetReal(*u.variables().Find(name), v);
}
double Real(const RouteFollowerUnit& u, const std::string& name) {
  return u.variables().GetReal(*u.variables().Find(name));
}
std::int64_t Int(const RouteFollowerUnit& u, const std::string& name) {
  return u.variables().GetInteger(*u.variables().Find(name));
}
bool Done(const RouteFollowerUnit& u) {
  return u.variables().GetBoolean(*u.variables().Find("done"));
}
double Speed(const RouteFollowerUnit& u) {
  return u.variables().GetRealArray(*u.variables().Find("velocity_command"))[0];
}

// A unicycle (the differential base's kinematics): the commands held over a
// period move the pose along the exact arc.
struct Unicycle {
  double x = 0, y = 0, yaw = 0;
  void Move(double v, double w, double dt) {
    if (std::abs(w) < 1e-12) {
      x += v * std::cos(yaw) * dt;
      y += v * std::sin(yaw) * dt;
    } else {
      x += v / w * (std::sin(yaw + w * dt) - std::sin(yaw));
      y -= v / w * (std::cos(yaw + w * dt) - std::cos(yaw));
    }
    yaw += w * dt;
  }
};

// One control period as the master runs it: pose in, commands out, DoStep,
// then the robot moves under the commands.
void Period(RouteFollowerUnit& u, Unicycle& r, int k) {
  SetPose(u, r.x, r.y, r.yaw);
  u.UpdateOutputs();
  const double v = Speed(u), w = Real(u, "yaw_rate_command");
  ASSERT_EQ(u.DoStep(k * kPeriod, kPeriod), cosim::StepResult::kOk) << u.last_error();
  r.Move(v, w, kPeriodS);
}

// Guards the interface the assembly wires (names, units, sizes, types).
TEST(RouteFollowerUnit, VariableTable) {
  RouteFollowerUnit u("route", {Line(0, 0, 1, 0)});
  EXPECT_EQ(u.type_name(), "route_follower");
  const auto& v = u.variables();
  for (const char* p :
       {"speed", "k_p_distance", "k_i_distance", "k_p_orientation", "k_i_orientation",
        "distance_integral", "max_distance_integral_rate", "max_orientation_integral_rate",
        "max_yaw_rate", "deceleration", "stop_tolerance"}) {
    ASSERT_TRUE(v.Find(p)) << p;
    EXPECT_EQ(v.info(*v.Find(p)).causality, cosim::Causality::kParameter) << p;
  }
  EXPECT_EQ(v.info(*v.Find("position")).size, 2u);
  EXPECT_EQ(v.info(*v.Find("yaw")).unit, "rad");
  const auto output = [&](const char* name, cosim::VarType type, const char* unit) {
    ASSERT_TRUE(v.Find(name)) << name;
    const auto& info = v.info(*v.Find(name));
    EXPECT_EQ(info.causality, cosim::Causality::kOutput) << name;
    EXPECT_EQ(info.type, type) << name;
    if (type == cosim::VarType::kReal || type == cosim::VarType::kRealArray) {
      EXPECT_EQ(info.unit, unit) << name;
    }
  };
  output("velocity_command", cosim::VarType::kRealArray, "m/s");
  EXPECT_EQ(v.info(*v.Find("velocity_command")).size, 2u);
  output("yaw_rate_command", cosim::VarType::kReal, "rad/s");
  output("done", cosim::VarType::kBoolean, "");
  output("segment", cosim::VarType::kInteger, "");
  output("map_index", cosim::VarType::kInteger, "");
  output("distance_error", cosim::VarType::kReal, "m");
  output("cross_track_error", cosim::VarType::kReal, "m");
  output("orientation_error", cosim::VarType::kReal, "rad");
  output("t", cosim::VarType::kReal, "1");
}

// Guards the sign switch of Eqs. 11-13 on both sides of a straight path
// along +x. Left of it (y = +0.2) the closest point is straight to the
// robot's right: T_theta = -90 deg - yaw < 0, Eq. 13: w = -K_P,D Err_D +
// K_P,theta Err_theta (turn right, back to the path); right of it, Eq. 12
// with +K_P,D Err_D. With K_P,D 2, K_P,theta 0.5, yaw 0.1:
// w = -+0.4 + 0.5 (-0.1). The robot facing back along the path (yaw pi) on
// its left side has the closest point on its left (T_theta = +90 deg):
// Eq. 12, w = +0.4 turns it left, which for a robot driving along -x is
// towards -y: back to the path again.
TEST(RouteFollowerUnit, DistanceTermSwitchesWithTheSideAndSteersBack) {
  struct Case {
    double y, yaw, w, cross_track;
  };
  for (const Case c : {Case{0.2, 0.1, -0.4 - 0.05, 0.2}, Case{-0.2, 0.1, 0.4 - 0.05, -0.2},
                       Case{0.2, kPi, 0.4 + 0.0, 0.2}}) {
    RouteFollowerUnit u("route", {Line(0, 0, 10, 0)});
    SetParam(u, "k_p_distance", 2.0);
    SetParam(u, "k_p_orientation", c.yaw == kPi ? 0.0 : 0.5);
    SetParam(u, "max_yaw_rate", 10.0);
    SetPose(u, 5.0, c.y, c.yaw);
    u.Initialize();
    EXPECT_NEAR(Real(u, "distance_error"), 0.2, 1e-15);
    EXPECT_NEAR(Real(u, "cross_track_error"), c.cross_track, 1e-15);
    EXPECT_NEAR(Real(u, "t"), 0.5, 1e-12);
    EXPECT_NEAR(Real(u, "yaw_rate_command"), c.w, 1e-12) << c.y << " " << c.yaw;
    EXPECT_NEAR(Speed(u), 0.3, 1e-15);  // V, far from the end
  }
}

// Guards the feed-forward at t_n (Eq. 17): a robot exactly on a circle of
// radius 2 m (a degree-15 polynomial quarter circle), heading along it,
// has no error and is commanded w = V / R = 0.15 rad/s.
TEST(RouteFollowerUnit, FeedForwardOnACircleIsSpeedOverRadius) {
  PolynomialSegment circle;
  circle.x.assign(16, 0.0);
  circle.y.assign(16, 0.0);
  double term = 2.0;
  for (int i = 0; i < 16; ++i) {
    if (i > 0) term *= (kPi / 2) / i;
    const int phase = i % 4;
    circle.x[i] = phase == 0 ? term : phase == 2 ? -term : 0.0;
    circle.y[i] = phase == 1 ? term : phase == 3 ? -term : 0.0;
  }
  RouteFollowerUnit u("route", {circle, Line(0, 2, -5, 2)});
  const double a = 0.3;  // rad along the circle
  SetPose(u, 2 * std::cos(a), 2 * std::sin(a), a + kPi / 2);
  u.Initialize();
  EXPECT_NEAR(Real(u, "distance_error"), 0.0, 1e-9);
  EXPECT_NEAR(Real(u, "orientation_error"), 0.0, 1e-8);
  EXPECT_NEAR(Real(u, "t"), a / (kPi / 2), 1e-8);
  EXPECT_NEAR(Real(u, "yaw_rate_command"), 0.15, 1e-7);
}

// Guards the closed loop on a straight path with the default gains (a
// double pole at p = 1.5 rad/s at 0.3 m/s): from 0.1 m left of the path,
// heading along it, the linearised offset is e(t) = e0 (1 + p t) e^{-p t}.
// The unicycle with the unit in the loop at 50 Hz follows it within 5 % of
// e0, never crosses the path (critically damped), and is below 2 mm at 5 s.
TEST(RouteFollowerUnit, DistanceErrorDecaysOnAStraightPath) {
  RouteFollowerUnit u("route", {Line(0, 0, 20, 0)});
  Unicycle r{0.0, 0.1, 0.0};
  SetPose(u, r.x, r.y, r.yaw);
  u.Initialize();
  const double p = 1.5, e0 = 0.1;
  double worst = 0.0, lowest = e0;
  for (int k = 0; k < 250; ++k) {
    Period(u, r, k);
    const double time = (k + 1) * kPeriodS;
    worst = std::max(worst, std::abs(r.y - e0 * (1 + p * time) * std::exp(-p * time)));
    lowest = std::min(lowest, r.y);
  }
  EXPECT_LT(worst, 0.05 * e0);
  EXPECT_GT(lowest, 0.0);
  EXPECT_LT(r.y, 0.002);
  EXPECT_FALSE(Done(u));
}

// Guards the segment advance, the map index, the stop and done: along two
// straight segments (maps 0 and 1) the robot is on segment 0 until it
// passes x = 1, then on segment 1 (map 1) and never back, even when its
// pose is put back before the joint; it stops within stop_tolerance of the
// end (2 mm; the sqrt profile reaches it in finite time), done latches,
// and both commands are 0 from then on.
TEST(RouteFollowerUnit, AdvancesSegmentsStopsOnTheEndAndLatchesDone) {
  RouteFollowerUnit u("route", {Line(0, 0, 1, 0, 0), Line(1, 0, 2, 0, 1)});
  Unicycle r;
  SetPose(u, r.x, r.y, r.yaw);
  u.Initialize();
  EXPECT_EQ(Int(u, "segment"), 0);
  EXPECT_EQ(Int(u, "map_index"), 0);
  int k = 0;
  for (; k < 1000 && !Done(u); ++k) {
    const double x = r.x;  // the pose the unit sees in this period
    Period(u, r, k);
    EXPECT_EQ(Int(u, "segment"), x < 1.0 ? 0 : 1) << x;
    EXPECT_EQ(Int(u, "map_index"), Int(u, "segment"));
  }
  ASSERT_TRUE(Done(u));
  // 2 m at 0.3 m/s (and the last 0.18 m slower): about 7.3 s.
  EXPECT_GT(k * kPeriodS, 6.5);
  EXPECT_LT(k * kPeriodS, 9.0);
  EXPECT_NEAR(r.x, 2.0, 0.0021);
  EXPECT_LE(r.x, 2.0);
  EXPECT_EQ(Speed(u), 0.0);
  // Latched: the robot pushed back stays done, on the last segment.
  SetPose(u, 1.5, 0.1, 0.0);
  u.UpdateOutputs();
  EXPECT_TRUE(Done(u));
  EXPECT_EQ(Speed(u), 0.0);
  EXPECT_EQ(Real(u, "yaw_rate_command"), 0.0);
  EXPECT_EQ(Int(u, "segment"), 1);
}

// Guards against chattering at a joint: once the robot has passed the end
// of segment 0, a pose back before the joint keeps segment 1 (its t_n is 0).
TEST(RouteFollowerUnit, SegmentNeverGoesBack) {
  RouteFollowerUnit u("route", {Line(0, 0, 1, 0, 0), Line(1, 0, 1, 1, 1)});
  SetPose(u, 0.9, 0.0, 0.0);
  u.Initialize();
  ASSERT_EQ(u.DoStep(0, kPeriod), cosim::StepResult::kOk);
  EXPECT_EQ(Int(u, "segment"), 0);
  SetPose(u, 1.001, -0.01, 0.0);
  ASSERT_EQ(u.DoStep(kPeriod, kPeriod), cosim::StepResult::kOk);
  EXPECT_EQ(Int(u, "segment"), 1);
  SetPose(u, 0.999, -0.01, 0.0);
  ASSERT_EQ(u.DoStep(2 * kPeriod, kPeriod), cosim::StepResult::kOk);
  EXPECT_EQ(Int(u, "segment"), 1);
  EXPECT_EQ(Real(u, "t"), 0.0);
  EXPECT_EQ(Int(u, "map_index"), 1);
}

// Guards the anti-windup clamp of the (unsigned, Eqs. 12-13) distance
// integral: a robot held 0.5 m left of the path with K_P,D = 0, K_I,D = 1
// integrates 0.5 m per second; its term is clamped at
// max_distance_integral_rate (0.15 rad/s), with the sign of Eq. 13 (-).
// Before the clamp (0.1 s: 0.05 m s) the term is -0.05.
TEST(RouteFollowerUnit, DistanceIntegralIsClampedAndSwitched) {
  RouteFollowerUnit u("route", {Line(0, 0, 100, 0)});
  SetParam(u, "k_p_distance", 0.0);
  SetParam(u, "k_p_orientation", 0.0);
  SetParam(u, "k_i_distance", 1.0);
  SetPose(u, 5.0, 0.5, 0.0);
  u.Initialize();
  for (int k = 0; k < 5; ++k) ASSERT_EQ(u.DoStep(k * kPeriod, kPeriod), cosim::StepResult::kOk);
  EXPECT_NEAR(Real(u, "yaw_rate_command"), -0.05, 1e-12);
  for (int k = 5; k < 100; ++k) ASSERT_EQ(u.DoStep(k * kPeriod, kPeriod), cosim::StepResult::kOk);
  EXPECT_NEAR(Real(u, "yaw_rate_command"), -0.15, 1e-12);
  // The other side: the same (non-negative) integral, the other sign (Eq. 12).
  SetPose(u, 5.0, -0.5, 0.0);
  u.UpdateOutputs();
  EXPECT_NEAR(Real(u, "yaw_rate_command"), 0.15, 1e-12);
}

// Guards the signed variant: the integral of the switched distance falls
// back through zero when the robot changes side (0.1 s left, then 0.1 s
// right at the same 0.5 m: 0 m s, no term).
TEST(RouteFollowerUnit, SignedDistanceIntegralCancelsAcrossThePath) {
  RouteFollowerUnit u("route", {Line(0, 0, 100, 0)});
  u.variables().SetString(*u.variables().Find("distance_integral"), "signed");
  SetParam(u, "k_p_distance", 0.0);
  SetParam(u, "k_p_orientation", 0.0);
  SetParam(u, "k_i_distance", 1.0);
  SetPose(u, 5.0, 0.5, 0.0);
  u.Initialize();
  for (int k = 0; k < 5; ++k) ASSERT_EQ(u.DoStep(k * kPeriod, kPeriod), cosim::StepResult::kOk);
  EXPECT_NEAR(Real(u, "yaw_rate_command"), -0.05, 1e-12);
  SetPose(u, 5.0, -0.5, 0.0);
  for (int k = 5; k < 10; ++k) ASSERT_EQ(u.DoStep(k * kPeriod, kPeriod), cosim::StepResult::kOk);
  EXPECT_NEAR(Real(u, "yaw_rate_command"), 0.0, 1e-12);
}

// Guards the yaw-rate limit and the conditional integration: while the
// command is clamped, the orientation integral does not grow.
TEST(RouteFollowerUnit, YawRateIsClampedWithoutWindup) {
  RouteFollowerUnit u("route", {Line(0, 0, 100, 0)});
  SetParam(u, "k_i_orientation", 1.0);
  SetParam(u, "max_yaw_rate", 0.5);
  SetPose(u, 5.0, 0.0, -1.0);  // Err_theta = 1 rad: K_P,theta 3 -> 3 rad/s unclamped
  u.Initialize();
  for (int k = 0; k < 50; ++k) ASSERT_EQ(u.DoStep(k * kPeriod, kPeriod), cosim::StepResult::kOk);
  EXPECT_EQ(Real(u, "yaw_rate_command"), 0.5);
  SetPose(u, 5.0, 0.0, -0.1);  // 0.3 rad/s from K_P,theta; the integral stayed at 0
  u.UpdateOutputs();
  EXPECT_NEAR(Real(u, "yaw_rate_command"), 0.3, 1e-12);
}

// Guards save/restore: a restored unit (segment, integrals, done) continues
// bit for bit.
TEST(RouteFollowerUnit, RestoredUnitContinuesIdentically) {
  const std::vector<PolynomialSegment> route = {models::HermiteSegment(0, 0, 0, 2, 1, 0.5, 0.0, 0),
                                                models::HermiteSegment(2, 1, 0.5, 3, 1, 0, 0.0, 1)};
  RouteFollowerUnit u("route", route);
  SetParam(u, "k_i_distance", 0.5);
  SetParam(u, "k_i_orientation", 0.5);
  Unicycle r{0.0, -0.1, 0.2};
  SetPose(u, r.x, r.y, r.yaw);
  u.Initialize();
  int k = 0;
  for (; k < 200; ++k) Period(u, r, k);
  const cosim::UnitState saved = u.SaveState();
  const Unicycle at_save = r;
  std::vector<double> first, second;
  for (int j = 0; j < 600; ++j) {
    Period(u, r, k + j);
    first.push_back(Real(u, "yaw_rate_command"));
    first.push_back(static_cast<double>(Int(u, "segment")));
    first.push_back(Done(u) ? 1.0 : 0.0);
  }
  EXPECT_TRUE(Done(u));
  RouteFollowerUnit v("route", route);
  v.RestoreState(saved);
  r = at_save;
  for (int j = 0; j < 600; ++j) {
    Period(v, r, k + j);
    second.push_back(Real(v, "yaw_rate_command"));
    second.push_back(static_cast<double>(Int(v, "segment")));
    second.push_back(Done(v) ? 1.0 : 0.0);
  }
  EXPECT_EQ(first, second);
}

// Guards the checks of the route: segments must join (1 mm), have a length
// and finite coefficients.
TEST(RouteFollowerUnit, BadRoutesAreRefused) {
  const auto problems = [](std::vector<PolynomialSegment> route) {
    RouteFollowerUnit u("route", std::move(route));
    std::string all;
    for (const auto& p : u.CheckParameters()) all += p.message + "\n";
    return all;
  };
  EXPECT_EQ(problems({Line(0, 0, 1, 0), Line(1, 0, 2, 0)}), "");
  EXPECT_NE(problems({Line(0, 0, 1, 0), Line(1.1, 0, 2, 0)}).find("starts 0.1 m from the end"),
            std::string::npos);
  EXPECT_NE(problems({{{1.0}, {2.0}, 0}}).find("has no length"), std::string::npos);
  EXPECT_NE(problems({{{0.0, NAN}, {0.0}, 0}}).find("not finite"), std::string::npos);
  EXPECT_NE(problems({}).find("at least one segment"), std::string::npos);
}

}  // namespace
}  // namespace linesim::control
