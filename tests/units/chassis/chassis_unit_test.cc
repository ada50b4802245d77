#include "units/chassis/chassis_unit.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>
#include <string>
#include <variant>
#include <vector>

#include "cosim/time.h"
#include "models/models_dir.h"
#include "models/moving_solids.h"
#include "tests/units/chassis/robots.h"
#include "tests/units/test_helpers.h"
#include "units/chassis/floor_world.h"

namespace linesim::chassis {
namespace {

using cosim::TimeNs;
using test_helpers::Get;
using test_helpers::Outputs;
using test_helpers::SameBits;
using test_helpers::SetArray;

constexpr TimeNs kMs = 1'000'000;
constexpr double kPi = std::numbers::pi;

// Rob@Work 3 numbers the expectations are computed from (sources in
// tests/units/chassis/robots.h).
using namespace test_robots;  // NOLINT: the robots' numbers and builders
constexpr double kMassKg = kRaw3MassKg;
constexpr double kModuleMassKg = kRaw3ModuleMassKg;
constexpr double kWheelRadiusM = kRaw3WheelRadiusM;
constexpr double kDriveRotorKgm2 = kRaw3DriveRotorKgm2;
constexpr double kSteerRotorKgm2 = kRaw3SteerRotorKgm2;
constexpr const double* kWheelXM = kRaw3WheelXM;
constexpr const double* kWheelYM = kRaw3WheelYM;

// ---------------------------------------------------------------------------
// Access through the variable table, as the master does.

void Set(ChassisUnit& u, const std::string& name, const cosim::Value& v) {
  u.variables().SetValue(*u.variables().Find(name), v);
}

void SetBrake(ChassisUnit& u, bool on) {
  u.variables().SetBoolean(*u.variables().Find("brake"), on);
}

// A Rob@Work 3 on one big square belt patch centred at (cx, cy).
std::unique_ptr<ChassisUnit> Raw3OnBelt(double cx_m, double cy_m, double size_m, double dir_rad) {
  return Raw3(test_robots::OneBelt({cx_m, cy_m, size_m, size_m, dir_rad}));
}

// A far belt (20 x 3 m along map x, centred 2.5 m to the left of the
// origin): a scene with one belt input that the robot does not touch.
std::unique_ptr<ChassisUnit> Raw3FarBelt() {
  return Raw3(test_robots::OneBelt({0.0, 2.5, 20.0, 3.0, 0.0}));
}

void Advance(ChassisUnit& u, TimeNs& t, int steps, TimeNs dt = kMs) {
  for (int i = 0; i < steps; ++i, t += dt) {
    ASSERT_EQ(u.DoStep(t, dt), cosim::StepResult::kOk) << u.last_error();
  }
}

// ---------------------------------------------------------------------------
// Guards against the robot creeping at rest (ODE vehicles can drift at rest
// on a plane) and against an Initialize that does not leave it at rest. Expected: nothing moves; 1
// mm over 5 s is the brief's bound.
TEST(ChassisUnit, RestsOnTheFloorWithoutDrift) {
  auto robot = Raw3();
  ChassisUnit& u = *robot;
  u.Initialize();
  for (double v : Get(u, "linear_velocity")) EXPECT_EQ(v, 0.0);
  EXPECT_EQ(Get(u, "yaw_rate")[0], 0.0);
  const auto p0 = Get(u, "position");
  const double yaw0 = Get(u, "yaw")[0];
  TimeNs t = 0;
  Advance(u, t, 5000);
  const auto p = Get(u, "position");
  EXPECT_LT(std::hypot(p[0] - p0[0], p[1] - p0[1]), 1e-3);
  EXPECT_LT(std::abs(Get(u, "yaw")[0] - yaw0), 1e-4);
  for (double v : Get(u, "linear_velocity")) EXPECT_LT(std::abs(v), 1e-6);
  EXPECT_LT(std::abs(Get(u, "yaw_rate")[0]), 1e-6);
  for (double a : Get(u, "steer_angle")) EXPECT_LT(std::abs(a), 1e-6);
  for (double w : Get(u, "drive_rate")) EXPECT_LT(std::abs(w), 1e-6);
}

// Guards against Initialize leaving the robot off its initial pose, and
// against wrong frames in the wheel outputs. Expected by geometry: wheel k
// in map = initial position + Rz(yaw) (wheel_x, wheel_y).
TEST(ChassisUnit, InitializePlacesRobotAtInitialPose) {
  auto robot = Raw3FarBelt();  // the belt is far away (y 1 to 4 m)
  ChassisUnit& u = *robot;
  const double x0 = -1.5, y0 = -2.0, yaw0 = 2.5;
  Set(u, "initial_x", x0);
  Set(u, "initial_y", y0);
  Set(u, "initial_yaw", yaw0);
  u.Initialize();
  const auto p = Get(u, "position");
  EXPECT_NEAR(p[0], x0, 1e-12);
  EXPECT_NEAR(p[1], y0, 1e-12);
  EXPECT_NEAR(Get(u, "yaw")[0], yaw0, 1e-12);
  const auto contact = Get(u, "wheel_contact");
  const auto surface = Get(u, "wheel_surface");
  for (int k = 0; k < 4; ++k) {
    const double x = x0 + std::cos(yaw0) * kWheelXM[k] - std::sin(yaw0) * kWheelYM[k];
    const double y = y0 + std::sin(yaw0) * kWheelXM[k] + std::cos(yaw0) * kWheelYM[k];
    EXPECT_NEAR(contact[2 * k], x, 1e-6) << k;
    EXPECT_NEAR(contact[2 * k + 1], y, 1e-6) << k;
    EXPECT_EQ(surface[k], 0.0) << k;
    EXPECT_NEAR(Get(u, "steer_angle")[k], 0.0, 1e-9) << k;
  }
}

// Guards against a wrong belt drag on the robot (direction, frame of the
// surface-velocity output) for belts that are not along map x. Expected:
// a braked robot wholly on a belt sticks to it, so it ends moving with the
// belt velocity and does not turn (a rigid body carried by its support).
TEST(ChassisUnit, BrakedRobotOnBeltMovesWithIt) {
  for (const double dir_rad : {0.0, 2.0}) {
    SCOPED_TRACE(dir_rad);
    auto robot = Raw3OnBelt(0.0, 0.0, 40.0, dir_rad);
    ChassisUnit& u = *robot;
    const double yaw0 = 0.7;
    Set(u, "initial_yaw", yaw0);
    SetBrake(u, true);
    u.Initialize();
    const double vx = 0.2 * std::cos(dir_rad), vy = 0.2 * std::sin(dir_rad);
    SetArray(u, "belt_velocity", {vx, vy});
    TimeNs t = 0;
    Advance(u, t, 500);
    const auto v = Get(u, "linear_velocity");
    EXPECT_NEAR(v[0], vx, 1e-4);
    EXPECT_NEAR(v[1], vy, 1e-4);
    EXPECT_NEAR(Get(u, "yaw_rate")[0], 0.0, 1e-4);
    EXPECT_NEAR(Get(u, "yaw")[0], yaw0, 1e-3);
    // In base_link: the map velocity turned by -yaw.
    const double yaw = Get(u, "yaw")[0];
    const double bx = std::cos(yaw) * vx + std::sin(yaw) * vy;
    const double by = -std::sin(yaw) * vx + std::cos(yaw) * vy;
    const auto bv = Get(u, "body_linear_velocity");
    EXPECT_NEAR(bv[0], bx, 1e-4);
    EXPECT_NEAR(bv[1], by, 1e-4);
    const auto sv = Get(u, "wheel_surface_velocity");
    const auto surface = Get(u, "wheel_surface");
    for (int k = 0; k < 4; ++k) {
      EXPECT_EQ(surface[k], 1.0) << k;
      EXPECT_NEAR(sv[2 * k], bx, 1e-12) << k;
      EXPECT_NEAR(sv[2 * k + 1], by, 1e-12) << k;
    }
  }
}

// Quasi-static reference for a braked rigid robot sliding on Coulomb
// contacts of equal load (the four loads of a rigid body on equally stiff
// contacts with its centre of mass at the origin are equal for the
// Rob@Work layout: sum x_i = sum y_i = 0). In steady sliding the friction
// forces -mu N s_i / |s_i| balance in force and moment, which is the
// stationary point of the convex sum_i |s_i(V, omega)|, with the slip
// s_i = V + omega z x p_i - u_i over the surface velocity u_i. Minimised by
// iteratively reweighted least squares. Returns (Vx, Vy, omega) in the
// wheel coordinates' frame.
Eigen::Vector3d CoulombSlidingTwist(const std::vector<Eigen::Vector2d>& p,
                                    const std::vector<Eigen::Vector2d>& u) {
  Eigen::Vector3d z = Eigen::Vector3d::Zero();
  for (int it = 0; it < 500; ++it) {
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < p.size(); ++i) {
      Eigen::Matrix<double, 2, 3> a;
      a << 1.0, 0.0, -p[i].y(), 0.0, 1.0, p[i].x();
      const double w = 1.0 / std::max((a * z - u[i]).norm(), 1e-12);
      h += w * a.transpose() * a;
      g += w * a.transpose() * u[i];
    }
    z = h.ldlt().solve(g);
  }
  return z;
}

// Braked robot with the front wheels (x = +0.368) on a belt that covers
// x > 0 in a frame turned by `turn_rad` from map and runs along that
// frame's +y at 0.2 m/s; the robot is turned by the same angle. Returns
// body_linear_velocity, yaw_rate and the yaw turned after 0.2 s (a few
// friction time constants).
std::vector<double> StraddleBodyVelocity(double turn_rad, std::vector<double>* surfaces_start,
                                         std::vector<double>* surfaces_end,
                                         std::vector<double>* surface_velocity) {
  auto robot =
      Raw3OnBelt(20.0 * std::cos(turn_rad), 20.0 * std::sin(turn_rad), 40.0, turn_rad + kPi / 2.0);
  ChassisUnit& u = *robot;
  Set(u, "initial_yaw", turn_rad);
  SetBrake(u, true);
  u.Initialize();
  *surfaces_start = Get(u, "wheel_surface");
  SetArray(u, "belt_velocity", {-0.2 * std::sin(turn_rad), 0.2 * std::cos(turn_rad)});
  TimeNs t = 0;
  Advance(u, t, 200);
  *surfaces_end = Get(u, "wheel_surface");
  *surface_velocity = Get(u, "wheel_surface_velocity");
  auto v = Get(u, "body_linear_velocity");
  v.push_back(Get(u, "yaw_rate")[0]);
  v.push_back(Get(u, "yaw")[0] - turn_rad);
  return v;
}

// Guards against the straddle case being wrong: per-wheel surfaces must be
// reported and the robot must turn as a Coulomb-friction body does, the
// same whatever the scene's orientation in map (ODE's friction pyramid
// would make it depend on it; floor_world.h). Expected: the quasi-static
// Coulomb balance above gives omega = 0.229 rad/s (13.1 deg/s,
// counter-clockwise: the belt pushes the front to the left) and V = (0,
// 0.1) m/s. A pure pivot about the rear wheels would give
// 0.2 / 0.736 = 0.272 rad/s.
TEST(ChassisUnit, BrakedRobotStraddlingBeltEdgeTurns) {
  const double belt_mps = 0.2;
  std::vector<Eigen::Vector2d> p, u;
  for (int k = 0; k < 4; ++k) {
    p.emplace_back(kWheelXM[k], kWheelYM[k]);
    u.emplace_back(0.0, kWheelXM[k] > 0.0 ? belt_mps : 0.0);
  }
  const Eigen::Vector3d ref = CoulombSlidingTwist(p, u);
  EXPECT_NEAR(ref.z(), 0.229, 0.001);  // guards the reference itself

  std::vector<double> start, end, sv;
  const auto v = StraddleBodyVelocity(0.0, &start, &end, &sv);
  EXPECT_EQ(start, (std::vector<double>{1.0, 0.0, 0.0, 1.0}));
  EXPECT_EQ(end, (std::vector<double>{1.0, 0.0, 0.0, 1.0}));
  EXPECT_NEAR(v[2], ref.z(), 0.02 * ref.z());
  EXPECT_GT(v[3], 0.0);  // yaw grew
  // The reference twist is in the start frame; base_link has turned by yaw.
  const double yaw = v[3];
  EXPECT_NEAR(v[0], std::cos(yaw) * ref.x() + std::sin(yaw) * ref.y(), 0.01 * belt_mps);
  EXPECT_NEAR(v[1], -std::sin(yaw) * ref.x() + std::cos(yaw) * ref.y(), 0.01 * belt_mps);
  // Belt wheels see the belt velocity in base_link, floor wheels zero.
  for (int k : {0, 3}) {
    EXPECT_NEAR(sv[2 * k], std::sin(yaw) * belt_mps, 1e-12);
    EXPECT_NEAR(sv[2 * k + 1], std::cos(yaw) * belt_mps, 1e-12);
  }
  for (int k : {1, 2}) {
    EXPECT_EQ(sv[2 * k], 0.0);
    EXPECT_EQ(sv[2 * k + 1], 0.0);
  }

  // The same scene turned in map: the same motion relative to the robot.
  for (const double turn_rad : {0.3, kPi / 4.0, -2.0}) {
    SCOPED_TRACE(turn_rad);
    const auto w = StraddleBodyVelocity(turn_rad, &start, &end, &sv);
    EXPECT_EQ(start, (std::vector<double>{1.0, 0.0, 0.0, 1.0}));
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(w[i], v[i], 1e-3 * belt_mps) << i;
  }
}

// Guards the motors' torque-speed lines as implicit joint rows: each drive
// motor gives tau = c (r0 - r) (drive_torque 0 at drive_torque_rate r0,
// slope -c), a steep line for the wheel's inertia: h c / J_axle = 9.7 at a
// 5 ms step (J_axle = m_mod r^2 / 2 + J_drive = 0.0207 kg.m^2), beyond
// explicit Euler's bound of 2, where the same torque applied as given over
// the step diverges. The wheels settle at r0, the robot at r0 times the
// rolling radius (nothing resists on a level floor), and a negative r0
// drives backwards.
TEST(ChassisUnit, TorqueSpeedLinesAreAppliedImplicitly) {
  const double c = 40.0;
  for (const double r0 : {3.0, -2.0}) {
    SCOPED_TRACE(r0);
    auto robot = Raw3();
    ChassisUnit& u = *robot;
    Set(u, "drive_friction", 0.0);
    u.Initialize();
    SetArray(u, "drive_torque", {0.0, 0.0, 0.0, 0.0});
    SetArray(u, "drive_torque_slope", {-c, -c, -c, -c});
    SetArray(u, "drive_torque_rate", {r0, r0, r0, r0});
    TimeNs t = 0;
    Advance(u, t, 400, 5 * kMs);
    for (double w : Get(u, "drive_rate")) EXPECT_NEAR(w, r0, 1e-3 * std::abs(r0));
    EXPECT_NEAR(Get(u, "body_linear_velocity")[0], r0 * kWheelRadiusM,
                2e-3 * std::abs(r0) * kWheelRadiusM);
    EXPECT_NEAR(Get(u, "yaw_rate")[0], 0.0, 1e-3);
  }
}

// Guards against wrong drive torque signs, a missing reflected rotor
// inertia, wrong body/map frames, a wrong drive_rate and a tread without
// creep. Analytic: four wheels at heading 0 each pushed by tau / r:
//   a = 4 tau / r / (M + 4 J_axle / r^2),  J_axle = m_mod r^2 / 2 + J_drive,
// and drive_rate = v (1 + kappa) / r: the brush tyre's longitudinal creep
// kappa = F / C_kappa under the traction F = M a / 4 each, C_kappa = c N,
// N = M g / 4 (equal loads): kappa = a / (c g).
TEST(ChassisUnit, EqualDriveTorquesAccelerateForward) {
  const double tau_nm = 2.0, yaw0 = 0.5;
  const double r = kWheelRadiusM;
  const double j_axle = 0.5 * kModuleMassKg * r * r + kDriveRotorKgm2;
  const double a = 4.0 * tau_nm / r / (kMassKg + 4.0 * j_axle / (r * r));
  for (const std::int64_t substeps : {1, 4}) {
    SCOPED_TRACE(substeps);
    auto robot = Raw3();
    ChassisUnit& u = *robot;
    Set(u, "drive_friction", 0.0);
    Set(u, "initial_yaw", yaw0);
    Set(u, "substeps", substeps);
    u.Initialize();
    SetArray(u, "drive_torque", {tau_nm, tau_nm, tau_nm, tau_nm});
    TimeNs t = 0;
    Advance(u, t, 1000);
    const double t_s = 1.0;
    const auto bv = Get(u, "body_linear_velocity");
    EXPECT_NEAR(bv[0], a * t_s, 0.005 * a * t_s);
    EXPECT_NEAR(bv[1], 0.0, 1e-3);
    EXPECT_NEAR(Get(u, "yaw_rate")[0], 0.0, 1e-3);
    const auto v = Get(u, "linear_velocity");
    EXPECT_NEAR(v[0], std::cos(yaw0) * bv[0], 1e-3);
    EXPECT_NEAR(v[1], std::sin(yaw0) * bv[0], 1e-3);
    const auto p = Get(u, "position");
    const double s_m = 0.5 * a * t_s * t_s;
    EXPECT_NEAR(std::hypot(p[0], p[1]), s_m, 0.01 * s_m);
    EXPECT_NEAR(std::atan2(p[1], p[0]), yaw0, 1e-2);
    // The traction is the body's share M a / 4 (the modules' own inertia
    // is driven through the joints, not the tread).
    const double body_a = 4.0 * (tau_nm / r - j_axle / r / r * a) / kMassKg;
    const double kappa = body_a / (kRaw3Tread.slip_stiffness * kGravityMps2);
    for (double w : Get(u, "drive_rate")) {
      EXPECT_NEAR(w, bv[0] * (1.0 + kappa) / r, 2e-3 * bv[0] / r);
    }
  }
  // Negative torques drive backwards.
  auto robot = Raw3();
  ChassisUnit& u = *robot;
  u.Initialize();
  SetArray(u, "drive_torque", {-tau_nm, -tau_nm, -tau_nm, -tau_nm});
  TimeNs t = 0;
  Advance(u, t, 200);
  EXPECT_LT(Get(u, "body_linear_velocity")[0], 0.0);
  for (double w : Get(u, "drive_rate")) EXPECT_LT(w, 0.0);
}

// Guards against wrong frames in the 3D outputs the sensors use and against
// a drive_angle that is not the integral of drive_rate. Expected by
// definition: at rest base_link's origin is on the floor (z within the
// contact deflection, 0.3 mm at 1e6 N/m) at the initial pose and the
// attitude is the yaw quaternion (cos(yaw/2), 0, 0, sin(yaw/2)); under equal
// drive torques the body accelerates at a (as in the test above), so after
// t the wheels have turned a t^2 / (2 r) and velocity_3d is the planar
// velocity; angular_velocity is zero when driving straight.
TEST(ChassisUnit, PoseTwistAndWheelAnglesIn3D) {
  const double tau_nm = 2.0, yaw0 = 0.5;
  const double r = kWheelRadiusM;
  const double j_axle = 0.5 * kModuleMassKg * r * r + kDriveRotorKgm2;
  const double a = 4.0 * tau_nm / r / (kMassKg + 4.0 * j_axle / (r * r));
  auto robot = Raw3();
  ChassisUnit& u = *robot;
  Set(u, "drive_friction", 0.0);
  Set(u, "initial_x", 1.0);
  Set(u, "initial_y", -2.0);
  Set(u, "initial_yaw", yaw0);
  u.Initialize();
  auto p = Get(u, "position_3d");
  EXPECT_NEAR(p[0], 1.0, 1e-9);
  EXPECT_NEAR(p[1], -2.0, 1e-9);
  EXPECT_NEAR(p[2], 0.0, 5e-4);
  const auto q = Get(u, "orientation");
  EXPECT_NEAR(q[0], std::cos(yaw0 / 2), 1e-6);
  EXPECT_NEAR(q[1], 0.0, 1e-6);
  EXPECT_NEAR(q[2], 0.0, 1e-6);
  EXPECT_NEAR(q[3], std::sin(yaw0 / 2), 1e-6);
  for (double d : Get(u, "drive_angle")) EXPECT_EQ(d, 0.0);

  SetArray(u, "drive_torque", {tau_nm, tau_nm, tau_nm, tau_nm});
  TimeNs t = 0;
  Advance(u, t, 1000);
  const double t_s = 1.0;
  for (double d : Get(u, "drive_angle")) EXPECT_NEAR(d, 0.5 * a * t_s * t_s / r, 0.01 * d);
  const auto v = Get(u, "velocity_3d");
  const auto v2 = Get(u, "linear_velocity");
  EXPECT_NEAR(v[0], v2[0], 1e-3);
  EXPECT_NEAR(v[1], v2[1], 1e-3);
  EXPECT_NEAR(v[2], 0.0, 1e-3);
  for (double w : Get(u, "angular_velocity")) EXPECT_NEAR(w, 0.0, 1e-3);
  p = Get(u, "position_3d");
  const auto p2 = Get(u, "position");
  EXPECT_NEAR(p[0], p2[0], 1e-3);
  EXPECT_NEAR(p[1], p2[1], 1e-3);
  // Initialize again: the wheel angles start from zero.
  u.Initialize();
  for (double d : Get(u, "drive_angle")) EXPECT_EQ(d, 0.0);
}

// Guards against a body box that follows the centre of mass instead of
// standing where the robot's data put it (issue 35: the Rob@Work 3's box,
// centred on its 0.13 m centre of mass, spanned -0.07 to 0.33 m, so a
// scan plane at 0.35 m passed over it). Expected by geometry: at rest on
// the flat floor body_box is base_link's pose with the body's planform and
// its heights body_bottom and body_bottom + body_height above base_link
// (the AABB of a level yawed box spans exactly its own heights; the
// settled roll and pitch, below 1e-4 rad, move them by less than 0.1 mm),
// whatever com_height and a payload do to the centre of mass.
TEST(ChassisUnit, BodyBoxIsWhereTheBodyIsNotWhereItsMassIs) {
  using models::MovingBox;
  const auto check = [](ChassisUnit& u, double bottom_m, double height_m, double length_m,
                        double width_m) {
    u.Initialize();
    const auto box = Get(u, "body_box");
    const auto p = Get(u, "position_3d");
    ASSERT_EQ(box.size(), MovingBox::kValues);
    EXPECT_EQ(box[MovingBox::kX], p[0]);
    EXPECT_EQ(box[MovingBox::kY], p[1]);
    EXPECT_EQ(box[MovingBox::kYaw], Get(u, "yaw")[0]);
    EXPECT_EQ(box[MovingBox::kLength], length_m);
    EXPECT_EQ(box[MovingBox::kWidth], width_m);
    EXPECT_NEAR(box[MovingBox::kZBottom] - p[2], bottom_m, 1e-4);
    EXPECT_NEAR(box[MovingBox::kZTop] - p[2], bottom_m + height_m, 1e-4);
  };
  for (const double com_m : {kRaw3ComHeightM, 0.30}) {
    SCOPED_TRACE(com_m);
    auto robot = Raw3();
    Set(*robot, "initial_x", 1.0);
    Set(*robot, "initial_y", -2.0);
    Set(*robot, "initial_yaw", 0.5);
    Set(*robot, "com_height", com_m);
    check(*robot, kRaw3BodyBottomM, kRaw3BodyM[2], kRaw3BodyM[0], kRaw3BodyM[1]);
  }
  // The Husky's box, 0.1323 to 0.3798 m, also with paper 2's arm raising
  // the joint centre of mass to 0.43 m, above the box.
  auto husky = test_robots::Husky(models::OpenFloor());
  check(*husky, kHuskyBodyBottomM, kHuskyBodyM[2], kHuskyBodyM[0], kHuskyBodyM[1]);
  auto armed = test_robots::HuskyWithArm(models::OpenFloor());
  check(*armed, kHuskyBodyBottomM, kHuskyBodyM[2], kHuskyBodyM[0], kHuskyBodyM[1]);

  // Moving, the box moves with base_link.
  auto robot = Raw3();
  ChassisUnit& u = *robot;
  u.Initialize();
  SetArray(u, "drive_torque", {2.0, 2.0, 2.0, 2.0});
  TimeNs t = 0;
  Advance(u, t, 500);
  const auto box = Get(u, "body_box");
  const auto v = Get(u, "velocity_3d");
  EXPECT_GT(v[0], 0.1);
  EXPECT_EQ(box[MovingBox::kVx], v[0]);
  EXPECT_EQ(box[MovingBox::kVy], v[1]);
  EXPECT_EQ(box[MovingBox::kYawRate], Get(u, "yaw_rate")[0]);
  EXPECT_NEAR(box[MovingBox::kZBottom] - Get(u, "position_3d")[2], kRaw3BodyBottomM, 1e-3);
}

// Guards against the solid's placement leaking into the dynamics: the mass
// is where com_height puts it and has the inertia of a box of the body's
// size about it, wherever body_bottom puts the box. On an open floor
// (nothing for the box to meet) two robots whose boxes stand at different
// heights drive the same path bit for bit.
TEST(ChassisUnit, BodyBottomMovesTheSolidNotTheMass) {
  std::vector<double> runs[2];
  for (int k = 0; k < 2; ++k) {
    auto robot = Raw3();
    ChassisUnit& u = *robot;
    Set(u, "body_bottom", k == 0 ? kRaw3BodyBottomM : 0.0);
    u.Initialize();
    SetArray(u, "drive_torque", {2.0, 1.0, 2.0, 1.0});
    SetArray(u, "steer_torque", {0.1, 0.1, -0.1, -0.1});
    TimeNs t = 0;
    Advance(u, t, 400);
    for (const char* name : {"position_3d", "orientation", "velocity_3d", "angular_velocity"}) {
      for (const double x : Get(u, name)) runs[k].push_back(x);
    }
  }
  EXPECT_TRUE(SameBits(runs[0], runs[1]));
}

// Guards against a wrong steering torque sign or module inertia. Analytic:
// the sphere wheel has one contact on the steering axis, so nothing resists
// steering but the module's inertia about the vertical,
// I = m_mod r^2 / 4 + J_steer (thin disc plus reflected rotor): the angle
// after t is tau t^2 / (2 I) and the rate tau t / I.
TEST(ChassisUnit, SteerTorqueTurnsWheelCounterClockwise) {
  auto robot = Raw3();
  ChassisUnit& u = *robot;
  Set(u, "steer_friction", 0.0);
  u.Initialize();
  const double tau_nm = 0.05;
  const double inertia = 0.25 * kModuleMassKg * kWheelRadiusM * kWheelRadiusM + kSteerRotorKgm2;
  SetArray(u, "steer_torque", {tau_nm, 0.0, 0.0, -tau_nm});
  TimeNs t = 0;
  Advance(u, t, 100);
  const double t_s = 0.1;
  const auto angle = Get(u, "steer_angle");
  const auto rate = Get(u, "steer_rate");
  EXPECT_NEAR(angle[0], tau_nm * t_s * t_s / (2.0 * inertia), 0.02 * angle[0]);
  EXPECT_NEAR(rate[0], tau_nm * t_s / inertia, 0.02 * rate[0]);
  EXPECT_NEAR(angle[3], -angle[0], 1e-3 * angle[0]);
  EXPECT_NEAR(angle[1], 0.0, 1e-6);
  EXPECT_NEAR(angle[2], 0.0, 1e-6);
}

// Guards against a steer angle that is not wrapped or loses its sign past
// 90 deg: a wheel driven round by a constant torque passes pi and comes
// back in (-pi, pi].
TEST(ChassisUnit, SteerAngleWrapsToHalfOpenInterval) {
  auto robot = Raw3();
  ChassisUnit& u = *robot;
  Set(u, "steer_friction", 0.0);
  u.Initialize();
  SetArray(u, "steer_torque", {0.2, 0.0, 0.0, 0.0});
  TimeNs t = 0;
  double previous = 0.0;
  bool wrapped = false;
  for (int i = 0; i < 800; ++i, t += kMs) {
    ASSERT_EQ(u.DoStep(t, kMs), cosim::StepResult::kOk);
    const double a = Get(u, "steer_angle")[0];
    EXPECT_GT(a, -kPi);
    EXPECT_LE(a, kPi);
    if (a < previous) wrapped = true;
    previous = a;
  }
  // 0.2 N.m for 0.8 s on 8.2e-3 kg.m^2 turns it by 7.8 rad.
  EXPECT_TRUE(wrapped);
}

// Guards against a brake that does not hold: a braked robot on the floor
// with drive torques below the brake torque does not move.
TEST(ChassisUnit, BrakeHoldsAgainstDriveTorque) {
  auto robot = Raw3();
  ChassisUnit& u = *robot;
  SetBrake(u, true);
  u.Initialize();
  SetArray(u, "drive_torque", {5.0, 5.0, 5.0, 5.0});
  TimeNs t = 0;
  Advance(u, t, 500);
  EXPECT_LT(std::abs(Get(u, "position")[0]), 1e-5);
  for (double w : Get(u, "drive_rate")) EXPECT_LT(std::abs(w), 1e-4);
}

// ---------------------------------------------------------------------------
// Save/restore and idempotence, compared bit for bit.

// Straddling a running belt with torques that change every step.
std::vector<std::vector<double>> Drive(ChassisUnit& u, int from, int to) {
  std::vector<std::vector<double>> out;
  for (int k = from; k < to; ++k) {
    const double s = std::sin(0.1 * k);
    SetArray(u, "drive_torque", {2.0 + s, 2.0 - s, 1.0, 1.5});
    SetArray(u, "steer_torque", {0.02 * s, -0.01, 0.0, 0.01 * s});
    SetArray(u, "belt_velocity", {0.0, 0.2});
    EXPECT_EQ(u.DoStep(k * kMs, kMs), cosim::StepResult::kOk) << u.last_error();
    out.push_back(Outputs(u));
  }
  return out;
}

std::unique_ptr<ChassisUnit> Straddle() { return Raw3OnBelt(20.0, 0.0, 40.0, kPi / 2.0); }

// Guards against hidden state that a restore misses (renormalised
// quaternions, joint settings, contact data): a restored unit, and a fresh
// unit restored from the same state, continue exactly like the original.
TEST(ChassisUnit, SaveRestoreIsBitForBit) {
  auto robot = Straddle();
  ChassisUnit& u = *robot;
  u.Initialize();
  Drive(u, 0, 50);
  const cosim::UnitState saved = u.SaveState();
  const auto first = Drive(u, 50, 150);
  u.RestoreState(saved);
  const auto second = Drive(u, 50, 150);
  auto fresh_robot = Straddle();
  ChassisUnit& fresh = *fresh_robot;
  fresh.RestoreState(saved);
  const auto third = Drive(fresh, 50, 150);
  for (std::size_t k = 0; k < first.size(); ++k) {
    EXPECT_TRUE(SameBits(first[k], second[k])) << "step " << 50 + k;
    EXPECT_TRUE(SameBits(first[k], third[k])) << "step " << 50 + k;
  }
}

// Guards the unit's own check of its internal state (the variable count
// matches, so only RestoreInternal can refuse): an initialised state holds
// 13 reals per body (position 3, quaternion 4, linear and angular velocity
// 3 each) for the body and 4 modules, 6 per tread (deflection and force
// direction) and one integer; one saved before Initialize holds no reals.
TEST(ChassisUnit, RestoreRefusesTruncatedInternalState) {
  auto robot = Raw3();
  ChassisUnit& u = *robot;
  const cosim::UnitState before_init = u.SaveState();
  ASSERT_TRUE(before_init.reals.empty());
  u.Initialize();
  const cosim::UnitState saved = u.SaveState();
  ASSERT_EQ(saved.reals.size(), 13u * 5u + 6u * 4u);
  ASSERT_EQ(saved.integers.size(), 1u);
  cosim::UnitState short_reals = saved;
  short_reals.reals.pop_back();
  cosim::UnitState no_integers = saved;
  no_integers.integers.clear();
  cosim::UnitState reals_without_init = before_init;
  reals_without_init.reals = saved.reals;
  for (const auto* bad : {&short_reals, &no_integers, &reals_without_init}) {
    auto fresh_robot = Raw3();
    ChassisUnit& fresh = *fresh_robot;
    try {
      fresh.RestoreState(*bad);
      ADD_FAILURE() << "restored a state of " << bad->reals.size() << " reals and "
                    << bad->integers.size() << " integers";
    } catch (const cosim::UnitError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("unit 'robot' (chassis): saved state has"), std::string::npos) << what;
    }
  }
  auto fresh_robot = Raw3();
  ChassisUnit& fresh = *fresh_robot;
  EXPECT_NO_THROW(fresh.RestoreState(saved));
  TimeNs t = 0;
  Advance(fresh, t, 10);
}

