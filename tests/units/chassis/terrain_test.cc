// The chassis on terrain pieces (units/chassis/floor_world.h): a braked
// Husky on an incline (Coulomb), and paper 2's Husky with its UR10 payload
// climbing the van bay's ramp (models/scenes/van_bay.yaml, read by the
// loader) at 0.3 m/s onto the van floor and its bump, with the drive
// motors' currents against their ratings.

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <numbers>
#include <vector>

#include "cosim/time.h"
#include "loader/scene_file.h"
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
constexpr double kPi = std::numbers::pi;

void StepOk(ChassisUnit& u, TimeNs& t) {
  ASSERT_EQ(u.DoStep(t, kMs), cosim::StepResult::kOk) << u.last_error();
  t += kMs;
}

// Nose-up angle of base_link's x axis above the map plane, and its roll
// (rotation about its own x axis, + raising its left side), from the
// orientation quaternion w, x, y, z.
double NoseUp(const std::vector<double>& q) {
  return std::asin(2.0 * (q[1] * q[3] - q[0] * q[2]));
}
double Roll(const std::vector<double>& q) {
  return std::atan2(2.0 * (q[0] * q[1] + q[2] * q[3]), 1.0 - 2.0 * (q[1] * q[1] + q[2] * q[2]));
}

// The test's speed loop (as tests/units/chassis/husky_test.cc): a PI per
// drive motor on the drive rate, torque = kp e + ki integral(e). With the
// arm the rim sees J = 2 x 0.036 + 43.85 kg x 0.1651^2 = 1.27 kg.m^2 per
// side: kp 20, ki 100 give omega_n 8.9 rad/s, damping 0.89.
struct SpeedLoop {
  double kp = 20.0, ki = 100.0;
  std::vector<double> integral = std::vector<double>(2, 0.0);
  std::vector<double> torque = std::vector<double>(2, 0.0);

  void Step(ChassisUnit& u, double target) {
    const auto rate = Get(u, "drive_rate");
    for (std::size_t m = 0; m < 2; ++m) {
      const double e = target - rate[m];
      integral[m] += e * kH;
      torque[m] = kp * e + ki * integral[m];
    }
    SetArray(u, "drive_torque", torque);
  }
};

// An open floor with one incline: a 4 x 3 m piece tilted by `pitch` about
// map y (rising along +x), its top face's centre at (0, 0, 0.6), of
// friction `mu`.
models::Scene Incline(double pitch, double mu) {
  models::Scene s = Floor(0.8);
  s.surfaces.push_back({"incline", mu, 0.2, 500.0});
  models::TerrainPiece t;
  t.name = "incline";
  t.length_m = 4.0;
  t.width_m = 3.0;
  t.thickness_m = 0.1;
  t.pitch_rad = pitch;
  t.center_x_m = 0.05 * std::sin(pitch);
  t.center_z_m = 0.6 - 0.05 * std::cos(pitch);
  t.surface = 1;
  s.terrain.push_back(t);
  return s;
}

