// The pose_fusion unit (units/estimation/pose_fusion_unit.h).
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "tests/units/test_helpers.h"
#include "units/estimation/planar_arc.h"
#include "units/estimation/pose_fusion_unit.h"

namespace linesim::estimation {
namespace {

using cosim::TimeNs;
using test_helpers::Get;
using test_helpers::SetAll;
using test_helpers::SetArray;

constexpr TimeNs kMs = 1'000'000;
constexpr TimeNs kCycle = 20 * kMs;  // the robots' 20 ms control cycle

struct Pose {
  double x, y, yaw;
};

/// A match as the localization sends it: the pose, its time, a covariance
/// of 1 cm and 5 mrad (about hector_mapping's on a good scan).
struct Match {
  Pose pose;
  TimeNs time;
};

class Fusion {
 public:
  explicit Fusion(Pose initial, const std::string& yaw_source = "odometry") {
    SetAll(u, "initial_x", initial.x);
    SetAll(u, "initial_y", initial.y);
    SetAll(u, "initial_yaw", initial.yaw);
    u.variables().SetString(*u.variables().Find("yaw_rate_source"), yaw_source);
    SetArray(u, "match_covariance", {1e-4, 0, 0, 0, 1e-4, 0, 0, 0, 2.5e-5});
    u.Setup(0, 1000 * 1000 * kMs);
    u.Initialize();
  }
  /// One step from t with the odometry twist and, if given, a new match.
  void Step(double vx, double vy, double omega, const std::optional<Match>& m = std::nullopt) {
    SetArray(u, "odometry_velocity", {vx, vy});
    SetAll(u, "odometry_yaw_rate", omega);
    if (m) {
      SetArray(u, "match_position", {m->pose.x, m->pose.y});
      SetAll(u, "match_yaw", m->pose.yaw);
      SetAll(u, "match_time", cosim::NsToSeconds(m->time));
      count += 1.0;
      SetAll(u, "match_count", count);
    }
    ASSERT_EQ(u.DoStep(t, kCycle), cosim::StepResult::kOk);
    t += kCycle;
  }
  Pose Estimate() const {
    const auto p = Get(u, "position");
    return {p[0], p[1], Get(u, "yaw")[0]};
  }
  double Scalar(const std::string& name) const { return Get(u, name)[0]; }