// Guards against Initialize depending on what ran before it (the master may
// call it several times).
TEST(ChassisUnit, InitializeIsIdempotent) {
  auto once_robot = Straddle(), twice_robot = Straddle();
  ChassisUnit &once = *once_robot, &twice = *twice_robot;
  once.Initialize();
  twice.Initialize();
  Drive(twice, 0, 20);
  // The same inputs as `once` at its Initialize (outputs use them).
  SetArray(twice, "drive_torque", {0, 0, 0, 0});
  SetArray(twice, "steer_torque", {0, 0, 0, 0});
  SetArray(twice, "belt_velocity", {0, 0});
  twice.Initialize();
  EXPECT_TRUE(SameBits(Outputs(once), Outputs(twice)));
  const auto a = Drive(once, 0, 50);
  const auto b = Drive(twice, 0, 50);
  for (std::size_t k = 0; k < a.size(); ++k) EXPECT_TRUE(SameBits(a[k], b[k])) << k;
}

// Guards the settle cache in Initialize (repeated calls while the master
// propagates initial values skip the rebuild): a parameter changed between
// two calls must still take effect, here the start position.
TEST(ChassisUnit, InitializeAgainHonoursChangedParameters) {
  auto robot = Raw3();
  ChassisUnit& u = *robot;
  u.Initialize();
  Set(u, "initial_x", 2.5);
  u.Initialize();
  const auto& v = u.variables();
  EXPECT_EQ(v.GetRealElement(*v.Find("position"), 0), 2.5);
}

