// The wheel_odometry unit (units/estimation/wheel_odometry_unit.h), driven
// by the real wheel_encoder unit's counts where the counts matter.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "config/unit_registry.h"
#include "config/yaml_reader.h"
#include "models/scene.h"
#include "tests/units/test_helpers.h"
#include "units/estimation/wheel_odometry_unit.h"
#include "units/sensors/wheel_encoder_unit.h"

namespace linesim::estimation {
namespace {

using cosim::TimeNs;
using test_helpers::Get;
using test_helpers::SetAll;
using test_helpers::SetArray;
using Kind = WheelOdometryUnit::Kind;

constexpr TimeNs kMs = 1'000'000;
constexpr TimeNs kCycle = 20 * kMs;  // the robots' 20 ms control cycle
constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Rob@Work 3 (models/robots/raw3.yaml: raw3-1 Platform.ini): steering axes
// and wheel radius; encoders 16384 (steering) and 86016 (drive) counts per
// joint revolution (the wheel_encoder tests' ASSUMPTION: 4096 counts per
// motor turn times the gears 4 and 21).
const std::vector<double> kRaw3X = {0.368, -0.368, -0.368, 0.368};
const std::vector<double> kRaw3Y = {0.186, 0.134, -0.186, -0.134};
constexpr double kRaw3Radius = 0.080;
constexpr double kSteerCpr = 4096.0 * 4.0;
constexpr double kDriveCpr = 4096.0 * 21.0;
// Husky A200 (models/robots/husky.yaml): wheels, radius, effective track;
// 78,000 ticks per metre (Clearpath user manual) = 80913.6 per wheel turn.
const std::vector<double> kHuskyX = {0.256, -0.256, 0.256, -0.256};
const std::vector<double> kHuskyY = {0.2854, 0.2854, -0.2854, -0.2854};
constexpr double kHuskyRadius = 0.1651;
constexpr double kHuskyTrack = 1.030;
const double kHuskyCpr = 78000.0 * kTwoPi * 0.1651;

std::unique_ptr<WheelOdometryUnit> Raw3Odometry(double yaw0 = 0.0, bool rectify = true) {
  auto u = std::make_unique<WheelOdometryUnit>("odo", Kind::kSwerve, 4);
  SetArray(*u, "wheel_x", kRaw3X);
  SetArray(*u, "wheel_y", kRaw3Y);
  SetAll(*u, "wheel_radius", kRaw3Radius);
  SetArray(
      *u, "counts_per_revolution",
      {kSteerCpr, kSteerCpr, kSteerCpr, kSteerCpr, kDriveCpr, kDriveCpr, kDriveCpr, kDriveCpr});
  SetAll(*u, "initial_x", 1.0);
  SetAll(*u, "initial_y", -2.0);
  SetAll(*u, "initial_yaw", yaw0);
  u->variables().SetBoolean(*u->variables().Find("rectify"), rectify);
  return u;
}

std::unique_ptr<WheelOdometryUnit> HuskyOdometry(bool rectify = true) {
  auto u = std::make_unique<WheelOdometryUnit>("odo", Kind::kDifferential, 4);
  SetArray(*u, "wheel_x", kHuskyX);
  SetArray(*u, "wheel_y", kHuskyY);
  SetAll(*u, "wheel_radius", kHuskyRadius);
  SetAll(*u, "counts_per_revolution", kHuskyCpr);
  SetAll(*u, "effective_track", kHuskyTrack);
  SetAll(*u, "initial_x", 0.0);
  SetAll(*u, "initial_y", 0.0);
  SetAll(*u, "initial_yaw", 0.0);
  u->variables().SetBoolean(*u->variables().Find("rectify"), rectify);
  return u;
}

/// The real encoder on the joints and the odometry reading it, sampled as
/// the master does: inputs, UpdateOutputs (feedthrough), then DoStep.
struct Rig {
  sensors::WheelEncoderUnit encoder;
  std::unique_ptr<WheelOdometryUnit> odometry;
  TimeNs t = 0;