// Guards against terrain contacts that are not Coulomb's on a wheeled
// robot, a robot not put onto the terrain it starts over, and a payload
// that does not weigh. Analytic (Coulomb, a braked body on an incline of
// 20 deg, tan 20 = 0.364): with mu 0.5 it stays; with mu 0.25 it slides
// down with a = g (sin p - mu cos p) = 1.050 m/s^2, whatever its mass. Its
// pitch is the incline's up to the contact springs: on the incline the
// arm's weight moves m g sin(p) h / wheelbase = 87.7 x 9.81 x 0.34 x 0.5
// / 0.512 = 290 N from the front wheels to the rear ones (145 N each), so
// the rear contacts sink 2 x 145 N / 1e6 N/m = 0.29 mm deeper than the
// front: 0.29 mm / 0.512 m = 5.7e-4 rad; 1e-3 rad tolerance. Brake 30 N.m
// per wheel holds the wheels: each carries at most m g sin(p) r / 4 =
// 12 N.m. Held, the robot sags down the slope until its treads (unloaded at
// time zero) carry the weight's share along it: sum k_x delta = m g sin p
// with k_x = C_kappa / sigma per wheel at its static load m g / 4, so
// delta = sigma sin(p) / (C_kappa / F_z) = 0.041 x 0.342 / 6.9 = 2.03 mm
// for the Husky's tyre, whatever the mass, at least (other compliances
// add); then it stays (a spring at standstill, no creep), to 1e-6 m over
// the last second once the tread's oscillation (damping ratio 0.1, about
// 0.25 s time constant) has died out.
TEST(Terrain, BrakedHuskyWithArmOnAnInclineIsCoulomb) {
  const double pitch = 20.0 * kPi / 180.0;
  for (const double mu : {0.5, 0.25}) {
    SCOPED_TRACE(mu);
    auto robot = HuskyWithArm(Incline(pitch, mu));
    ChassisUnit& u = *robot;
    u.Initialize();
    // Placed on the incline: base_link's origin on its top face, at the
    // initial x, y; every wheel on the piece (surface 1: no belts).
    const auto p0 = Get(u, "position_3d");
    EXPECT_NEAR(p0[0], 0.0, 1e-12);
    EXPECT_NEAR(p0[1], 0.0, 1e-12);
    EXPECT_NEAR(p0[2], 0.6, 1e-3);
    EXPECT_EQ(Get(u, "wheel_surface"), (std::vector<double>{1.0, 1.0, 1.0, 1.0}));
    EXPECT_NEAR(NoseUp(Get(u, "orientation")), pitch, 1e-3);
    u.variables().SetBoolean(*u.variables().Find("brake"), true);
    TimeNs t = 0;
    const bool holds = mu > std::tan(pitch);
    // Held: settled after 2 s; sliding: the acceleration from 0.2 to 1 s.
    const int settle = holds ? 2000 : 200, steps = holds ? 3000 : 1000;
    double v_start = 0.0, x_start = 0.0;
    for (int i = 1; i <= steps; ++i) {
      StepOk(u, t);
      if (i == settle) {
        v_start = Get(u, "velocity_3d")[0];
        x_start = Get(u, "position")[0];
      }
    }
    const auto v = Get(u, "velocity_3d");
    std::printf("incline 20 deg, mu %.2f: pitch error %.2e rad, moved %.2e m after settling\n", mu,
                NoseUp(Get(u, "orientation")) - pitch, Get(u, "position")[0] - x_start);
    if (holds) {
      const double sag = -(x_start - p0[0]) / std::cos(pitch);
      const double tread = test_robots::kHuskyTread.relaxation_m * std::sin(pitch) /
                           test_robots::kHuskyTread.slip_stiffness;
      std::printf("incline 20 deg, mu %.2f: sag %.4f mm (treads %.4f mm)\n", mu, 1e3 * sag,
                  1e3 * tread);
      // The treads are one compliance in series with the brake's and the
      // contacts': the sag is at least theirs (measured 4.8 mm: with mu 0.5
      // the unloaded front wheels, mu N = 65 N, cannot hold their 74 N
      // share, and the rest is not yet traced).
      EXPECT_GT(sag, 0.95 * tread);
      // Stays: no creep (1e-6 m over the last second).
      EXPECT_NEAR(Get(u, "position")[0], x_start, 1e-6);
      EXPECT_NEAR(v[0], 0.0, 1e-6);
      EXPECT_NEAR(NoseUp(Get(u, "orientation")), pitch, 1e-3);
    } else {
      const double a = kGravityMps2 * (std::sin(pitch) - mu * std::cos(pitch));
      // Down the slope (-x); the acceleration along it over 0.8 s.
      const double measured = -(v[0] - v_start) / std::cos(pitch) / 0.8;
      std::printf("incline 20 deg, mu %.2f: a = %.4f m/s^2 (Coulomb %.4f)\n", mu, measured, a);
      EXPECT_NEAR(measured, a, 0.02 * a);
      EXPECT_NEAR(v[1], 0.0, 1e-6);
    }
  }
}