// ---------------------------------------------------------------------------
// Errors.

// Guards the contract "no robot-specific defaults": a unit built with no
// parameters names every robot-specific one and refuses to initialise.
TEST(ChassisUnit, RobotSpecificParametersHaveNoDefault) {
  ChassisUnit u("robot", {0, 1, 2, 3}, {0, 1, 2, 3}, models::OpenFloor());
  std::vector<std::string> names;  // each parameter once: a list reports every wheel
  for (const auto& p : u.CheckParameters()) {
    EXPECT_EQ(p.message, "must be set (robot-specific: no default)") << p.variable;
    if (names.empty() || names.back() != p.variable) names.push_back(p.variable);
  }
  EXPECT_EQ(names, (std::vector<std::string>{
                       "body_length", "body_width", "body_height", "body_bottom", "mass",
                       "module_mass", "com_height", "wheel_radius", "wheel_x", "wheel_y",
                       "steer_rotor_inertia", "drive_rotor_inertia", "tread_slip_stiffness",
                       "tread_cornering_stiffness", "tread_longitudinal_relaxation",
                       "tread_lateral_relaxation", "tread_damping_ratio", "tread_patch_length",
                       "tread_patch_width"}));
  EXPECT_THROW(u.Initialize(), cosim::UnitError);
  // Without a steerable wheel there is no steering rotor to ask for.
  ChassisUnit fixed("robot", {-1, -1}, {0, 1}, models::OpenFloor());
  for (const auto& p : fixed.CheckParameters()) EXPECT_NE(p.variable, "steer_rotor_inertia");
}

