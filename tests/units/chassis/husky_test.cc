// The chassis unit built as a Clearpath Husky A200 (skid-steer: four fixed
// wheels, the two of a side coupled on one drive motor), and the body's
// collisions with the scene's obstacles and carried objects.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <vector>

#include "cosim/time.h"
#include "models/models_dir.h"
#include "tests/units/chassis/robots.h"
#include "tests/units/test_helpers.h"
#include "units/chassis/chassis_unit.h"
#include "units/chassis/floor_world.h"

namespace linesim::chassis {
namespace {

using cosim::TimeNs;
using test_helpers::Get;
using test_helpers::SetArray;
using namespace test_robots;  // NOLINT: the robots' numbers and builders

constexpr TimeNs kMs = 1'000'000;
constexpr double kH = 1e-3;  // communication step, s

// The test's own speed loop: a PI controller per drive motor on the drive
// rate, torque = kp e + ki integral(e). Gains for the Husky's straight
// drive (per motor 2 wheels + half the robot seen at the rim:
// J = 2 x 0.036 + 25 kg x 0.1651^2 = 0.75 kg.m^2): kp 20, ki 100 give
// J s^2 + kp s + ki with omega_n 11.5 rad/s, damping 1.15; on a sliding
// wheel pair alone (0.072 kg.m^2) kp h / J = 0.28 keeps the discrete loop
// stable.
struct SpeedLoop {
  double kp = 20.0, ki = 100.0;
  std::vector<double> integral = std::vector<double>(2, 0.0);
  std::vector<double> torque = std::vector<double>(2, 0.0);