// Guards against a payload without a box (a point mass, as README's
// robot.payload documents it: the box is optional) being built with an
// inertia ODE refuses: dMassSetParameters with a zero inertia printed ODE's
// "inertia must be positive definite" while the run went on. The point mass
// must still weigh and sit where it is given: braked on the incline of 20
// deg with mu 0.25 the robot slides down with a = g (sin p - mu cos p) =
// 1.050 m/s^2 (Coulomb, whatever the mass and its distribution, as above).
TEST(Terrain, PointMassPayloadIsAValidBody) {
  const double pitch = 20.0 * kPi / 180.0;
  const double mu = 0.25;
  auto robot = HuskyWithArm(Incline(pitch, mu));
  ChassisUnit& u = *robot;
  test_robots::Set(u, "payload_size", std::vector<double>{0.0, 0.0, 0.0});
  testing::internal::CaptureStderr();
  u.Initialize();
  u.variables().SetBoolean(*u.variables().Find("brake"), true);
  TimeNs t = 0;
  double v_start = 0.0;
  for (int i = 1; i <= 1000; ++i) {
    StepOk(u, t);
    if (i == 200) v_start = Get(u, "velocity_3d")[0];
  }
  const std::string printed = testing::internal::GetCapturedStderr();
  EXPECT_EQ(printed.find("positive definite"), std::string::npos) << printed;
  const double a = kGravityMps2 * (std::sin(pitch) - mu * std::cos(pitch));
  const double measured = -(Get(u, "velocity_3d")[0] - v_start) / std::cos(pitch) / 0.8;
  EXPECT_NEAR(measured, a, 0.02 * a);
}

// Guards against a robot built sunk into a terrain piece's side (the
// contacts would throw it out): refused, naming the piece.
TEST(Terrain, StartAgainstAPiecesSideIsRefused) {
  models::Scene s = Floor(0.8);
  models::TerrainPiece block;
  block.name = "block";
  block.length_m = block.width_m = block.thickness_m = 1.0;
  // Its -x face at x = 0.35: the front wheels (x = 0.256, r 0.1651) 6.6 cm in.
  block.center_x_m = 0.85;
  block.center_z_m = 0.5;
  s.terrain.push_back(block);
  auto robot = Husky(s);
  try {
    robot->Initialize();
    FAIL() << "Initialize accepted a wheel 6.6 cm into a terrain piece";
  } catch (const cosim::UnitError& e) {
    EXPECT_NE(std::string(e.what()).find("deep in terrain piece 'block'"), std::string::npos)
        << e.what();
  }
}

// Guards the body's collision with terrain (a belly or bumper meeting a
// piece the wheels pass beside): a Husky driven at 0.3 m/s towards a beam
// 0.2 m high and 0.3 m wide on its centre line (its wheels, inner faces at
// |y| = 0.2854 - 0.1143 / 2 = 0.228 m, pass either side) stops with its body
// box's front face (x + 0.9874 / 2) on the beam's near face (x = 1.2), to
// the contact springs (the traction, at most mu m g = 490 N, over the
// face's contact points of 1e6 N/m: below 0.5 mm; 2 mm tolerance).
TEST(Terrain, BodyStopsAtABeamTheWheelsStraddle) {
  models::Scene s = Floor(kHuskyMu);
  models::TerrainPiece beam;
  beam.name = "beam";
  beam.length_m = 0.6;
  beam.width_m = 0.3;
  beam.thickness_m = 0.2;
  beam.center_x_m = 1.5;
  beam.center_z_m = 0.1;
  s.terrain.push_back(beam);
  auto robot = Husky(s);
  ChassisUnit& u = *robot;
  u.Initialize();
  SpeedLoop loop;
  TimeNs t = 0;
  bool wheel_on_beam = false;
  for (int i = 0; i < 5000; ++i) {
    loop.Step(u, 0.3 / kHuskyWheelRadiusM);
    StepOk(u, t);
    for (double w : Get(u, "wheel_surface")) wheel_on_beam = wheel_on_beam || w == 1.0;
  }
  EXPECT_FALSE(wheel_on_beam);
  EXPECT_NEAR(Get(u, "position")[0] + 0.5 * kHuskyBodyM[0], 1.2, 2e-3);
  EXPECT_NEAR(Get(u, "velocity_3d")[0], 0.0, 1e-3);
}