  PoseFusionUnit u{"fusion"};
  TimeNs t = 0;
  double count = 0.0;
};

/// The pose at time s of a body starting at `p0` with the constant body
/// twist (vx, vy, omega): the exact arc (analytic).
Pose ArcPose(Pose p0, double vx, double vy, double omega, double s) {
  double dx, dy;
  ArcDisplacement(vx, vy, omega, s, &dx, &dy);
  const double c = std::cos(p0.yaw), sn = std::sin(p0.yaw);
  return {p0.x + c * dx - sn * dy, p0.y + sn * dx + c * dy, p0.yaw + omega * s};
}

double AngleError(double a, double b) { return std::remainder(a - b, 2.0 * std::numbers::pi); }

TEST(PoseFusionUnit, DeclaresItsVariables) {
  PoseFusionUnit u("fusion");
  using cosim::Causality;
  test_helpers::ExpectTable(u, {{"yaw_rate_source", Causality::kParameter, "", 0},
                                {"velocity_noise", Causality::kParameter, "m/(s.Hz^0.5)", 0},
                                {"yaw_rate_noise", Causality::kParameter, "rad/(s.Hz^0.5)", 0},
                                {"offset_random_walk", Causality::kParameter, "m/(s2.Hz^0.5)", 0},
                                {"initial_position_sigma", Causality::kParameter, "m", 0},
                                {"initial_yaw_sigma", Causality::kParameter, "rad", 0},
                                {"initial_offset_sigma", Causality::kParameter, "m/s", 0},
                                {"position_floor", Causality::kParameter, "m", 0},
                                {"yaw_floor", Causality::kParameter, "rad", 0},
                                {"gate", Causality::kParameter, "1", 0},
                                {"timeout", Causality::kParameter, "s", 0},
                                {"initial_x", Causality::kParameter, "m", 0},
                                {"initial_y", Causality::kParameter, "m", 0},
                                {"initial_yaw", Causality::kParameter, "rad", 0},
                                {"odometry_velocity", Causality::kInput, "m/s", 2},
                                {"odometry_yaw_rate", Causality::kInput, "rad/s", 0},
                                {"base_pitch", Causality::kInput, "rad", 0},
                                {"base_roll", Causality::kInput, "rad", 0},
                                {"imu_angular_velocity", Causality::kInput, "rad/s", 3},
                                {"match_position", Causality::kInput, "m", 2},
                                {"match_yaw", Causality::kInput, "rad", 0},
                                {"match_covariance", Causality::kInput, "1", 9},
                                {"match_time", Causality::kInput, "s", 0},
                                {"match_count", Causality::kInput, "1", 0},
                                {"position", Causality::kOutput, "m", 2},
                                {"yaw", Causality::kOutput, "rad", 0},
                                {"velocity", Causality::kOutput, "m/s", 2},
                                {"yaw_rate", Causality::kOutput, "rad/s", 0},
                                {"velocity_offset", Causality::kOutput, "m/s", 2},
                                {"covariance", Causality::kOutput, "1", 9},
                                {"source", Causality::kOutput, "1", 0},
                                {"rejected_matches", Causality::kOutput, "1", 0},
                                {"accepted_matches", Causality::kOutput, "1", 0},
                                {"resets", Causality::kOutput, "1", 0}});
}

// Guards the correction: a robot standing at (0.05, -0.03, 0.02) while the
// filter starts at the origin. The truth is the filter's fixed point (zero
// innovation with exact matches and exact odometry 0); the linear error
// dynamics contract, so after 10 s of matches every 40 ms (25 Hz, the S300)
// the estimate is at the truth and the covariance below the match's.
TEST(PoseFusionUnit, ConvergesToTheLaserPose) {
  Fusion f({0.0, 0.0, 0.0});
  const Pose truth{0.05, -0.03, 0.02};
  EXPECT_EQ(f.Scalar("source"), 1.0);  // no match yet
  for (int k = 0; k < 500; ++k) {
    f.Step(0.0, 0.0, 0.0, k % 2 == 0 ? std::optional<Match>({truth, f.t}) : std::nullopt);
  }
  const Pose e = f.Estimate();
  EXPECT_NEAR(e.x, truth.x, 1e-5);
  EXPECT_NEAR(e.y, truth.y, 1e-5);
  EXPECT_NEAR(e.yaw, truth.yaw, 1e-5);
  EXPECT_EQ(f.Scalar("source"), 0.0);
  EXPECT_EQ(f.Scalar("accepted_matches"), 250.0);
  EXPECT_EQ(f.Scalar("rejected_matches"), 0.0);
  const auto cov = Get(f.u, "covariance");
  EXPECT_LT(cov[0], 1e-4);
  EXPECT_LT(cov[8], 2.5e-5);
  EXPECT_EQ(cov[1], cov[3]);
}

// Guards b: the robot is carried at d = (0.08, -0.05) m/s in map (a belt
// the odometry does not see: no rectification) while its wheels report
// standing still. The truth p0 + d t with b = d is a fixed point of the
// filter (the prediction p + b dt reproduces the ramp, zero innovation);
// b is a state with an integrator, so a ramp is followed with no standing
// error (a type-2 loop): b -> d, velocity -> d.
TEST(PoseFusionUnit, OffsetConvergesToTheDriftTheOdometryMisses) {
  const Pose p0{1.0, 2.0, 0.4};
  const double dx = 0.08, dy = -0.05;
  Fusion f(p0);
  for (int k = 0; k < 1500; ++k) {  // 30 s
    const double s = cosim::NsToSeconds(f.t);
    const Pose truth{p0.x + dx * s, p0.y + dy * s, p0.yaw};
    f.Step(0.0, 0.0, 0.0, k % 2 == 0 ? std::optional<Match>({truth, f.t}) : std::nullopt);
  }
  const auto b = Get(f.u, "velocity_offset");
  EXPECT_NEAR(b[0], dx, 1e-4);
  EXPECT_NEAR(b[1], dy, 1e-4);
  const auto v = Get(f.u, "velocity");
  EXPECT_NEAR(v[0], dx, 1e-4);
  EXPECT_NEAR(v[1], dy, 1e-4);
  const double s = cosim::NsToSeconds(f.t);
  EXPECT_NEAR(f.Estimate().x, p0.x + dx * s, 1e-5);
  EXPECT_NEAR(f.Estimate().y, p0.y + dy * s, 1e-5);
}

// Guards the delay handling: a robot on the exact arc of the constant twist
// (0.3 m/s, 0.05 m/s, 0.2 rad/s) with exact odometry, matches every 40 ms
// that refer to the pose 33 ms before they arrive (off the 20 ms steps: the
// split step). Applied at their arrival they would drag the estimate back
// by |v| x 33 ms = 10 mm; applied at their own time they find zero
// innovation (the truth is the fixed point), so an initial error of 2 cm
// and 0.01 rad decays to nothing: no lag error.
TEST(PoseFusionUnit, DelayedMatchesLeaveNoLagError) {
  const Pose p0{0.0, 0.0, 0.3};
  const double vx = 0.3, vy = 0.05, w = 0.2;
  Fusion f({p0.x + 0.02, p0.y - 0.02, p0.yaw + 0.01});
  for (int k = 0; k < 500; ++k) {  // 10 s
    std::optional<Match> m;
    if (k % 2 == 0 && k > 1) {
      const TimeNs tm = f.t - 33 * kMs;
      m = Match{ArcPose(p0, vx, vy, w, cosim::NsToSeconds(tm)), tm};
    }
    f.Step(vx, vy, w, m);
  }
  const Pose truth = ArcPose(p0, vx, vy, w, cosim::NsToSeconds(f.t));
  const Pose e = f.Estimate();
  EXPECT_NEAR(e.x, truth.x, 1e-4);
  EXPECT_NEAR(e.y, truth.y, 1e-4);
  EXPECT_NEAR(AngleError(e.yaw, truth.yaw), 0.0, 1e-5);
  EXPECT_EQ(f.Scalar("rejected_matches"), 0.0);
  EXPECT_NEAR(Get(f.u, "velocity_offset")[0], 0.0, 1e-4);
}

// Guards the gate: with the filter converged (sigma of a few mm), a match
// 1 m off has a Mahalanobis distance far above 16.27 and is refused; the
// estimate stays where the odometry puts it, and the next good match is
// accepted.
TEST(PoseFusionUnit, GateRejectsAnOutlier) {
  const Pose truth{3.0, 1.0, -0.5};
  Fusion f(truth);
  for (int k = 0; k < 100; ++k) {
    f.Step(0.0, 0.0, 0.0, k % 2 == 0 ? std::optional<Match>({truth, f.t}) : std::nullopt);
  }
  EXPECT_EQ(f.Scalar("accepted_matches"), 50.0);
  f.Step(0.0, 0.0, 0.0, Match{{truth.x + 1.0, truth.y, truth.yaw}, f.t});
  EXPECT_EQ(f.Scalar("rejected_matches"), 1.0);
  EXPECT_EQ(f.Scalar("accepted_matches"), 50.0);
  EXPECT_NEAR(f.Estimate().x, truth.x, 1e-9);
  f.Step(0.0, 0.0, 0.0, Match{truth, f.t});
  EXPECT_EQ(f.Scalar("accepted_matches"), 51.0);
  EXPECT_EQ(f.Scalar("rejected_matches"), 1.0);
}

// Guards the source code: with matches it is 0 (fused); after more than
// `timeout` (0.5 s) without one it is 1 (odometry only), and exactly at
// 0.5 s still 0; matches again -> 0.
TEST(PoseFusionUnit, SourceFallsBackToOdometryAfterTimeout) {
  const Pose truth{0.0, 0.0, 0.0};
  Fusion f(truth);
  for (int k = 0; k < 10; ++k) f.Step(0.0, 0.0, 0.0, Match{truth, f.t});
  EXPECT_EQ(f.Scalar("source"), 0.0);
  const TimeNs last = f.t - kCycle;  // time of the last match
  while (f.t - last < 500 * kMs) {
    f.Step(0.0, 0.0, 0.0);
    EXPECT_EQ(f.Scalar("source"), 0.0) << cosim::NsToSeconds(f.t);
  }
  f.Step(0.0, 0.0, 0.0);
  EXPECT_EQ(f.Scalar("source"), 1.0);
  for (int k = 0; k < 25; ++k) f.Step(0.0, 0.0, 0.0);
  EXPECT_EQ(f.Scalar("source"), 1.0);
  f.Step(0.0, 0.0, 0.0, Match{truth, f.t});
  EXPECT_EQ(f.Scalar("source"), 0.0);
}

// Guards the recovery: the odometry alone carried the estimate 1 m off
// (its surface velocity wrong for a while: here it reports 0.5 m/s for 2 s
// of a robot at rest, with no match). A match at the truth then lies beyond
// the gate; refused while the fusion is fused, after timeout without an
// accepted match the pose restarts from it (resets 1) instead of waiting
// forever for a match inside the gate, and the next matches are accepted.
TEST(PoseFusionUnit, RestartsFromTheMatchesWhenTheOdometryDriftedOutOfTheGate) {
  const Pose truth{0.0, 0.0, 0.0};
  Fusion f(truth);
  for (int k = 0; k < 10; ++k) f.Step(0.0, 0.0, 0.0, Match{truth, f.t});
  for (int k = 0; k < 100; ++k) f.Step(0.5, 0.0, 0.0);  // 2 s: 1 m of drift
  EXPECT_NEAR(f.Estimate().x, 1.0, 0.05);
  EXPECT_EQ(f.Scalar("source"), 1.0);
  f.Step(0.0, 0.0, 0.0, Match{truth, f.t});
  EXPECT_EQ(f.Scalar("resets"), 1.0);
  EXPECT_NEAR(f.Estimate().x, 0.0, 1e-9);
  EXPECT_EQ(f.Scalar("source"), 0.0);
  for (int k = 0; k < 5; ++k) f.Step(0.0, 0.0, 0.0, Match{truth, f.t});
  EXPECT_EQ(f.Scalar("resets"), 1.0);
  EXPECT_EQ(f.Scalar("accepted_matches"), 15.0);
}

// Guards yaw_rate_source = imu: the odometry's yaw rate (here wrong) is
// ignored and theta integrates the IMU's z rate (analytic: 0.3 rad/s x 1 s).
TEST(PoseFusionUnit, ImuYawRateDrivesTheHeading) {
  Fusion f({0.0, 0.0, 0.0}, "imu");
  SetArray(f.u, "imu_angular_velocity", {0.01, -0.02, 0.3});
  for (int k = 0; k < 50; ++k) f.Step(0.0, 0.0, -1.0);
  EXPECT_NEAR(f.Estimate().yaw, 0.3, 1e-12);
  EXPECT_EQ(f.Scalar("yaw_rate"), 0.3);
}

// Guards the order rule: a match older than the last applied one is
// refused (replaying from before it would drop the newer correction).
TEST(PoseFusionUnit, RefusesOutOfOrderMatches) {
  const Pose truth{0.0, 0.0, 0.0};
  Fusion f(truth);
  for (int k = 0; k < 5; ++k) f.Step(0.0, 0.0, 0.0);
  f.Step(0.0, 0.0, 0.0, Match{truth, f.t - 10 * kMs});
  f.Step(0.0, 0.0, 0.0, Match{truth, f.t - 50 * kMs});
  EXPECT_EQ(f.Scalar("accepted_matches"), 1.0);
  EXPECT_EQ(f.Scalar("rejected_matches"), 1.0);
}

// Guards the history's reach: after 300 steps of 20 ms (6 s) the buffer
// holds the last 256 (5.12 s), so a match of t = 0.5 s is refused; one
// that refers exactly to a buffered step (40 ms ago) is applied there and
// carried to now: with a robot at 0.2 m/s and exact odometry the estimate
// then equals the truth the match implies (the prediction is exact).
TEST(PoseFusionUnit, MatchesOlderThanTheHistoryAreRefused) {
  const Pose p0{0.0, 0.0, 0.0};
  Fusion f(p0);
  for (int k = 0; k < 300; ++k) f.Step(0.2, 0.0, 0.0);
  f.Step(0.2, 0.0, 0.0, Match{ArcPose(p0, 0.2, 0.0, 0.0, 0.5), 500 * kMs});
  EXPECT_EQ(f.Scalar("rejected_matches"), 1.0);
  EXPECT_EQ(f.Scalar("accepted_matches"), 0.0);
  const TimeNs tm = f.t - 40 * kMs;
  Pose seen = ArcPose(p0, 0.2, 0.0, 0.0, cosim::NsToSeconds(tm));
  seen.y += 0.01;  // the laser sees the robot 1 cm to the left
  f.Step(0.2, 0.0, 0.0, Match{seen, tm});
  EXPECT_EQ(f.Scalar("accepted_matches"), 1.0);
  // After T = 6 s of dead reckoning P_yy dwarfs the match's 1e-4: b_y is
  // the initial offset (sigma0 = 0.1 m/s) plus a random walk (q = 0.1
  // m/s/sqrt(s)), so var y = sigma0^2 T^2 + q^2 T^3 / 3 = 1.08 m^2 and
  // cov(y, b_y) = sigma0^2 T + q^2 T^2 / 2 = 0.24 m^2/s: the gain on y is
  // about 1 (y moves to 0.01 at tm) and b_y takes 0.01 x 0.24 / 1.08; the
  // 40 ms replay then adds b_y x 0.04 s.
  const double b_y = 0.01 * 0.24 / 1.08;
  EXPECT_NEAR(Get(f.u, "velocity_offset")[1], b_y, 2e-4);
  EXPECT_NEAR(f.Estimate().y, 0.01 + b_y * 0.04, 5e-5);
  EXPECT_NEAR(f.Estimate().x, 0.2 * cosim::NsToSeconds(f.t), 1e-3);
}

// A restored unit continues bit for bit, including its history (delayed
// matches after the save correct states from before it).
TEST(PoseFusionUnit, RestoredUnitContinuesBitForBit) {
  const Pose p0{0.5, 0.5, 0.0};
  const auto run = [&](Fusion& f, int from, int to) {
    for (int k = from; k < to; ++k) {
      std::optional<Match> m;
      if (k % 2 == 0) {
        const TimeNs tm = f.t - 47 * kMs;
        Pose p = ArcPose(p0, 0.25, 0.0, 0.1, cosim::NsToSeconds(tm));
        p.x += 0.003 * std::sin(k);  // a little noise
        m = Match{p, tm};
      }
      f.Step(0.24, 0.01, 0.11, m);
    }
  };
  Fusion a(p0);
  run(a, 0, 60);
  const cosim::UnitState saved = a.u.SaveState();
  run(a, 60, 120);

  Fusion b({9.0, 9.0, 1.0});
  run(b, 0, 3);
  b.u.RestoreState(saved);
  b.t = 60 * kCycle;
  b.count = a.count - 30;
  run(b, 60, 120);
  EXPECT_TRUE(test_helpers::SameBits(test_helpers::Outputs(a.u), test_helpers::Outputs(b.u)));
}

// Parameter problems are named.
TEST(PoseFusionUnit, NamesParameterProblems) {
  PoseFusionUnit u("fusion");
  u.variables().SetString(*u.variables().Find("yaw_rate_source"), "gyro");
  SetAll(u, "gate", -1.0);
  std::vector<std::string> names;
  for (const auto& p : u.CheckParameters()) names.push_back(p.variable);
  for (const char* v : {"yaw_rate_source", "gate", "initial_x", "initial_y", "initial_yaw"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), v), names.end()) << v;
  }
  EXPECT_EQ(names.size(), 5u);
  EXPECT_THROW(u.Initialize(), cosim::UnitError);
}

}  // namespace
}  // namespace linesim::estimation
