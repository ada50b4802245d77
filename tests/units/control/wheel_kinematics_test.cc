#include "units/control/wheel_kinematics.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace linesim::control {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRadiusM = 0.08;  // Rob@Work 3 wheel (raw3-1 Platform.ini, docs/references.md)

double Deg(double d) { return d * kPi / 180.0; }

// Rob@Work 3 steering axes W1..W4 (raw3-1 Platform.ini, docs/references.md).
const std::array<Eigen::Vector2d, 4> kWheels = {
    Eigen::Vector2d(0.368, 0.186), Eigen::Vector2d(-0.368, 0.134), Eigen::Vector2d(-0.368, -0.186),
    Eigen::Vector2d(0.368, -0.134)};

// Guards against a wrap that leaves -pi (two names for one heading) or
// drifts multiples of 2 pi. Definition: result in (-pi, pi], same angle.
// control::WrapAngle is models::WrapAngle, which the chassis and the path
// follower use too, so this covers every unit's wrap.
TEST(WrapAngle, MapsIntoHalfOpenInterval) {
  EXPECT_EQ(WrapAngle(kPi), kPi);
  EXPECT_EQ(WrapAngle(-kPi), kPi);
  EXPECT_NEAR(WrapAngle(3 * kPi), kPi, 1e-15);
  EXPECT_NEAR(WrapAngle(Deg(190)), Deg(-170), 1e-15);
  EXPECT_NEAR(WrapAngle(Deg(-190)), Deg(170), 1e-15);
  EXPECT_NEAR(WrapAngle(Deg(725)), Deg(5), 1e-14);
  EXPECT_EQ(WrapAngle(0.25), 0.25);
}

// Guards against wrong signs in Eq. 1 (paper 1): a pure translation moves
// every contact alike.
TEST(WheelVelocity, PureTranslationIsTheSameForAllWheels) {
  const Eigen::Vector3d twist(0.3, -0.2, 0.0);
  for (const auto& p : kWheels) {
    const Eigen::Vector2d v = WheelVelocity(twist, p);
    EXPECT_EQ(v[0], 0.3);
    EXPECT_EQ(v[1], -0.2);
  }
}

// Guards against wrong signs in Eq. 1: a pure rotation (counter-clockwise,
// phidot > 0) moves each contact at phidot * |p| perpendicular to p, turned
// +90 deg from p (rigid body: v = omega z x p).
TEST(WheelVelocity, PureRotationIsTangentialWithSpeedProportionalToDistance) {
  const double phidot = 0.7;
  for (const auto& p : kWheels) {
    const Eigen::Vector2d v = WheelVelocity({0.0, 0.0, phidot}, p);
    EXPECT_NEAR(v.norm(), phidot * p.norm(), 1e-15);
    EXPECT_NEAR(v.dot(p), 0.0, 1e-15);
    EXPECT_NEAR(v[0], -phidot * p[1], 1e-15);
    EXPECT_NEAR(v[1], phidot * p[0], 1e-15);
  }
}

// Guards against a wrong sign or frame in Algorithm 1: the wheel must move
// relative to its floor, so a floor moving at +0.2 m/s under a robot that
// stands still needs -0.2 m/s from the wheel.
TEST(CompensateSurface, SubtractsTheSurfaceVelocity) {
  const Eigen::Vector2d v = CompensateSurface({0.1, 0.05}, {0.2, -0.1});
  EXPECT_NEAR(v[0], -0.1, 1e-16);
  EXPECT_NEAR(v[1], 0.15, 1e-16);
}

// Guards against the flip rule turning a wheel 180 deg for a command behind
// it instead of reversing the drive (IPA cob_control, docs/references.md).
TEST(ToWheelSetpoint, CommandBehindTheWheelReversesTheDrive) {
  const WheelSetpoint s = ToWheelSetpoint({-0.4, 0.0}, kRadiusM, 0.0, 0.0, 1e-3);
  EXPECT_NEAR(s.steer_angle_rad, 0.0, 1e-15);
  EXPECT_NEAR(s.drive_rate_rad_s, -0.4 / kRadiusM, 1e-12);
  // Ahead: forward at |v| / R on the heading atan2(v_y, v_x).
  const WheelSetpoint f = ToWheelSetpoint({0.3, 0.3}, kRadiusM, 0.0, 0.0, 1e-3);
  EXPECT_NEAR(f.steer_angle_rad, Deg(45), 1e-15);
  EXPECT_NEAR(f.drive_rate_rad_s, std::sqrt(0.18) / kRadiusM, 1e-12);
}

// Guards the invariant of the flip rule: a wheel that sits at its last
// target never gets a new heading more than 90 deg away, and the set point
// always reproduces the commanded contact velocity. Random commands and
// headings; the numbers are the rule's definition.
TEST(ToWheelSetpoint, NeverMoreThanNinetyDegreesAndReproducesTheVelocity) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> angle(-kPi, kPi), speed(-1.0, 1.0);
  for (int k = 0; k < 2000; ++k) {
    const double now = angle(rng);
    const Eigen::Vector2d v(speed(rng), speed(rng));
    if (v.norm() < 1e-3) continue;
    const WheelSetpoint s = ToWheelSetpoint(v, kRadiusM, now, now, 1e-3);
    EXPECT_LE(std::abs(WrapAngle(s.steer_angle_rad - now)), kPi / 2 + 1e-12);
    EXPECT_GT(s.steer_angle_rad, -kPi);
    EXPECT_LE(s.steer_angle_rad, kPi);
    const double rim = s.drive_rate_rad_s * kRadiusM;
    EXPECT_NEAR(rim * std::cos(s.steer_angle_rad), v[0], 1e-12);
    EXPECT_NEAR(rim * std::sin(s.steer_angle_rad), v[1], 1e-12);
  }
}