  void Step(ChassisUnit& u, const std::vector<double>& target) {
    const auto rate = Get(u, "drive_rate");
    for (std::size_t m = 0; m < 2; ++m) {
      const double e = target[m] - rate[m];
      integral[m] += e * kH;
      torque[m] = kp * e + ki * integral[m];
    }
    SetArray(u, "drive_torque", torque);
  }
};

void StepOk(ChassisUnit& u, TimeNs& t) {
  ASSERT_EQ(u.DoStep(t, kMs), cosim::StepResult::kOk) << u.last_error();
  t += kMs;
}

// Drives both sides at `rate` (rad/s, the speed loop) for `steps` 1 ms steps
// from t = 0; returns the largest x base_link reached.
double DriveStraight(ChassisUnit& u, double rate, int steps) {
  SpeedLoop loop;
  TimeNs t = 0;
  double max_x = 0.0;
  for (int i = 0; i < steps; ++i) {
    loop.Step(u, {rate, rate});
    StepOk(u, t);
    max_x = std::max(max_x, Get(u, "position")[0]);
  }
  return max_x;
}

// Guards the coupling of a side's two wheels (a belt in the real robot):
// they must turn together by a constraint, also when the torque acts on one
// of them only and the pair straddles a belt edge (front wheel on a running
// belt, rear wheel on the floor), which pulls them apart. Expected: equal
// rates to the coupling's compliance (CFM 1e-10 x torques of tens of N.m:
// about 1e-8 rad/s), checked against 1e-6 rad/s; drive_rate is that rate.
TEST(Husky, WheelsOfASideTurnTogether) {
  // Belt along map y covering x > 0: the front wheels (x = +0.256) on it.
  auto robot = Husky(OneBelt({20.0, 0.0, 40.0, 40.0, std::acos(0.0)}, kHuskyMu));
  ChassisUnit& u = *robot;
  u.Initialize();
  EXPECT_EQ(Get(u, "wheel_surface"), (std::vector<double>{1.0, 0.0, 1.0, 0.0}));
  SetArray(u, "belt_velocity", {0.0, 0.3});
  TimeNs t = 0;
  double max_rate = 0.0, max_difference = 0.0;
  for (int i = 0; i < 1500; ++i) {
    const double s = std::sin(0.01 * i);
    SetArray(u, "drive_torque", {8.0 * s, -3.0});
    StepOk(u, t);
    ASSERT_NEAR(u.WheelRate(0), u.WheelRate(1), 1e-6) << "step " << i;
    ASSERT_NEAR(u.WheelRate(2), u.WheelRate(3), 1e-6) << "step " << i;
    EXPECT_EQ(Get(u, "drive_rate")[0], u.WheelRate(0));
    EXPECT_EQ(Get(u, "drive_rate")[1], u.WheelRate(2));
    max_rate = std::max(max_rate, std::abs(u.WheelRate(1)));
    max_difference = std::max({max_difference, std::abs(u.WheelRate(0) - u.WheelRate(1)),
                               std::abs(u.WheelRate(2) - u.WheelRate(3))});
  }
  RecordProperty("max_rate_difference", [&] {
    char b[32];
    std::snprintf(b, sizeof b, "%.3g", max_difference);
    return std::string(b);
  }());
  EXPECT_GT(max_rate, 1.0);  // the uncoupled-side wheel did turn
}

// Guards the skid-steer drive straight ahead: both motors held at the rate
// of 0.5 m/s at the rim, 0.5 / 0.1651 rad/s; four wheels rolling without
// slip carry the body at r omega. Expected: 0.5 m/s within 1 % (the soft
// contact shortens the rolling radius by m g / 4 / k = 0.12 mm, 0.07 %),
// no turning.
TEST(Husky, DrivesStraightAtTheRimSpeed) {
  auto robot = Husky(Floor(kHuskyMu));
  ChassisUnit& u = *robot;
  u.Initialize();
  const double rate = 0.5 / kHuskyWheelRadiusM;
  SpeedLoop loop;
  TimeNs t = 0;
  for (int i = 0; i < 3000; ++i) {
    loop.Step(u, {rate, rate});
    StepOk(u, t);
  }
  EXPECT_NEAR(Get(u, "body_linear_velocity")[0], 0.5, 0.005);
  RecordProperty("speed", [&] {
    char b[32];
    std::snprintf(b, sizeof b, "%.7f", Get(u, "body_linear_velocity")[0]);
    return std::string(b);
  }());
  EXPECT_NEAR(Get(u, "body_linear_velocity")[1], 0.0, 1e-4);
  EXPECT_NEAR(Get(u, "yaw_rate")[0], 0.0, 1e-4);
  EXPECT_NEAR(Get(u, "position")[1], 0.0, 1e-3);
}

// Turning in place: left rims at -u, right rims at +u (wheels at
// (+-a, +-b), a = 0.256 half wheelbase, b = 0.2854 half track). All four
// contacts slide. With the body turning at omega about its centre, the
// slip of a contact point over the floor is
//   left  (x, +b): s = omega (-b, x) + (u, 0) = (u - omega b, omega x),
//   right (x, -b): s = omega (+b, x) - (u, 0) = (omega b - u, omega x),
// all of length sqrt((u - omega b)^2 + (omega a)^2). Each contact pushes
// -mu N s / |s| (Coulomb, equal loads N = m g / 4: the centre of mass is
// over the wheels' centre and the friction forces have no net force, so
// no net moment tilting the body). The net moment about z of contact i,
// x F_y - y F_x, is -mu N / |s| (omega a^2 + omega b^2 - u b) for every
// wheel, so the steady turn (zero net moment) is
//   omega = u b / (a^2 + b^2).
// There u - omega b = u a^2 / (a^2 + b^2) and |s| = u a / sqrt(a^2 + b^2),
// so the floor pushes each rim back with mu N a / sqrt(a^2 + b^2) along
// its heading: the wheel torque that holds the rim speed is
//   tau = mu N r a / sqrt(a^2 + b^2)   (13.5 N.m for the Husky),
// 2 tau per motor. Driving straight at the same rim speed needs only the
// joint friction (0.01 N.m.s/rad x 1.8 rad/s per wheel).
TEST(Husky, TurnsInPlaceAtTheCoulombRateWithTheCoulombTorque) {
  const double a = kHuskyHalfBaseM, b = kHuskyHalfTrackM, r = kHuskyWheelRadiusM;
  const double u_mps = 0.3;
  const double omega = u_mps * b / (a * a + b * b);  // 0.5825 rad/s
  const double n_per_wheel = kHuskyMassKg * kGravityMps2 / 4.0;
  const double tau_wheel = kHuskyMu * n_per_wheel * r * a / std::hypot(a, b);
  const double rate = u_mps / r;

  // Mean yaw rate and mean |motor torque| over the last second of 4 s.
  const auto run = [&](double left, double right, double* yaw_rate, double* torque) {
    auto robot = Husky(Floor(kHuskyMu));
    ChassisUnit& u = *robot;
    u.Initialize();
    SpeedLoop loop;
    TimeNs t = 0;
    *yaw_rate = 0.0;
    *torque = 0.0;
    for (int i = 0; i < 4000; ++i) {
      loop.Step(u, {left, right});
      StepOk(u, t);
      if (i >= 3000) {
        *yaw_rate += Get(u, "yaw_rate")[0] / 1000.0;
        *torque += 0.5 * (std::abs(loop.torque[0]) + std::abs(loop.torque[1])) / 1000.0;
      }
    }
    // The rims are at the commanded speed (the loop's integral holds them).
    EXPECT_NEAR(Get(u, "drive_rate")[0], left, 1e-3 * rate);
    EXPECT_NEAR(Get(u, "drive_rate")[1], right, 1e-3 * rate);
    // Turning in place: the centre stays put.
    if (left == -right) {
      EXPECT_LT(std::hypot(Get(u, "position")[0], Get(u, "position")[1]), 0.01);
    }
  };
  double turn_rate = 0.0, turn_torque = 0.0;
  run(-rate, rate, &turn_rate, &turn_torque);
  // Tolerances: in the steady turn the slip directions are constant, so
  // the contacts' sideways damper (slip_damping) carries no force, and the
  // soft normal (0.12 mm) changes the lever arms by 1e-3 %; 0.5 % leaves
  // room for the loop's ripple (measured: 2e-6 relative for the rate). The
  // motor torque also turns the two wheel joints' viscous friction
  // (default 0.01 N.m.s/rad) at the commanded rate.
  EXPECT_NEAR(turn_rate, omega, 0.005 * omega);
  const double joint_nm = 2.0 * 0.01 * rate;
  EXPECT_NEAR(turn_torque, 2.0 * tau_wheel + joint_nm, 0.005 * 2.0 * tau_wheel);

  double straight_rate = 0.0, straight_torque = 0.0;
  run(rate, rate, &straight_rate, &straight_torque);
  EXPECT_NEAR(straight_rate, 0.0, 1e-4);
  // A turn on the spot needs far more torque than driving straight at the
  // same rim speed (here over a hundred times).
  EXPECT_GT(turn_torque, 100.0 * straight_torque);
  RecordProperty("turn_yaw_rate", std::to_string(turn_rate) + " vs " + std::to_string(omega));
  RecordProperty("turn_torque",
                 std::to_string(turn_torque) + " vs " + std::to_string(2.0 * tau_wheel));
  RecordProperty("straight_torque", std::to_string(straight_torque));
}

// Mean yaw rate (last second of 6 s) of a Husky whose rims are held at
// v -+ du / 2 (left, right) on the open floor of friction mu.
double SteadyYawRate(ChassisUnit& u, double v_mps, double du_mps) {
  u.Initialize();
  SpeedLoop loop;
  const double r = kHuskyWheelRadiusM;
  TimeNs t = 0;
  double yaw_rate = 0.0;
  for (int i = 0; i < 6000; ++i) {
    loop.Step(u, {(v_mps - 0.5 * du_mps) / r, (v_mps + 0.5 * du_mps) / r});
    StepOk(u, t);
    if (i >= 5000) yaw_rate += Get(u, "yaw_rate")[0] / 1000.0;
  }
  return yaw_rate;
}

// Guards the skid-steer's turning from the tyres' creep. Quasi-static
// force balance of four linear brush tyres (longitudinal F = -C_kappa
// s_x / V, lateral F = -C_alpha s_y / V, equal loads and wheel speeds V,
// wheels at (+-a, +-b), rims u_L, u_R, body at v and omega): the net
// longitudinal force gives v = (u_L + u_R) / 2, the lateral one no
// sideslip, and the yaw moment
//   -4 C_alpha a^2 omega + 2 b C_kappa (du - 2 b omega) = 0
// an effective track du / omega = B_eff = 2 b (1 + (C_alpha / C_kappa)
// (a / b)^2), the same at every radius while the tyres creep. With C_alpha
// = C_kappa / 2 (a tread made anisotropic for the test) 0.8004 m; the
// Husky's isotropic brush tread gives 2 (a^2 + b^2) / b = 1.0300 m, which
// is also the all-sliding figure of TurnsInPlace... above. Radii 4 to 16 m
// at 0.5 m/s keep the lateral slip a / R below 0.064 rad, within creep
// (mu / 6.9 = 0.11 rad). Tolerance 2 %: the inner and outer wheels roll
// at V (1 -+ b / R), which the balance neglects. The Husky's own tread is
// measured at six radii, 1 to 16 m: below 4 m its contacts slide in part,
// which for an isotropic tread gives the same figure (1.030 m), and every
// radius is within 10 % of Clearpath's husky_control figure, wheel_separation
// 0.555 m x wheel_separation_multiplier 1.875 = 1.0406 m.
TEST(Husky, EffectiveTrackFromTheTyresCreep) {
  const double a = kHuskyHalfBaseM, b = kHuskyHalfTrackM, v = 0.5;
  const double clearpath = 0.555 * 1.875;
  for (const double ratio : {0.5, 1.0}) {
    const double expected = 2.0 * b * (1.0 + ratio * (a / b) * (a / b));
    const std::vector<double> radii = ratio == 1.0
                                          ? std::vector<double>{1.0, 1.5, 2.0, 4.0, 8.0, 16.0}
                                          : std::vector<double>{4.0, 8.0, 16.0};
    for (const double radius : radii) {
      SCOPED_TRACE(std::to_string(ratio) + " at R " + std::to_string(radius));
      auto robot = Husky(Floor(0.75));
      std::vector<double> cornering(4, kHuskyTread.slip_stiffness * ratio);
      Set(*robot, "tread_cornering_stiffness", cornering);
      const double du = v * expected / radius;
      const double omega = SteadyYawRate(*robot, v, du);
      EXPECT_NEAR(du / omega, expected, 0.02 * expected);
      if (ratio == 1.0) {
        EXPECT_NEAR(du / omega, clearpath, 0.1 * clearpath);
      }
      std::printf("C_alpha/C_kappa %.1f  R %5.1f m  B_eff %.4f m  (analytic %.4f)\n", ratio, radius,
                  du / omega, expected);
    }
  }
}

// ---------------------------------------------------------------------------
// Obstacles and carried objects.

// Guards against a body that passes through obstacles: a Husky driven at
// 0.5 m/s straight at a pillar (radius 0.2 m, 2 m tall, centre 1.5 m
// ahead) stops with its front face at the pillar: base_link at
// 1.5 - 0.2 - 0.9874 / 2 = 0.806 m, pressed in by no more than a few mm
// (the loop then spins the wheels: about mu m g = 490 N on the contact,
// 1e6 N/m per contact point).
TEST(Obstacles, PillarStopsTheRobot) {
  models::Scene scene = Floor(kHuskyMu);
  models::Solid pillar;
  pillar.kind = models::Solid::Kind::kCylinder;
  pillar.x_m = 1.5;
  pillar.radius_m = 0.2;
  pillar.height_m = 2.0;
  scene.obstacles.push_back({"pillar", "pillar", pillar});
  auto robot = Husky(scene);
  ChassisUnit& u = *robot;
  u.Initialize();
  const double rate = 0.5 / kHuskyWheelRadiusM;
  const double stop_x = 1.5 - 0.2 - 0.5 * kHuskyBodyM[0];
  const double max_x = DriveStraight(u, rate, 5000);
  EXPECT_LT(max_x, stop_x + 0.003);
  RecordProperty("pillar_overshoot_m", std::to_string(max_x - stop_x));
  EXPECT_NEAR(Get(u, "position")[0], stop_x, 0.003);
  EXPECT_NEAR(Get(u, "position")[1], 0.0, 1e-3);
  EXPECT_NEAR(Get(u, "body_linear_velocity")[0], 0.0, 1e-3);
  // The wheels spin on: the pillar, not the drive, stopped the robot.
  EXPECT_GT(Get(u, "drive_rate")[0], 0.5 * rate);
}

// Guards against carried objects that do not move with belt_travel, do
// not push, or do not leave with their belt's end: a car body (4.5 x 1.8 x
// 1.2 m on skids 5 cm up) carried by a belt at 0.3 m/s reaches a braked
// Husky standing on the floor at the belt's end (the belt reaches under the
// robot's rear, short of its rear wheels) and pushes it along at the belt
// speed (its locked wheels slide: the brake's 30 N.m exceeds the mu N r =
// 20 N.m a wheel can take), its rear face at the car's front face to a few
// mm. When the car's front reaches the belt's end it is lifted off the
// line: gone from the scene, so the robot slides to a stop there, pushed
// 0.19 m in all.
TEST(Obstacles, CarBodyPushesABrakedRobot) {
  const double belt_mps = 0.3;
  // Belt along map x from x = -8 to -0.3 (3 m wide); the robot at the
  // origin: its rear face at -0.494, its rear wheels' contacts at -0.256.
  const double belt_end = -0.3;
  models::Scene scene = OneBelt({-4.15, 0.0, 7.7, 3.0, 0.0}, kHuskyMu);
  models::Solid car;
  car.x_m = -3.5;  // front face at -1.25 m at zero travel
  car.length_m = 4.5;
  car.width_m = 1.8;
  car.bottom_m = 0.05;
  car.height_m = 1.2;
  scene.carried.push_back({"car", 0, car});
  auto robot = Husky(scene);
  ChassisUnit& u = *robot;
  u.variables().SetBoolean(*u.variables().Find("brake"), true);
  u.Initialize();
  SetArray(u, "belt_velocity", {belt_mps, 0.0});
  TimeNs t = 0;
  const double rear = 0.5 * kHuskyBodyM[0];
  double min_gap = 1e9;
  double pushed_velocity = 0.0;
  for (int i = 0; i < 6000; ++i) {
    const double travel = belt_mps * cosim::NsToSeconds(t);
    SetArray(u, "belt_travel", {travel});
    StepOk(u, t);
    const double car_front = -1.25 + belt_mps * cosim::NsToSeconds(t);
    if (car_front <= belt_end) {
      min_gap = std::min(min_gap, Get(u, "position")[0] - rear - car_front);
    }
    // Before it arrives (0.756 m at 0.3 m/s: 2.5 s) the robot stands still.
    if (car_front < -rear - 0.01) {
      ASSERT_LT(std::abs(Get(u, "position")[0]), 1e-4) << "step " << i;
    }
    // 0.5 s into the push, 0.15 s before the car leaves.
    if (i == 3000) pushed_velocity = Get(u, "linear_velocity")[0];
    // The wheels stay on the floor.
    for (double s : Get(u, "wheel_surface")) ASSERT_EQ(s, 0.0) << "step " << i;
  }
  EXPECT_NEAR(pushed_velocity, belt_mps, 0.01 * belt_mps);
  RecordProperty("car_min_gap_m", std::to_string(min_gap));
  EXPECT_GT(min_gap, -0.003);
  EXPECT_LT(min_gap, 0.001);
  // The car left at 3.17 s (its front at the belt's end): the robot slid
  // to a stop (mu g = 9.8 m/s^2: 5 mm from 0.3 m/s) right after it, its
  // rear at the belt's end, and stood there for the remaining 2.8 s though
  // the belt ran on.
  EXPECT_NEAR(Get(u, "linear_velocity")[0], 0.0, 1e-4);
  EXPECT_GT(Get(u, "position")[0] - rear, belt_end - 0.003);
  EXPECT_LT(Get(u, "position")[0] - rear, belt_end + 0.01);
}

// Guards against a body that passes through other robots and workers (a
// fleet's moving boxes and cylinders, which the chassis meets as it meets a
// pillar): a Husky driven at 0.5 m/s towards a still Rob@Work 3 body (1.03 x
// 0.57 x 0.40 m, paper 1 Table I) centred 2 m ahead, and towards a still
// leg (radius 0.06 m, DIN 33402-2 calf, as people::WorkerUnit) 1.5 m
// ahead, stops with its front face at it, pressed in by no more than a few
// mm as at the pillar.
TEST(MovingSolids, OtherRobotAndLegStopTheRobot) {
  for (const bool box : {true, false}) {
    SCOPED_TRACE(box ? "box" : "cylinder");
    auto robot = Husky(Floor(kHuskyMu), "husky", box ? 1 : 0, box ? 0 : 1);
    ChassisUnit& u = *robot;
    u.Initialize();
    if (box) {
      SetArray(u, "moving_boxes", {2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.03, 0.57, 0.0, 0.4});
    } else {
      SetArray(u, "moving_cylinders", {1.5, 0.0, 0.0, 0.0, 0.06, 0.0, 0.5});
    }
    const double face = box ? 2.0 - 0.5 * 1.03 : 1.5 - 0.06;
    const double stop_x = face - 0.5 * kHuskyBodyM[0];
    const double rate = 0.5 / kHuskyWheelRadiusM;
    const double max_x = DriveStraight(u, rate, 5000);
    EXPECT_LT(max_x, stop_x + 0.003);
    EXPECT_GT(Get(u, "position")[0], stop_x - 0.01);
    EXPECT_NEAR(Get(u, "body_linear_velocity")[0], 0.0, 1e-3);
    EXPECT_GT(Get(u, "drive_rate")[0], 0.5 * rate);
  }
}

// Guards against a moving box that does not push: another robot's body
// coming at 0.3 m/s (its pose given every step, as a fleet's connections
// give it) pushes a braked Husky along at its speed, its rear face at the
// box's front face to a few mm (the box moves on within the step at its
// velocity).
TEST(MovingSolids, OtherRobotPushesABrakedRobot) {
  const double v = 0.3;
  auto robot = Husky(Floor(kHuskyMu), "husky", 1, 0);
  ChassisUnit& u = *robot;
  u.variables().SetBoolean(*u.variables().Find("brake"), true);
  u.Initialize();
  const double rear = 0.5 * kHuskyBodyM[0];
  const double start = -rear - 0.3 - 0.5 * 1.03;  // 0.3 m behind at t = 0
  TimeNs t = 0;
  double min_gap = 1e9;
  for (int i = 0; i < 4000; ++i) {
    const double x = start + v * cosim::NsToSeconds(t);
    SetArray(u, "moving_boxes", {x, 0.0, 0.0, v, 0.0, 0.0, 1.03, 0.57, 0.0, 0.4});
    StepOk(u, t);
    if (i > 1500) min_gap = std::min(min_gap, Get(u, "position")[0] - rear - (x + 0.5 * 1.03));
  }
  EXPECT_NEAR(Get(u, "linear_velocity")[0], v, 0.01 * v);
  EXPECT_GT(min_gap, -0.003);
  EXPECT_LT(min_gap, 0.003);
}

// Guards against the Husky's robot description and the test robot
// drifting apart: models/robots/husky.yaml's body (its box from the URDF,
// its com_height_m the assumed 0.13 m clearance + 0.2475 / 2 m) is the
// test robot's.
TEST(Husky, RobotDescriptionBodyMatchesTestRobot) {
  const auto path = std::filesystem::path(models::ModelsDir()) / "robots" / "husky.yaml";
  const YAML::Node body = YAML::LoadFile(path.string())["body"];
  ASSERT_TRUE(body && body.IsMap());
  EXPECT_EQ(body["length_m"].as<double>(), kHuskyBodyM[0]);
  EXPECT_EQ(body["width_m"].as<double>(), kHuskyBodyM[1]);
  EXPECT_EQ(body["height_m"].as<double>(), kHuskyBodyM[2]);
  EXPECT_EQ(body["bottom_m"].as<double>(), kHuskyBodyBottomM);
  EXPECT_EQ(body["mass_kg"].as<double>(), kHuskyMassKg);
  EXPECT_NEAR(body["com_height_m"].as<double>(), kHuskyComHeightM, 1e-15);
}

// Guards against hidden state in the coupling joints, the obstacle lists or
// the carried objects that a restore misses: a Husky driving towards a
// pillar while a car body catches up and pushes it, saved mid-push and
// restored (in itself and in a fresh unit), continues bit for bit.
TEST(Obstacles, SaveRestoreWithObjectsIsBitForBit) {
  // Belt from x = -8 to -0.3: the car leaves at its end (belt travel
  // 0.25 m, step 833), within the compared stretch.
  models::Scene scene = OneBelt({-4.15, 0.0, 7.7, 3.0, 0.0}, kHuskyMu);
  models::Solid car;
  car.x_m = -2.8;  // front face 0.05 m behind the robot's rear at zero travel
  car.length_m = 4.5;
  car.width_m = 1.8;
  car.bottom_m = 0.05;
  car.height_m = 1.2;
  scene.carried.push_back({"car", 0, car});
  models::Solid pillar;
  pillar.kind = models::Solid::Kind::kCylinder;
  pillar.x_m = 0.9;
  pillar.y_m = 0.3;
  pillar.radius_m = 0.2;
  pillar.height_m = 2.0;
  scene.obstacles.push_back({"pillar", "pillar", pillar});
  const auto drive = [](ChassisUnit& u, int from, int to) {
    std::vector<std::vector<double>> out;
    for (int k = from; k < to; ++k) {
      SetArray(u, "drive_torque", {3.0 + std::sin(0.05 * k), 2.0});
      SetArray(u, "belt_velocity", {0.3, 0.0});
      SetArray(u, "belt_travel", {0.3e-3 * k});
      EXPECT_EQ(u.DoStep(k * kMs, kMs), cosim::StepResult::kOk) << u.last_error();
      out.push_back(test_helpers::Outputs(u));
    }
    return out;
  };
  auto robot = Husky(scene);
  robot->Initialize();
  drive(*robot, 0, 400);
  const cosim::UnitState saved = robot->SaveState();
  const auto first = drive(*robot, 400, 1200);
  robot->RestoreState(saved);
  const auto second = drive(*robot, 400, 1200);
  auto fresh = Husky(scene);
  fresh->RestoreState(saved);
  const auto third = drive(*fresh, 400, 1200);
  for (std::size_t k = 0; k < first.size(); ++k) {
    ASSERT_TRUE(test_helpers::SameBits(first[k], second[k])) << "step " << 400 + k;
    ASSERT_TRUE(test_helpers::SameBits(first[k], third[k])) << "step " << 400 + k;
  }
  // The car did reach the robot and push it on.
  EXPECT_GT(first.back()[2], 0.1);  // position x
}

}  // namespace
}  // namespace linesim::chassis