// The van bay scene as the loader reads it.
models::Scene VanBay() {
  return loader::LoadSceneFile(
      (std::filesystem::path(models::ModelsDir()) / "scenes" / "van_bay.yaml").string());
}

// Husky drive numbers from models/motors/husky_drive.yaml (the maxon RE 40
// 148877 stand-in and the Husky's gear): torque per ampere at the wheel
// eta N k_t.
struct Drive {
  double amps_per_nm = 0.0;  // 1 / (eta N k_t)
  double resistance_ohm = 0.0;
};
Drive HuskyDrive() {
  const YAML::Node m = YAML::LoadFile(
      (std::filesystem::path(models::ModelsDir()) / "motors" / "husky_drive.yaml").string());
  const double kt = m["torque_constant"].as<double>();
  const double n = m["gear_ratio"].as<double>();
  const double eta = m["gear_efficiency"].as<double>();
  return {1.0 / (eta * n * kt), m["resistance"].as<double>()};
}

// Guards paper 2's van entry in the physics: a Husky with its arm (87.7 kg)
// driven at 0.3 m/s (drive rate 0.3 / 0.1651 = 1.817 rad/s, the test's PI
// on the wheel torques) from x = 1 up the van bay's ramp (15.11 deg,
// aluminium tread, mu 0.6) to the work pose x = 5.9 on the van floor.
// Expected, analytic:
// - with all four wheels on the ramp its nose is up by the ramp's angle
//   atan(0.54 / 2.0) = 15.11 deg, to the contact springs' 5.7e-4 rad (as
//   in BrakedHuskyWithArmOnAnInclineIsCoulomb at 15 deg: less); 1e-3 rad;
// - it never rolls back (mu 0.6 > tan 15.11 deg = 0.27);
// - at the end base_link's origin is on the van floor, z = 0.54, lifted by
//   half the 6 mm bump under its right wheels (van_bay's floor_bump, which
//   the scene ships sunk mid-van: this test raises it to 6 mm and moves it
//   under the work pose, x 5.5..6.3), and
//   rolled right by atan(0.006 / 0.5708) = 0.0105 rad; the contacts sink
//   by m g / 4 k = 0.2 mm: 0.3 mm and 5e-4 rad tolerances;
// - climbing at constant speed each drive motor supplies half of
//   m g sin(p) r = 87.7 x 9.807 x 0.2607 x 0.1651 = 37.0 N.m at its two
//   wheels: 18.5 N.m, i.e. 18.5 / (eta N k_t) = 18.5 / 1.670 = 11.1 A.
// The motor's ratings (maxon RE 40, the 150 W frame of the 148877 stand-in;
// maxon data sheet of its 48 V winding: max. continuous torque 187 mNm,
// thermal time constant of the winding 41.5 s, thermal resistances 4.65 and
// 1.93 K/W): the continuous torque is the frame's thermal limit, so the
// 24 V winding's nominal (max. continuous) current is 187 / 30.2 + 0.137 =
// 6.33 A (the same rule gives the 48 V winding's listed 3.17 A); stall
// current U / R = 24 / 0.299 = 80.3 A. A climb above the nominal current
// is allowed for a while: a winding of time constant tau heats towards
// (I / I_N)^2 times its allowed rise, reaching the allowed rise after
// t = tau ln(I^2 / (I^2 - I_N^2)) (first-order thermal model, from cold).
TEST(Terrain, HuskyWithArmClimbsTheVanRamp) {
  models::Scene scene = VanBay();
  ASSERT_EQ(scene.terrain.size(), 3u);
  ASSERT_EQ(scene.terrain[0].name, "ramp");
  ASSERT_EQ(scene.terrain[1].name, "van_floor");
  ASSERT_EQ(scene.terrain[2].name, "floor_bump");
  scene.terrain[2].center_x_m = 5.9;
  scene.terrain[2].center_z_m = 0.536;  // its top 6 mm above the floor
  const double ramp = std::atan(0.54 / 2.0);
  EXPECT_NEAR(scene.terrain[0].pitch_rad, ramp, 1e-8);
  auto robot = HuskyWithArm(scene);
  ChassisUnit& u = *robot;
  test_robots::Set(u, "initial_x", 1.0);
  u.Initialize();
  EXPECT_NEAR(Get(u, "position_3d")[2], 0.0, 3e-4);
  const Drive drive = HuskyDrive();
  const double nominal_a = 0.187 / 0.0302 + 0.137;
  const double stall_a = 24.0 / drive.resistance_ohm;
  const double tau_winding_s = 41.5;
  const double m = kHuskyMassKg + kArmPayloadMassKg;
  const double climb_a =
      m * kGravityMps2 * std::sin(ramp) * kHuskyWheelRadiusM / 2.0 * drive.amps_per_nm;

  SpeedLoop loop;
  const double rate = 0.3 / kHuskyWheelRadiusM;
  TimeNs t = 0;
  double max_x = -1e9, worst_rollback = 0.0, worst_pitch = 0.0;
  int all_on_ramp = 0;
  // Currents while any wheel is on the ramp (the climb), and while all four
  // are (steady climbing).
  double sum_sq = 0.0, peak = 0.0, steady_sum = 0.0;
  int climb_steps = 0, steady_steps = 0;
  bool arrived = false;
  int stopped_steps = 0;
  for (int i = 0; i < 30000 && stopped_steps < 1000; ++i) {
    const double x = Get(u, "position")[0];
    arrived = arrived || x >= 5.9;
    loop.Step(u, arrived ? 0.0 : rate);
    StepOk(u, t);
    const auto p = Get(u, "position");
    max_x = std::max(max_x, p[0]);
    const auto surface = Get(u, "wheel_surface");
    const bool any_ramp = std::count(surface.begin(), surface.end(), 1.0) > 0;
    // Every wheel on the ramp's face, away from its edges (a wheel over an
    // edge touches both sides of it).
    const auto contact = Get(u, "wheel_contact");
    bool all_ramp = true;
    for (std::size_t k = 0; k < 4; ++k) {
      all_ramp = all_ramp && surface[k] == 1.0 && contact[2 * k] > 2.1 && contact[2 * k] < 3.9;
    }
    if (any_ramp) {
      worst_rollback = std::max(worst_rollback, max_x - p[0]);
      for (double tau : loop.torque) {
        const double amps = std::abs(tau) * drive.amps_per_nm;
        sum_sq += amps * amps;
        peak = std::max(peak, amps);
      }
      climb_steps += 2;
    }
    if (all_ramp) {
      ++all_on_ramp;
      worst_pitch = std::max(worst_pitch, std::abs(NoseUp(Get(u, "orientation")) - ramp));
      for (double tau : loop.torque) steady_sum += tau * drive.amps_per_nm;
      steady_steps += 2;
    }
    if (arrived && std::abs(Get(u, "velocity_3d")[0]) < 1e-3) ++stopped_steps;
  }
  ASSERT_TRUE(arrived);
  // All four wheels on the ramp's face for (2.0716 - 0.2 - 0.512) / 0.3 =
  // 4.5 s (their contacts 0.1 m from its edges).
  EXPECT_GT(all_on_ramp, 4400);
  EXPECT_LT(worst_pitch, 1e-3);
  EXPECT_LT(worst_rollback, 1e-3);
  // At rest on the van floor: left wheels on van_floor (terrain 1: surface
  // 2), right wheels on floor_bump (terrain 2: surface 3).
  EXPECT_EQ(Get(u, "wheel_surface"), (std::vector<double>{2.0, 2.0, 3.0, 3.0}));
  const auto p3 = Get(u, "position_3d");
  EXPECT_NEAR(p3[2], 0.54 + 0.003, 3e-4);
  EXPECT_NEAR(Roll(Get(u, "orientation")), -std::atan(0.006 / (2.0 * kHuskyHalfTrackM)), 5e-4);
  EXPECT_NEAR(NoseUp(Get(u, "orientation")), 0.0, 5e-4);
  // Stopped at the work pose (the test's PI stops it from 0.3 m/s there).
  EXPECT_NEAR(p3[0], 5.9, 0.05);
  // Currents.
  const double steady = steady_sum / steady_steps;
  const double rms = std::sqrt(sum_sq / climb_steps);
  const double climb_s = 0.5 * climb_steps * kH;
  const double allowed_s = tau_winding_s * std::log(rms * rms / (rms * rms - nominal_a * nominal_a));
  std::printf(
      "climb: %.2f s; current per motor: steady %.2f A (analytic %.2f A), RMS %.2f A, peak "
      "%.2f A; nominal %.2f A, stall %.1f A; RMS allowed for %.1f s from cold\n",
      climb_s, steady, climb_a, rms, peak, nominal_a, stall_a, allowed_s);
  std::printf(
      "pitch on the ramp: worst error %.2e rad; worst roll-back %.2e m; end z %.5f m, "
      "roll %.5f rad, x %.4f m\n",
      worst_pitch, worst_rollback, p3[2], Roll(Get(u, "orientation")), p3[0]);
  EXPECT_NEAR(steady, climb_a, 0.03 * climb_a);
  EXPECT_LT(peak, stall_a);
  // Above the nominal current, but for less time than the winding takes to
  // reach its limit.
  EXPECT_GT(rms, nominal_a);
  EXPECT_LT(climb_s, allowed_s);
}