// Guards against a wheel re-aiming on noise: below the threshold the
// command's direction means nothing (atan2 of noise), so the wheel keeps its
// last target and rolls the command's component along it; zero stops it.
TEST(ToWheelSetpoint, SlowCommandKeepsTheLastTargetAndRollsItsComponent) {
  const double last = Deg(30);
  const WheelSetpoint zero = ToWheelSetpoint({0.0, 0.0}, kRadiusM, Deg(28), last, 1e-2);
  EXPECT_EQ(zero.steer_angle_rad, last);
  EXPECT_EQ(zero.drive_rate_rad_s, 0.0);
  // 5 mm/s at 120 deg, 90 deg off the heading: nothing to roll.
  const Eigen::Vector2d across(5e-3 * std::cos(Deg(120)), 5e-3 * std::sin(Deg(120)));
  const WheelSetpoint s = ToWheelSetpoint(across, kRadiusM, Deg(28), last, 1e-2);
  EXPECT_EQ(s.steer_angle_rad, last);
  EXPECT_NEAR(s.drive_rate_rad_s, 0.0, 1e-15);
  // 8 mm/s at 90 deg: rolls 8 cos(60 deg) = 4 mm/s along 30 deg.
  const WheelSetpoint half = ToWheelSetpoint({0.0, 8e-3}, kRadiusM, Deg(28), last, 1e-2);
  EXPECT_EQ(half.steer_angle_rad, last);
  EXPECT_NEAR(half.drive_rate_rad_s * kRadiusM, 4e-3, 1e-15);
  // Behind the heading it rolls backward, still without turning.
  const WheelSetpoint back = ToWheelSetpoint({-6e-3, 0.0}, kRadiusM, Deg(28), last, 1e-2);
  EXPECT_EQ(back.steer_angle_rad, last);
  EXPECT_NEAR(back.drive_rate_rad_s * kRadiusM, -6e-3 * std::cos(last), 1e-15);
  // At the threshold the heading follows the command again.
  const WheelSetpoint aimed = ToWheelSetpoint({0.0, 1e-2}, kRadiusM, 0.0, 0.0, 1e-2);
  EXPECT_NEAR(aimed.steer_angle_rad, Deg(90), 1e-15);
  EXPECT_NEAR(aimed.drive_rate_rad_s * kRadiusM, 1e-2, 1e-15);
}

// Guards against flip-flop near 90 deg. Cost 0.6 |a - now| + 0.4 |a - last|:
// - a wheel at 0 (now = last = 0) commanded to 91 deg: forward costs
//   91 deg, reverse (-89 deg) costs 89: it reverses;
// - a wheel that chose 89 deg forward and lags at 80 deg, commanded to
//   91 deg: forward costs 0.6*11 + 0.4*2 = 7.4 deg, reverse (-89) costs
//   0.6*169 + 0.4*178 = 172.6 deg: it keeps going forward, no flip.
TEST(ToWheelSetpoint, HysteresisNearNinetyDegrees) {
  const Eigen::Vector2d at91(std::cos(Deg(91)), std::sin(Deg(91)));
  const WheelSetpoint fresh = ToWheelSetpoint(0.2 * at91, kRadiusM, 0.0, 0.0, 1e-3);
  EXPECT_NEAR(fresh.steer_angle_rad, Deg(-89), 1e-12);
  EXPECT_LT(fresh.drive_rate_rad_s, 0.0);
  const WheelSetpoint lagging = ToWheelSetpoint(0.2 * at91, kRadiusM, Deg(80), Deg(89), 1e-3);
  EXPECT_NEAR(lagging.steer_angle_rad, Deg(91), 1e-12);
  EXPECT_GT(lagging.drive_rate_rad_s, 0.0);
  // The mirror case, across the +-180 deg seam: last target -179 deg
  // (forward), command at 179 deg: 2 deg away forward, no reversal.
  const Eigen::Vector2d at179(std::cos(Deg(179)), std::sin(Deg(179)));
  const WheelSetpoint seam = ToWheelSetpoint(0.2 * at179, kRadiusM, Deg(-179), Deg(-179), 1e-3);
  EXPECT_NEAR(seam.steer_angle_rad, Deg(179), 1e-12);
  EXPECT_GT(seam.drive_rate_rad_s, 0.0);
}

// Guards against Algorithm 1 acting on the wrong wheels or with the wrong
// sign (brief): standstill command, floor at (0.2, 0) m/s under W1 and W2
// only: those wheels roll at -0.2 m/s relative to it (heading kept at 0,
// drive reversed), the others stay at zero.
TEST(ToWheelSetpoint, AlgorithmOneOnlyMovesTheWheelsOnTheBelt) {
  const std::array<Eigen::Vector2d, 4> surface = {Eigen::Vector2d(0.2, 0), Eigen::Vector2d(0.2, 0),
                                                  Eigen::Vector2d(0, 0), Eigen::Vector2d(0, 0)};
  for (std::size_t i = 0; i < 4; ++i) {
    const Eigen::Vector2d v = CompensateSurface(WheelVelocity({0, 0, 0}, kWheels[i]), surface[i]);
    const WheelSetpoint s = ToWheelSetpoint(v, kRadiusM, 0.0, 0.0, 1e-3);
    EXPECT_NEAR(s.steer_angle_rad, 0.0, 1e-15);
    EXPECT_NEAR(s.drive_rate_rad_s * kRadiusM, i < 2 ? -0.2 : 0.0, 1e-15) << "wheel " << i;
  }
}

}  // namespace
}  // namespace linesim::control