// Guards against bad parameters reaching ODE: each is named with its index.
TEST(ChassisUnit, CheckParametersRejectsBadValues) {
  auto robot = Raw3();
  ChassisUnit& u = *robot;
  EXPECT_TRUE(u.CheckParameters().empty());
  Set(u, "mass", 15.0);  // 4 modules of 5 kg weigh more
  u.variables().SetRealElement(*u.variables().Find("wheel_radius"), 1, 0.0);
  Set(u, "substeps", std::int64_t{0});
  u.variables().SetRealElement(*u.variables().Find("wheel_x"), 2, std::nan(""));
  Set(u, "contact_stiffness", -1.0);
  Set(u, "payload_size", std::vector<double>{0.5, 0.0, 0.3});  // a box needs all three
  Set(u, "com_height", 0.45);                                  // above the 0.07 to 0.40 m box
  const auto problems = u.CheckParameters();
  std::vector<std::string> names;
  for (const auto& p : problems) {
    names.push_back(p.variable + (p.index ? "[" + std::to_string(*p.index) + "]" : ""));
  }
  // The declared rules in declaration order, then the rule between
  // parameters.
  EXPECT_EQ(names,
            (std::vector<std::string>{"wheel_radius[1]", "wheel_x[2]", "contact_stiffness",
                                      "substeps", "module_mass", "com_height", "payload_size"}));
  EXPECT_EQ(problems[2].message, "must be > 0, got -1");
  EXPECT_EQ(problems[3].message, "must be in [1, 1000], got 0");
  EXPECT_EQ(problems[4].message, "times 4 wheels must be less than mass 15, got 5");
  EXPECT_EQ(problems[5].message,
            "must lie within the body box, from body_bottom 0.07 to body_bottom + body_height "
            "0.4, got 0.45");
  EXPECT_EQ(problems[6].message,
            "give all three sizes (a box) or none (a point mass), got 0.5, 0, 0.3");
  try {
    u.Initialize();
    ADD_FAILURE() << "Initialize accepted bad parameters";
  } catch (const cosim::UnitError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("unit 'robot' (chassis)"), std::string::npos) << what;
    EXPECT_NE(what.find("'wheel_radius[1]' must be > 0, got 0"), std::string::npos) << what;
  }
}