// Guards against state of the terrain contacts that a save misses: a climb
// saved on the ramp and restored (in itself and in a fresh unit) continues
// bit for bit.
TEST(Terrain, SaveRestoreOnTheRampIsBitForBit) {
  const models::Scene scene = VanBay();
  const double rate = 0.3 / kHuskyWheelRadiusM;
  const auto run = [&](ChassisUnit& u, TimeNs& t, int steps, SpeedLoop* loop) {
    for (int i = 0; i < steps; ++i) {
      loop->Step(u, rate);
      StepOk(u, t);
    }
  };
  auto robot = HuskyWithArm(scene);
  ChassisUnit& u = *robot;
  test_robots::Set(u, "initial_x", 1.2);
  u.Initialize();
  SpeedLoop loop;
  TimeNs t = 0;
  run(u, t, 3500, &loop);  // front wheels on the ramp
  ASSERT_EQ(Get(u, "wheel_surface")[0], 1.0);
  const cosim::UnitState saved = u.SaveState();
  const SpeedLoop loop_saved = loop;
  const TimeNs t_saved = t;
  run(u, t, 500, &loop);
  const auto first = test_helpers::Outputs(u);
  u.RestoreState(saved);
  loop = loop_saved;
  t = t_saved;
  run(u, t, 500, &loop);
  EXPECT_TRUE(test_helpers::SameBits(test_helpers::Outputs(u), first));
  auto fresh = HuskyWithArm(scene);
  test_robots::Set(*fresh, "initial_x", 1.2);
  fresh->RestoreState(saved);
  loop = loop_saved;
  t = t_saved;
  run(*fresh, t, 500, &loop);
  EXPECT_TRUE(test_helpers::SameBits(test_helpers::Outputs(*fresh), first));
}

}  // namespace
}  // namespace linesim::chassis