  Rig(std::unique_ptr<WheelOdometryUnit> odo, const std::vector<double>& cpr)
      : encoder("enc", static_cast<int>(cpr.size())), odometry(std::move(odo)) {
    SetArray(encoder, "counts_per_revolution", cpr);
  }
  /// Starts both with the joints at `angle`.
  void Start(const std::vector<double>& angle) {
    SetArray(encoder, "angle", angle);
    encoder.Setup(0, 1000 * 1000 * kMs);
    encoder.Initialize();
    SetArray(*odometry, "counts", Get(encoder, "counts"));
    odometry->Setup(0, 1000 * 1000 * kMs);
    odometry->Initialize();
  }
  /// The next sample at t + kCycle with the joints at `angle`.
  void Step(const std::vector<double>& angle) {
    ASSERT_EQ(encoder.DoStep(t, kCycle), cosim::StepResult::kOk);
    ASSERT_EQ(odometry->DoStep(t, kCycle), cosim::StepResult::kOk);
    t += kCycle;
    SetArray(encoder, "angle", angle);
    encoder.UpdateOutputs();
    SetArray(*odometry, "counts", Get(encoder, "counts"));
    odometry->UpdateOutputs();
  }
};

std::vector<double> Raw3Cpr() {
  return {kSteerCpr, kSteerCpr, kSteerCpr, kSteerCpr, kDriveCpr, kDriveCpr, kDriveCpr, kDriveCpr};
}

TEST(WheelOdometryUnit, DeclaresItsVariables) {
  WheelOdometryUnit s("odo", Kind::kSwerve, 4);
  const std::vector<std::string> both = {"counts", "surface_velocity"};
  test_helpers::ExpectTable(s,
                            {{"wheel_x", cosim::Causality::kParameter, "m", 4},
                             {"wheel_y", cosim::Causality::kParameter, "m", 4},
                             {"wheel_radius", cosim::Causality::kParameter, "m", 0},
                             {"counts_per_revolution", cosim::Causality::kParameter, "1", 8},
                             {"rectify", cosim::Causality::kParameter, "", 0},
                             {"initial_x", cosim::Causality::kParameter, "m", 0},
                             {"initial_y", cosim::Causality::kParameter, "m", 0},
                             {"initial_yaw", cosim::Causality::kParameter, "rad", 0},
                             {"counts", cosim::Causality::kInput, "1", 8},
                             {"surface_velocity", cosim::Causality::kInput, "m/s", 8},
                             {"body_velocity", cosim::Causality::kOutput, "m/s", 2, both},
                             {"yaw_rate", cosim::Causality::kOutput, "rad/s", 0, both},
                             {"raw_body_velocity", cosim::Causality::kOutput, "m/s", 2, {"counts"}},
                             {"raw_yaw_rate", cosim::Causality::kOutput, "rad/s", 0, {"counts"}},
                             {"wheel_velocity", cosim::Causality::kOutput, "m/s", 8, {"counts"}},
                             {"position", cosim::Causality::kOutput, "m", 2, both},
                             {"yaw", cosim::Causality::kOutput, "rad", 0, both},
                             {"velocity", cosim::Causality::kOutput, "m/s", 2, both}});
  WheelOdometryUnit d("odo", Kind::kDifferential, 4);
  EXPECT_EQ(d.variables().info(*d.variables().Find("counts")).size, 2u);
  EXPECT_EQ(d.variables().info(*d.variables().Find("surface_velocity")).size, 8u);
  EXPECT_TRUE(d.variables().Find("effective_track"));
  EXPECT_FALSE(s.variables().Find("effective_track"));
}

// Guards the swerve kinematics, the joint conventions and the count
// arithmetic on a pure translation at (0.3, 0.2) m/s in base_link: every
// wheel heads atan2(0.2, 0.3) and rolls at |v| / r. Analytic bound from the
// quantization: the drive count difference is off by less than one count
// (each end is a floor), a speed error below r 2 pi / cpr_d / dt; the
// steering angle (middle of its count) is off by at most pi / cpr_s, a
// velocity error |v| pi / cpr_s across the wheel. The wheels' centroid is
// base_link's origin (sum x = sum y = 0), so the least squares reduce to
// vx = mean v_ix, vy = mean v_iy, omega = sum(x_i v_iy - y_i v_ix) /
// sum rho_i^2: |vx|, |vy| errors below e and |omega| error below
// sum rho_i e / sum rho_i^2.
//
// The heading, 33.7 deg, is put 0.9 of a steering count above an edge
// (1533.9 counts): the middle of the count is 0.4 count off, the count's
// floor would be 0.9 off. All wheels share that error, a rotation of every
// wheel velocity (no yaw: the centroid is the origin), so the direction of
// the dead-reckoned travel is off by at most pi / cpr_s plus the drive
// quantization (one count of each wheel over the distance, and the yaw it
// makes: the shared steering error turns no yaw, so only the drive counts
// do, sum rho q / sum rho^2 for one count q of travel).
TEST(WheelOdometryUnit, SwerveTranslationFromRealEncoderCounts) {
  const double heading = 1533.9 * kTwoPi / kSteerCpr, speed = 0.36;
  const double vx = speed * std::cos(heading), vy = speed * std::sin(heading);
  Rig rig(Raw3Odometry(0.5), Raw3Cpr());
  const auto angles = [&](double t_s) {
    const double roll = speed * t_s / kRaw3Radius;
    return std::vector<double>{heading, heading, heading, heading, roll, roll, roll, roll};
  };
  rig.Start(angles(0.0));
  const double dt = cosim::NsToSeconds(kCycle);
  const double e = kRaw3Radius * kTwoPi / kDriveCpr / dt + speed * std::numbers::pi / kSteerCpr;
  double sum_rho = 0.0, sum_rho2 = 0.0;
  for (std::size_t i = 0; i < 4; ++i) {
    sum_rho += std::hypot(kRaw3X[i], kRaw3Y[i]);
    sum_rho2 += kRaw3X[i] * kRaw3X[i] + kRaw3Y[i] * kRaw3Y[i];
  }
  const int steps = 150;  // 3 s, 1.08 m
  for (int k = 1; k <= steps; ++k) {
    rig.Step(angles(k * dt));
    const auto v = Get(*rig.odometry, "body_velocity");
    EXPECT_NEAR(v[0], vx, e) << k;
    EXPECT_NEAR(v[1], vy, e) << k;
    EXPECT_NEAR(Get(*rig.odometry, "yaw_rate")[0], 0.0, sum_rho * e / sum_rho2) << k;
    // Each wheel's own velocity (what the surface estimator's check reads):
    // the same translation, within the same one-wheel bound e.
    const auto wv = Get(*rig.odometry, "wheel_velocity");
    for (std::size_t i = 0; i < 4; ++i) {
      EXPECT_NEAR(wv[2 * i], vx, e) << k;
      EXPECT_NEAR(wv[2 * i + 1], vy, e) << k;
    }
  }
  // Dead reckoning: the count differences telescope, so each wheel's
  // travel is off by less than one drive count plus the steering error
  // across the distance D; the yaw by sum rho e_D / sum rho^2; the position
  // by e_D + D * that yaw bound. From (1, -2) at yaw 0.5.
  const double distance = speed * steps * dt;
  const double e_travel =
      kRaw3Radius * kTwoPi / kDriveCpr + distance * std::numbers::pi / kSteerCpr;
  const double e_yaw = sum_rho * e_travel / sum_rho2;
  const double c = std::cos(0.5), s = std::sin(0.5);
  const auto p = Get(*rig.odometry, "position");
  EXPECT_NEAR(Get(*rig.odometry, "yaw")[0], 0.5, e_yaw);
  EXPECT_NEAR(p[0], 1.0 + (c * vx - s * vy) * steps * dt, e_travel + distance * e_yaw);
  EXPECT_NEAR(p[1], -2.0 + (s * vx + c * vy) * steps * dt, e_travel + distance * e_yaw);
  const double travel_direction = std::atan2(p[1] + 2.0, p[0] - 1.0) - 0.5;
  const double drive_quantum = kRaw3Radius * kTwoPi / kDriveCpr;  // m of travel
  const double e_yaw_drive = sum_rho * drive_quantum / sum_rho2;
  EXPECT_NEAR(travel_direction, heading,
              std::numbers::pi / kSteerCpr + drive_quantum / distance + e_yaw_drive);
  const auto vm = Get(*rig.odometry, "velocity");
  EXPECT_NEAR(vm[0], c * vx - s * vy, 2 * e);
  EXPECT_NEAR(vm[1], s * vx + c * vy, 2 * e);
}

// Guards the rotation part: turning in place at 0.5 rad/s, wheel i heads
// along (-y_i, x_i), atan2(x_i, -y_i), and rolls at omega rho_i / r (paper
// 1 Eq. 1). Bounds as for the translation with e_i = r 2 pi / cpr_d / dt +
// omega rho_i pi / cpr_s per wheel. The yaw telescopes like the travel; the
// position (truly fixed) moves by at most T mean(e_i).
TEST(WheelOdometryUnit, SwerveRotationFromRealEncoderCounts) {
  const double omega = 0.5;
  Rig rig(Raw3Odometry(0.0), Raw3Cpr());
  const auto angles = [&](double t_s) {
    std::vector<double> a(8);
    for (std::size_t i = 0; i < 4; ++i) {
      a[i] = std::atan2(kRaw3X[i], -kRaw3Y[i]);
      a[4 + i] = omega * std::hypot(kRaw3X[i], kRaw3Y[i]) * t_s / kRaw3Radius;
    }
    return a;
  };
  rig.Start(angles(0.0));
  const double dt = cosim::NsToSeconds(kCycle);
  double sum_rho_e = 0.0, sum_rho2 = 0.0, mean_e = 0.0, sum_rho_travel = 0.0;
  const int steps = 100;  // 2 s, 1 rad
  const double t_end = steps * dt;
  for (std::size_t i = 0; i < 4; ++i) {
    const double rho = std::hypot(kRaw3X[i], kRaw3Y[i]);
    const double e =
        kRaw3Radius * kTwoPi / kDriveCpr / dt + omega * rho * std::numbers::pi / kSteerCpr;
    sum_rho_e += rho * e;
    sum_rho2 += rho * rho;
    mean_e += e / 4.0;
    sum_rho_travel += rho * (kRaw3Radius * kTwoPi / kDriveCpr +
                             omega * rho * t_end * std::numbers::pi / kSteerCpr);
  }
  for (int k = 1; k <= steps; ++k) {
    rig.Step(angles(k * dt));
    const auto v = Get(*rig.odometry, "body_velocity");
    EXPECT_NEAR(v[0], 0.0, mean_e) << k;
    EXPECT_NEAR(v[1], 0.0, mean_e) << k;
    EXPECT_NEAR(Get(*rig.odometry, "yaw_rate")[0], omega, sum_rho_e / sum_rho2) << k;
  }
  EXPECT_NEAR(Get(*rig.odometry, "yaw")[0], omega * t_end, sum_rho_travel / sum_rho2);
  const auto p = Get(*rig.odometry, "position");
  EXPECT_NEAR(p[0], 1.0, t_end * mean_e);
  EXPECT_NEAR(p[1], -2.0, t_end * mean_e);
}

// Guards the skid-steer law with the effective track: left 2 rad/s, right
// 4 rad/s on the Husky gives v = r (2 + 4) / 2 = 0.4953 m/s and omega =
// r (4 - 2) / 1.030 = 0.3206 rad/s (the law), each within one count per
// side per sample: q = r 2 pi / cpr / dt on v, 2 q / track on omega. The
// pose after T is the circle of that constant twist, x = v/w sin(wT),
// y = v/w (1 - cos(wT)); the yaw telescopes (2 counts / track), the
// position within T q + D * that yaw bound.
TEST(WheelOdometryUnit, SkidSteerUsesTheEffectiveTrack) {
  const double wl = 2.0, wr = 4.0;
  Rig rig(HuskyOdometry(), {kHuskyCpr, kHuskyCpr});
  rig.Start({0.0, 0.0});
  const double dt = cosim::NsToSeconds(kCycle);
  const double v = kHuskyRadius * (wl + wr) / 2.0, w = kHuskyRadius * (wr - wl) / kHuskyTrack;
  const double q = kHuskyRadius * kTwoPi / kHuskyCpr / dt;
  const int steps = 100;
  for (int k = 1; k <= steps; ++k) {
    rig.Step({wl * k * dt, wr * k * dt});
    EXPECT_NEAR(Get(*rig.odometry, "body_velocity")[0], v, q) << k;
    EXPECT_EQ(Get(*rig.odometry, "body_velocity")[1], 0.0) << k;
    EXPECT_NEAR(Get(*rig.odometry, "yaw_rate")[0], w, 2 * q / kHuskyTrack) << k;
  }
  const double t_end = steps * dt;
  const double e_yaw = 2.0 * kHuskyRadius * kTwoPi / kHuskyCpr / kHuskyTrack;
  EXPECT_NEAR(Get(*rig.odometry, "yaw")[0], w * t_end, e_yaw);
  const auto p = Get(*rig.odometry, "position");
  const double e_pos = t_end * q + v * t_end * e_yaw;
  EXPECT_NEAR(p[0], v / w * std::sin(w * t_end), e_pos);
  EXPECT_NEAR(p[1], v / w * (1.0 - std::cos(w * t_end)), e_pos);
}

// Paper 1 Eq. 3: a braked robot carried by the belt. The counts stay
// constant (the wheels do not turn relative to the body), the surface under
// every wheel moves with the belt, 0.1 m/s along map x (paper 1, Sec. V:
// the representative line speed), seen in base_link at the robot's yaw.
// The robot truly moves 0.1 m/s x T along x with its yaw unchanged; the
// rectified odometry integrates exactly that (the solve of identical wheel
// velocities is that velocity, with no rotation), the raw one nothing.
void ExpectCarriedByTheBelt(Kind kind) {
  const double yaw0 = 0.7, belt = 0.1;
  const double bx = std::cos(yaw0) * belt, by = -std::sin(yaw0) * belt;  // in base_link
  for (bool rectify : {true, false}) {
    std::unique_ptr<WheelOdometryUnit> u;
    if (kind == Kind::kSwerve) {
      u = Raw3Odometry(yaw0, rectify);
    } else {
      u = HuskyOdometry(rectify);
      SetAll(*u, "initial_x", 1.0);
      SetAll(*u, "initial_y", -2.0);
      SetAll(*u, "initial_yaw", yaw0);
    }
    const std::size_t channels = kind == Kind::kSwerve ? 8 : 2;
    SetArray(*u, "counts", std::vector<double>(channels, 1234.0));
    SetArray(*u, "surface_velocity", {bx, by, bx, by, bx, by, bx, by});
    u->Setup(0, 1000 * kMs * 1000);
    u->Initialize();
    TimeNs t = 0;
    for (int k = 0; k < 150; ++k) {  // 3 s
      ASSERT_EQ(u->DoStep(t, kCycle), cosim::StepResult::kOk);
      t += kCycle;
      u->UpdateOutputs();
    }
    const auto p = Get(*u, "position");
    const auto bv = Get(*u, "body_velocity");
    const auto raw = Get(*u, "raw_body_velocity");
    EXPECT_EQ(raw[0], 0.0);
    EXPECT_EQ(raw[1], 0.0);
    if (rectify) {
      EXPECT_NEAR(p[0], 1.0 + belt * 3.0, 1e-12);
      EXPECT_NEAR(p[1], -2.0, 1e-12);
      EXPECT_NEAR(bv[0], bx, 1e-15);
      EXPECT_NEAR(bv[1], by, 1e-15);
      EXPECT_NEAR(Get(*u, "velocity")[0], belt, 1e-15);
      EXPECT_NEAR(Get(*u, "yaw")[0], yaw0, 1e-12);
    } else {
      EXPECT_EQ(p[0], 1.0);
      EXPECT_EQ(p[1], -2.0);
      EXPECT_EQ(bv[0], 0.0);
    }
  }
}

TEST(WheelOdometryUnit, Eq3SwerveIntegratesTheBeltsTravelOnlyWhenRectified) {
  ExpectCarriedByTheBelt(Kind::kSwerve);
}

TEST(WheelOdometryUnit, Eq3DifferentialIntegratesTheBeltsTravelOnlyWhenRectified) {
  ExpectCarriedByTheBelt(Kind::kDifferential);
}

// Guards the per-side mean of the differential's rectification: the belt
// (0.1 m/s along x) under the left front wheel only adds half of it to the
// left side: vx = 0.05 / 2, omega = -0.05 / track (the law in the header).
TEST(WheelOdometryUnit, DifferentialRectifiesPerSideMean) {
  auto u = HuskyOdometry();
  SetArray(*u, "surface_velocity", {0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0});
  u->Setup(0, kMs * 1000);
  u->Initialize();
  EXPECT_DOUBLE_EQ(Get(*u, "body_velocity")[0], 0.025);
  EXPECT_DOUBLE_EQ(Get(*u, "yaw_rate")[0], -0.05 / kHuskyTrack);
  EXPECT_EQ(Get(*u, "raw_yaw_rate")[0], 0.0);
}

// Guards the use of the actual interval: a sample after a 30 ms step then
// one after 10 ms divide the same count difference by their own interval.
TEST(WheelOdometryUnit, RateUsesTheActualInterval) {
  auto u = HuskyOdometry();
  SetArray(*u, "counts", {0.0, 0.0});
  u->Setup(0, kMs * 1000);
  u->Initialize();
  ASSERT_EQ(u->DoStep(0, 30 * kMs), cosim::StepResult::kOk);
  SetArray(*u, "counts", {100.0, 100.0});
  u->UpdateOutputs();
  const double per_count = kHuskyRadius * kTwoPi / kHuskyCpr;
  EXPECT_DOUBLE_EQ(Get(*u, "body_velocity")[0], 100.0 * per_count / 0.030);
  ASSERT_EQ(u->DoStep(30 * kMs, 10 * kMs), cosim::StepResult::kOk);
  SetArray(*u, "counts", {200.0, 200.0});
  u->UpdateOutputs();
  EXPECT_DOUBLE_EQ(Get(*u, "body_velocity")[0], 100.0 * per_count / 0.010);
  EXPECT_NEAR(Get(*u, "position")[0], 200.0 * per_count, 1e-15);
}

// A restored unit continues bit for bit (save in the middle of a turn).
TEST(WheelOdometryUnit, RestoredUnitContinuesBitForBit) {
  const auto run = [](Rig& rig, int from, int to) {
    for (int k = from; k < to; ++k) {
      const double t = k * 0.02;
      rig.Step({0.3 + 0.1 * t, 0.3 + 0.1 * t, -0.2, 0.4, 10 * t, 11 * t, 9 * t + t * t, 10 * t});
      SetArray(*rig.odometry, "surface_velocity", {0.1, 0.0, 0.1, 0.0, 0.0, 0.0, 0.02 * t, 0.0});
      rig.odometry->UpdateOutputs();
    }
  };
  Rig a(Raw3Odometry(0.2), Raw3Cpr());
  a.Start({0.3, 0.3, -0.2, 0.4, 0, 0, 0, 0});
  run(a, 1, 50);
  const cosim::UnitState enc = a.encoder.SaveState();
  const cosim::UnitState odo = a.odometry->SaveState();
  run(a, 50, 100);

  Rig b(Raw3Odometry(0.0), Raw3Cpr());
  b.Start({0, 0, 0, 0, 0, 0, 0, 0});
  run(b, 1, 7);
  b.encoder.RestoreState(enc);
  b.odometry->RestoreState(odo);
  b.t = 49 * kCycle;
  run(b, 50, 100);
  EXPECT_TRUE(test_helpers::SameBits(test_helpers::Outputs(*a.odometry),
                                     test_helpers::Outputs(*b.odometry)));
}

// Parameter problems are named: unset robot-specific values, a
// differential wheel on the centre line, swerve wheels all at one point.
TEST(WheelOdometryUnit, NamesParameterProblems) {
  const auto names = [](const cosim::Unit& u) {
    std::vector<std::string> n;
    for (const auto& p : u.CheckParameters()) n.push_back(p.variable);
    return n;
  };
  WheelOdometryUnit bare("odo", Kind::kDifferential, 2);
  const auto n = names(bare);
  for (const char* v : {"wheel_x", "wheel_y", "wheel_radius", "counts_per_revolution",
                        "effective_track", "initial_x", "initial_y", "initial_yaw"}) {
    EXPECT_NE(std::find(n.begin(), n.end(), v), n.end()) << v;
  }
  EXPECT_THROW(bare.Initialize(), cosim::UnitError);

  auto d = HuskyOdometry();
  SetArray(*d, "wheel_y", {0.2854, 0.2854, 0.0, 0.1});
  const auto pd = d->CheckParameters();
  ASSERT_EQ(pd.size(), 2u);
  EXPECT_EQ(pd[0].variable, "wheel_y");
  EXPECT_EQ(pd[0].index, 2u);
  EXPECT_NE(pd[1].message.find("right"), std::string::npos) << pd[1].message;

  auto s = Raw3Odometry();
  SetAll(*s, "wheel_x", 0.1);
  SetAll(*s, "wheel_y", 0.1);
  const auto ps = s->CheckParameters();
  ASSERT_EQ(ps.size(), 1u);
  EXPECT_EQ(ps[0].variable, "wheel_x");
}

// The factory: structural keys shape the table; a bad kind or wheel count
// is reported at its key and builds nothing.
TEST(WheelOdometryFactory, ReadsAndChecksStructuralKeys) {
  const config::UnitType* type = config::FindUnitType("wheel_odometry");
  ASSERT_NE(type, nullptr);
  const models::Scene scene = models::OpenFloor();
  const auto make = [&](const std::string& params, std::vector<config::Issue>* issues) {
    config::YamlReader reader("scenario.yaml");
    auto u = type->create(
        {"odo", 1, reader, YAML::Load(params), "units.odo.parameters", scene, YAML::Node(), ""});
    *issues = reader.issues();
    return u;
  };
  std::vector<config::Issue> issues;
  auto d = make("{kind: differential, wheels: 4}", &issues);
  ASSERT_TRUE(d);
  EXPECT_EQ(d->variables().info(*d->variables().Find("counts")).size, 2u);
  auto s = make("{}", &issues);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->variables().info(*s->variables().Find("counts")).size, 8u);
  EXPECT_FALSE(make("{kind: tracked}", &issues));
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].key_path, "units.odo.parameters.kind");
  EXPECT_FALSE(make("{wheels: 1}", &issues));
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].key_path, "units.odo.parameters.wheels");
}

}  // namespace
}  // namespace linesim::estimation