// Guards the rules declared with the parameters: each is in the table (what
// inspect and the loader show), and a value outside it is refused at its
// name with the rule in the message, before anything is built.
TEST(ChassisUnit, DeclaredRulesRefuseValuesOutsideThem) {
  auto robot = Raw3();
  ChassisUnit& u = *robot;
  const auto rule = [&](const std::string& name) {
    return u.variables().info(*u.variables().Find(name)).rule.Text();
  };
  EXPECT_EQ(rule("mass"), "required, > 0");
  EXPECT_EQ(rule("wheel_x"), "required");
  EXPECT_EQ(rule("steer_rotor_inertia"), "required, >= 0");
  EXPECT_EQ(rule("body_friction"), ">= 0");
  EXPECT_EQ(rule("tread_slip_stiffness"), "required, > 0");
  EXPECT_EQ(rule("substeps"), "[1, 1000]");
  EXPECT_EQ(rule("initial_yaw"), "finite");
  // Without a steered wheel the steering rotor inertia has a default (0).
  ChassisUnit fixed("robot", {-1, -1}, {0, 1}, models::OpenFloor());
  EXPECT_EQ(fixed.variables().info(*fixed.variables().Find("steer_rotor_inertia")).rule.Text(),
            ">= 0");

  Set(u, "body_friction", -0.1);
  Set(u, "substeps", std::int64_t{1001});
  Set(u, "initial_yaw", INFINITY);
  const auto problems = u.CheckParameters();
  ASSERT_EQ(problems.size(), 3u);
  EXPECT_EQ(problems[0].variable, "body_friction");
  EXPECT_EQ(problems[0].message, "must be >= 0, got -0.1");
  EXPECT_EQ(problems[1].variable, "substeps");
  EXPECT_EQ(problems[1].message, "must be in [1, 1000], got 1001");
  EXPECT_EQ(problems[2].variable, "initial_yaw");
  EXPECT_EQ(problems[2].message, "must be finite, got inf");
  try {
    u.Initialize();
    ADD_FAILURE() << "Initialize accepted bad parameters";
  } catch (const cosim::UnitError& e) {
    EXPECT_NE(std::string(e.what()).find("parameter 'substeps' must be in [1, 1000], got 1001"),
              std::string::npos)
        << e.what();
  }
}

// Guards against topologies and scenes the unit cannot build: each refusal
// names the key and what was expected.
TEST(ChassisUnit, ConstructorChecksTopologyAndScene) {
  const auto problem = [](std::vector<int> steer, std::vector<int> drive) {
    try {
      ChassisUnit u("robot", std::move(steer), std::move(drive), models::OpenFloor());
    } catch (const cosim::UnitError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(problem({}, {}).find("wheel_count"), std::string::npos);
  EXPECT_NE(problem({0, 1}, {0}).find("drive_motor: expected one entry per wheel"),
            std::string::npos);
  EXPECT_NE(problem({0, -2}, {0, 1}).find("steer_motor[1]"), std::string::npos);
  EXPECT_NE(problem({0, 0}, {0, 1}).find("already steers another wheel"), std::string::npos);
  EXPECT_NE(problem({0, 2, 1}, {0, 1, 1}).find("share drive motor 1"), std::string::npos);
  EXPECT_NE(problem({-1, -1, -1}, {0, 2, 2}).find("drive motor 1 drives no wheel"),
            std::string::npos);
  EXPECT_NE(problem({1, -1}, {0, 1}).find("steering motor 0 steers no wheel"), std::string::npos);
  EXPECT_EQ(problem({-1, -1, -1, -1}, {0, 0, 1, 1}), "");

  models::Scene bad = test_robots::OneBelt({0.0, 5.0, 10.0, 1.0, 0.0});
  bad.belts[0].surface = 7;
  EXPECT_THROW(ChassisUnit("robot", {0}, {0}, bad), cosim::UnitError);
  bad = models::OpenFloor();
  bad.carried.push_back({"car", 0, {}});  // belt 0 of a scene with none
  EXPECT_THROW(ChassisUnit("robot", {0}, {0}, bad), cosim::UnitError);
  const auto scene_problem = [](const models::Scene& scene) {
    try {
      ChassisUnit u("robot", {0}, {0}, scene);
    } catch (const cosim::UnitError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  // A car body overhanging its belt's end at time zero (it would leave the
  // scene at once: it leaves with the belt's end).
  bad = test_robots::OneBelt({0.0, 5.0, 10.0, 3.0, 0.0});
  models::Solid car;
  car.x_m = 3.0;  // 4.5 m long: its front at 5.25 m, past the belt's end at 5 m
  car.y_m = 5.0;
  car.length_m = 4.5;
  car.width_m = 1.8;
  car.height_m = 1.2;
  bad.carried.push_back({"car", 0, car});
  EXPECT_NE(
      scene_problem(bad).find("carried object 'car' overhangs the downstream end of belt 'belt'"),
      std::string::npos)
      << scene_problem(bad);
  bad.carried[0].solid.x_m = 2.75;  // its front exactly at the end: on the belt
  EXPECT_EQ(scene_problem(bad), "");
  // Upstream of the belt's start (-5 m), wholly or in part, it waits to be
  // put on the line.
  bad.carried[0].solid.x_m = -6.0;
  EXPECT_EQ(scene_problem(bad), "");
  // A terrain piece without a size, or on a surface the scene lacks:
  // refused, naming the piece.
  bad = models::OpenFloor();
  bad.terrain.push_back({});
  bad.terrain.back().name = "ramp";
  EXPECT_NE(scene_problem(bad).find("terrain 'ramp' needs a positive length, width and thickness"),
            std::string::npos)
      << scene_problem(bad);
  bad.terrain.back().length_m = bad.terrain.back().width_m = bad.terrain.back().thickness_m = 1.0;
  EXPECT_EQ(scene_problem(bad), "");
  bad.terrain.back().surface = 1;
  EXPECT_NE(scene_problem(bad).find("terrain 'ramp' has surface 1, not one of its 1 surfaces"),
            std::string::npos)
      << scene_problem(bad);
  // A floor with no area: every wheel would be off it.
  bad = models::OpenFloor();
  bad.floor.max_x_m = bad.floor.min_x_m;
  EXPECT_NE(scene_problem(bad).find("the floor's rectangle is empty"), std::string::npos)
      << scene_problem(bad);

  // Three modules and no belts: no belt inputs, and it builds and steps.
  auto three = std::make_unique<ChassisUnit>("robot", std::vector<int>{0, 1, 2},
                                             std::vector<int>{0, 1, 2}, models::OpenFloor());
  EXPECT_FALSE(three->variables().Find("belt_velocity"));
  EXPECT_FALSE(three->variables().Find("belt_travel"));
  Set(*three, "body_length", 0.8);
  Set(*three, "body_width", 0.6);
  Set(*three, "body_height", 0.3);
  Set(*three, "body_bottom", 0.05);
  Set(*three, "mass", 60.0);
  Set(*three, "module_mass", 3.0);
  Set(*three, "com_height", 0.12);
  Set(*three, "wheel_radius", 0.08);
  // Evenly on a circle of 0.3 m (made-up geometry for a build test).
  Set(*three, "wheel_x", std::vector<double>{0.3, -0.15, -0.15});
  Set(*three, "wheel_y", std::vector<double>{0.0, 0.26, -0.26});
  Set(*three, "steer_rotor_inertia", 0.0);
  Set(*three, "drive_rotor_inertia", 0.0);
  SetTreads(*three, 3, kRaw3Tread);
  EXPECT_NO_THROW(three->Initialize());
  TimeNs t = 0;
  Advance(*three, t, 10);
}

// Guards against motor indices that size vectors before they are checked
// (a huge index allocated gigabytes; INT_MAX + 1 overflowed) and against
// wheel-count limits that disagree: every index must be in [0, wheel
// count) (steer -1: a fixed wheel), checked first; 1 to kMaxWheels wheels.
TEST(ChassisUnit, TopologyRefusesOutOfRangeIndicesAndWheelCounts) {
  constexpr int kMax = std::numeric_limits<int>::max();
  const auto problem = [](std::vector<int> steer, std::vector<int> drive) {
    return ChassisUnit::TopologyProblem(steer, drive);
  };
  for (const int huge : {2000000000, kMax}) {
    SCOPED_TRACE(huge);
    std::string p = problem({huge}, {0});
    EXPECT_NE(p.find("steer_motor[0]: expected a steering motor index in [0, 0]"),
              std::string::npos)
        << p;
    EXPECT_NE(p.find("got " + std::to_string(huge)), std::string::npos) << p;
    p = problem({-1, -1}, {0, huge});
    EXPECT_NE(p.find("drive_motor[1]: expected a drive motor index in [0, 1]"), std::string::npos)
        << p;
    EXPECT_NE(p.find("got " + std::to_string(huge)), std::string::npos) << p;
    // The constructor refuses them with the same message, before it sizes
    // anything (a std::bad_alloc would fail the test).
    try {
      ChassisUnit u("robot", {-1, -1}, {0, huge}, models::OpenFloor());
      ADD_FAILURE() << "accepted drive motor " << huge;
    } catch (const cosim::UnitError& e) {
      EXPECT_NE(std::string(e.what()).find("drive_motor[1]"), std::string::npos) << e.what();
    }
  }
  EXPECT_NE(problem({std::numeric_limits<int>::min()}, {0}).find("steer_motor[0]"),
            std::string::npos);
  EXPECT_NE(problem({0, 1}, {0, 2}).find("drive_motor[1]: expected a drive motor index in [0, 1]"),
            std::string::npos);

  // kMaxWheels fixed wheels on one motor each: accepted; one more: refused.
  const auto n = static_cast<std::size_t>(ChassisUnit::kMaxWheels);
  static_assert(ChassisUnit::kMaxWheels == 64);
  std::vector<int> fixed(n, -1), drive(n);
  for (std::size_t k = 0; k < n; ++k) drive[k] = static_cast<int>(k);
  EXPECT_EQ(problem(fixed, drive), "");
  fixed.push_back(-1);
  drive.push_back(static_cast<int>(n));
  EXPECT_EQ(problem(fixed, drive), "wheel_count: expected 1 to 64 wheels, got 65");
  EXPECT_EQ(problem({}, {}), "wheel_count: expected 1 to 64 wheels, got 0");
}

// Guards against a robot that drives off the scene's floor without notice
// (nothing is simulated there): the step whose end finds a wheel contact
// outside the floor's rectangle fails, naming the unit, the time and the
// wheel and its contact point; an initial pose off the floor is refused.
TEST(ChassisUnit, LeavingTheFloorFails) {
  models::Scene hall = models::OpenFloor();
  hall.name = "hall";
  hall.floor = {-1.0, 1.0, -2.0, 2.0, 0};
  auto robot = Raw3(hall);
  ChassisUnit& u = *robot;
  u.Initialize();
  SetArray(u, "drive_torque", {2.0, 2.0, 2.0, 2.0});
  TimeNs t = 0;
  cosim::StepResult result = cosim::StepResult::kOk;
  for (int i = 0; i < 3000 && result == cosim::StepResult::kOk; ++i) {
    result = u.DoStep(t, kMs);
    if (result == cosim::StepResult::kOk) t += kMs;
  }
  ASSERT_EQ(result, cosim::StepResult::kError);
  const std::string e = u.last_error();
  // The front wheels (x 0.368 in base_link) cross x = 1 first: wheel 0 (or
  // 3, its mirror; 0 is checked first).
  EXPECT_NE(e.find("robot"), std::string::npos) << e;
  EXPECT_NE(e.find("at the end of the step at t = " + cosim::FormatSeconds(t) + " s"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("wheel 0's contact (1"), std::string::npos) << e;
  EXPECT_NE(e.find("is off the floor of scene 'hall' (x -1 to 1, y -2 to 2 m): the robot ran "
                   "off the scene's floor"),
            std::string::npos)
      << e;
  // About 0.63 m at 0.83 m/s^2 (a = 4 tau / r / m): after about 1.2 s.
  EXPECT_GT(cosim::NsToSeconds(t), 1.0);
  EXPECT_LT(cosim::NsToSeconds(t), 1.5);
  // The outputs show where it went: the step's end.
  EXPECT_GT(Get(u, "wheel_contact")[0], 1.0);

  // Placed off the floor: refused at Initialize.
  auto outside = Raw3(hall);
  Set(*outside, "initial_x", 5.0);
  try {
    outside->Initialize();
    ADD_FAILURE() << "initialised off the floor";
  } catch (const cosim::UnitError& err) {
    EXPECT_NE(std::string(err.what()).find("at the initial pose, wheel 0's contact (5.368"),
              std::string::npos)
        << err.what();
  }
  // Within the floor to the edge: fine (the open floor is +-1e6 m).
  auto open = Raw3();
  Set(*open, "initial_x", 1e6 - 0.5);
  EXPECT_NO_THROW(open->Initialize());
}

// Guards against non-finite inputs or states passing silently: DoStep
// fails and names the variable.
TEST(ChassisUnit, NonFiniteInputOrStateFails) {
  auto robot = Raw3FarBelt();
  ChassisUnit& u = *robot;
  u.Initialize();
  SetArray(u, "drive_torque", {0.0, std::nan(""), 0.0, 0.0});
  EXPECT_EQ(u.DoStep(0, kMs), cosim::StepResult::kError);
  EXPECT_NE(u.last_error().find("input 'drive_torque[1]' is nan"), std::string::npos)
      << u.last_error();
  // A finite but absurd torque overflows the ODE state.
  SetArray(u, "drive_torque", {0.0, 0.0, 1e308, 0.0});
  EXPECT_EQ(u.DoStep(0, kMs), cosim::StepResult::kError);
  EXPECT_NE(u.last_error().find("non-finite"), std::string::npos) << u.last_error();
  // The torque reaches every body through the joints; ODE stops at the
  // first it cannot normalise. The message names a body and its outputs
  // by their current names.
  EXPECT_NE(u.last_error().find("ODE state went non-finite: position of"), std::string::npos)
      << u.last_error();
  EXPECT_NE(u.last_error().find("(outputs "), std::string::npos) << u.last_error();
  EXPECT_EQ(u.last_error().find("pose"), std::string::npos) << u.last_error();
  // The unit refuses to go on until it is initialised again.
  EXPECT_EQ(u.DoStep(kMs, kMs), cosim::StepResult::kError);
  EXPECT_NE(u.last_error().find("needs Initialize or RestoreState"), std::string::npos)
      << u.last_error();
  SetArray(u, "drive_torque", {0.0, 0.0, 0.0, 0.0});
  u.Initialize();
  EXPECT_EQ(u.DoStep(0, kMs), cosim::StepResult::kOk) << u.last_error();
}

// ---------------------------------------------------------------------------
// Guards against the interface drifting from the contract
// (notes: signals, one unit of measure per variable).
using Expected = test_helpers::ExpectedVariable;

std::vector<Expected> Parameters(std::size_t wheels, std::size_t surfaces) {
  using C = cosim::Causality;
  return {{"body_length", C::kParameter, "m", 0},
          {"body_width", C::kParameter, "m", 0},
          {"body_height", C::kParameter, "m", 0},
          {"body_bottom", C::kParameter, "m", 0},
          {"mass", C::kParameter, "kg", 0},
          {"module_mass", C::kParameter, "kg", 0},
          {"com_height", C::kParameter, "m", 0},
          {"wheel_radius", C::kParameter, "m", wheels},
          {"wheel_x", C::kParameter, "m", wheels},
          {"wheel_y", C::kParameter, "m", wheels},
          {"steer_rotor_inertia", C::kParameter, "kg.m2", 0},
          {"drive_rotor_inertia", C::kParameter, "kg.m2", 0},
          {"payload_mass", C::kParameter, "kg", 0},
          {"payload_position", C::kParameter, "m", 3},
          {"payload_size", C::kParameter, "m", 3},
          {"steer_friction", C::kParameter, "N.m.s/rad", 0},
          {"drive_friction", C::kParameter, "N.m.s/rad", 0},
          {"body_friction", C::kParameter, "1", 0},
          {"contact_stiffness", C::kParameter, "N/m", 0},
          {"contact_damping", C::kParameter, "N.s/m", 0},
          {"tread_slip_stiffness", C::kParameter, "1", wheels},
          {"tread_cornering_stiffness", C::kParameter, "1/rad", wheels},
          {"tread_longitudinal_relaxation", C::kParameter, "m", wheels},
          {"tread_lateral_relaxation", C::kParameter, "m", wheels},
          {"tread_damping_ratio", C::kParameter, "1", wheels},
          {"tread_patch_length", C::kParameter, "m", wheels},
          {"tread_patch_width", C::kParameter, "m", wheels},
          {"wheel_friction", C::kParameter, "1", wheels * surfaces},
          {"suspension_stiffness", C::kParameter, "N/m", 0},
          {"suspension_damping", C::kParameter, "N.s/m", 0},
          {"brake_torque", C::kParameter, "N.m", 0},
          {"substeps", C::kParameter, "", 0},
          {"initial_x", C::kParameter, "m", 0},
          {"initial_y", C::kParameter, "m", 0},
          {"initial_yaw", C::kParameter, "rad", 0}};
}

TEST(ChassisUnit, VariableTable) {
  using C = cosim::Causality;
  // Swerve, two belts.
  models::Scene two = test_robots::OneBelt({0.0, 5.0, 10.0, 1.0, 0.0});
  two.belts.push_back(two.belts[0]);
  auto robot = Raw3(two);
  EXPECT_EQ(robot->type_name(), "chassis");
  std::vector<Expected> expected = Parameters(4, 2);
  const std::vector<Expected> swerve = {{"steer_torque", C::kInput, "N.m", 4},
                                        {"drive_torque", C::kInput, "N.m", 4},
                                        {"steer_torque_slope", C::kInput, "N.m.s/rad", 4},
                                        {"steer_torque_rate", C::kInput, "rad/s", 4},
                                        {"drive_torque_slope", C::kInput, "N.m.s/rad", 4},
                                        {"drive_torque_rate", C::kInput, "rad/s", 4},
                                        {"belt_velocity", C::kInput, "m/s", 4},
                                        {"belt_travel", C::kInput, "m", 2},
                                        {"brake", C::kInput, "", 0},
                                        {"steer_angle", C::kOutput, "rad", 4},
                                        {"steer_rate", C::kOutput, "rad/s", 4},
                                        {"drive_rate", C::kOutput, "rad/s", 4},
                                        {"drive_angle", C::kOutput, "rad", 4},
                                        {"position", C::kOutput, "m", 2},
                                        {"yaw", C::kOutput, "rad", 0},
                                        {"linear_velocity", C::kOutput, "m/s", 2},
                                        {"yaw_rate", C::kOutput, "rad/s", 0},
                                        {"body_linear_velocity", C::kOutput, "m/s", 2},
                                        {"position_3d", C::kOutput, "m", 3},
                                        {"orientation", C::kOutput, "1", 4},
                                        {"velocity_3d", C::kOutput, "m/s", 3},
                                        {"angular_velocity", C::kOutput, "rad/s", 3},
                                        {"wheel_surface", C::kOutput, "1", 4},
                                        {"wheel_surface_velocity", C::kOutput, "m/s", 8},
                                        {"wheel_contact", C::kOutput, "m", 8},
                                        {"body_box", C::kOutput, "m, rad, m/s, rad/s", 10}};
  expected.insert(expected.end(), swerve.begin(), swerve.end());
  test_helpers::ExpectTable(*robot, expected);

  // Skid-steer, no belts: no steer_* variables, one drive variable per motor.
  auto husky = Husky(models::OpenFloor());
  expected = Parameters(4, 1);
  const std::vector<Expected> skid = {{"drive_torque", C::kInput, "N.m", 2},
                                      {"drive_torque_slope", C::kInput, "N.m.s/rad", 2},
                                      {"drive_torque_rate", C::kInput, "rad/s", 2},
                                      {"brake", C::kInput, "", 0},
                                      {"drive_rate", C::kOutput, "rad/s", 2},
                                      {"drive_angle", C::kOutput, "rad", 2},
                                      {"position", C::kOutput, "m", 2},
                                      {"yaw", C::kOutput, "rad", 0},
                                      {"linear_velocity", C::kOutput, "m/s", 2},
                                      {"yaw_rate", C::kOutput, "rad/s", 0},
                                      {"body_linear_velocity", C::kOutput, "m/s", 2},
                                      {"position_3d", C::kOutput, "m", 3},
                                      {"orientation", C::kOutput, "1", 4},
                                      {"velocity_3d", C::kOutput, "m/s", 3},
                                      {"angular_velocity", C::kOutput, "rad/s", 3},
                                      {"wheel_surface", C::kOutput, "1", 4},
                                      {"wheel_surface_velocity", C::kOutput, "m/s", 8},
                                      {"wheel_contact", C::kOutput, "m", 8},
                                      {"body_box", C::kOutput, "m, rad, m/s, rad/s", 10}};
  expected.insert(expected.end(), skid.begin(), skid.end());
  test_helpers::ExpectTable(*husky, expected);
}

// Guards against the Rob@Work 3 robot description (models/robots/raw3.yaml)
// and the test robot drifting apart: its `chassis:` section uses only the
// unit's parameters, with the values the tests use (robots.h) or the
// generic defaults, and its body and wheels are the test robot's.
TEST(ChassisUnit, RobotDescriptionMatchesTestRobot) {
  const auto path = std::filesystem::path(models::ModelsDir()) / "robots" / "raw3.yaml";
  const YAML::Node root = YAML::LoadFile(path.string());
  ASSERT_TRUE(root.IsMap());
  EXPECT_TRUE(root["source"] && root["source"].IsScalar());
  auto reference = Raw3();
  const ChassisUnit& defaults = *reference;
  auto robot = Raw3();
  ChassisUnit& u = *robot;
  const YAML::Node chassis = root["chassis"];
  ASSERT_TRUE(chassis && chassis.IsMap());
  for (const auto& kv : chassis) {
    const std::string key = kv.first.as<std::string>();
    const auto ref = u.variables().Find(key);
    ASSERT_TRUE(ref) << "unknown key " << key;
    const auto& info = u.variables().info(*ref);
    EXPECT_EQ(info.causality, cosim::Causality::kParameter) << key;
    if (kv.second.IsSequence()) {
      u.variables().SetValue(*ref, cosim::Value{kv.second.as<std::vector<double>>()});
    } else if (info.type == cosim::VarType::kInteger) {
      u.variables().SetValue(*ref, cosim::Value{kv.second.as<std::int64_t>()});
    } else {
      u.variables().SetValue(*ref, cosim::Value{kv.second.as<double>()});
    }
    // Equal to the reference up to the rounding of a decimal literal.
    const cosim::Value got = u.variables().GetValue(*ref);
    const cosim::Value want = defaults.variables().GetValue(*ref);
    if (const auto* g = std::get_if<double>(&got)) {
      EXPECT_NEAR(*g, std::get<double>(want), 1e-12 * std::abs(*g)) << key;
    } else if (const auto* a = std::get_if<std::vector<double>>(&got)) {
      const auto& b = std::get<std::vector<double>>(want);
      ASSERT_EQ(a->size(), b.size()) << key;
      for (std::size_t k = 0; k < a->size(); ++k) EXPECT_NEAR((*a)[k], b[k], 1e-12) << key;
    } else {
      EXPECT_EQ(got, want) << key;
    }
  }
  EXPECT_TRUE(u.CheckParameters().empty());

  const YAML::Node body = root["body"];
  ASSERT_TRUE(body && body.IsMap());
  EXPECT_EQ(body["length_m"].as<double>(), kRaw3BodyM[0]);
  EXPECT_EQ(body["width_m"].as<double>(), kRaw3BodyM[1]);
  EXPECT_EQ(body["height_m"].as<double>(), kRaw3BodyM[2]);
  EXPECT_EQ(body["bottom_m"].as<double>(), kRaw3BodyBottomM);
  EXPECT_EQ(body["mass_kg"].as<double>(), kRaw3MassKg);
  EXPECT_EQ(body["com_height_m"].as<double>(), kRaw3ComHeightM);
  const YAML::Node wheels = root["wheels"];
  ASSERT_TRUE(wheels && wheels.IsSequence());
  ASSERT_EQ(wheels.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(wheels[k]["x_m"].as<double>(), kRaw3WheelXM[k]) << k;
    EXPECT_EQ(wheels[k]["y_m"].as<double>(), kRaw3WheelYM[k]) << k;
    EXPECT_EQ(wheels[k]["radius_m"].as<double>(), kRaw3WheelRadiusM) << k;
    EXPECT_EQ(wheels[k]["mass_kg"].as<double>(), kRaw3ModuleMassKg) << k;
  }
}

}  // namespace
}  // namespace linesim::chassis
