// A laser scanner sees moving cylinders (workers' legs) where their
// velocity takes them at each beam's time.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <string>

#include "tests/units/test_helpers.h"
#include "units/sensors/laser_scanner_unit.h"

namespace linesim::sensors {
namespace {

using cosim::TimeNs;
using test_helpers::Get;
using test_helpers::SetAll;
using test_helpers::SetArray;

constexpr TimeNs kMs = 1'000'000;
constexpr double kDeg = std::numbers::pi / 180.0;
// Half the S300's 1 cm range step (8010948), plus rounding.
constexpr double kHalfStep = 0.005 + 1e-9;

// The S300 of models/sensors/sick_s300.yaml, exact (no noise, one ray per
// beam), with `cylinders` moving cylinders.
std::unique_ptr<LaserScannerUnit> S300(const models::Scene& scene, int cylinders, int boxes = 0) {
  const YAML::Node m =
      YAML::LoadFile(std::string(LINESIM_SOURCE_DIR) + "/models/sensors/sick_s300.yaml");
  auto u = std::make_unique<LaserScannerUnit>("laser", scene, m["beam_count"].as<int>(),
                                              std::vector<std::array<double, 2>>{}, 1, cylinders,
                                              boxes);
  for (const auto& kv : m) {
    const std::string key = kv.first.as<std::string>();
    if (key == "beam_count" || key == "protective_field" || key == "source" ||
        key == "description" || key == "multiple_sampling") {
      continue;
    }
    SetAll(*u, key, kv.second.as<double>());
  }
  SetAll(*u, "noise_sigma", 0.0);
  SetAll(*u, "spot_divergence", 0.0);
  SetAll(*u, "spot_offset", 0.0);
  SetAll(*u, "mount_z", 0.18);  // the Rob@Work 3's S300 height (models/robots/raw3.yaml)
  return u;
}

// Range of a ray from the origin at angle a to a circle of radius r centred
// at (cx, cy): the nearer root of |t (cos a, sin a) - c| = r; NaN if none.
double CircleRange(double a, double cx, double cy, double r) {
  const double b = cx * std::cos(a) + cy * std::sin(a);
  const double disc = b * b - (cx * cx + cy * cy - r * r);
  return disc < 0.0 ? std::nan("") : b - std::sqrt(disc);
}

double BeamAngle(int i) { return -135.0 * kDeg + i * 0.5 * kDeg; }
// Beam i's time after its scan's start: i * 0.5 deg / 360 deg * 40 ms.
double BeamTime(int i) { return i * 0.5 / 360.0 * 0.04; }

// Guards against a leg that is not seen, or seen at the wrong place: a
// still leg (radius 0.04 m) at (2, 0.01): every beam within 1.5 deg of it
// reads the circle's analytic range (to the S300's 1 cm step), the others
// nothing (an open floor).
TEST(LaserMoving, StillLegGivesTheAnalyticRange) {
  auto u = S300(models::OpenFloor(), 3);
  std::vector<double> cyl(21, 0.0);
  const double leg[7] = {2.0, 0.01, 0.0, 0.0, 0.04, 0.0, 0.84};
  std::copy(leg, leg + 7, cyl.begin());
  // The other two far away (a second leg and the torso out of reach).
  const double away[7] = {-50.0, 0.0, 0.0, 0.0, 0.04, 0.0, 0.84};
  std::copy(away, away + 7, cyl.begin() + 7);
  std::copy(away, away + 7, cyl.begin() + 14);
  SetArray(*u, "moving_cylinders", cyl);
  u->Setup(0, 1000 * kMs);
  u->Initialize();
  ASSERT_EQ(u->DoStep(0, 40 * kMs), cosim::StepResult::kOk) << u->last_error();
  ASSERT_EQ(Get(*u, "scan_count")[0], 1.0);
  const auto r = Get(*u, "ranges");
  int hits = 0;
  for (int i = 0; i < 541; ++i) {
    const double expected = CircleRange(BeamAngle(i), 2.0, 0.01, 0.04);
    if (std::isnan(expected)) {
      EXPECT_EQ(r[static_cast<std::size_t>(i)], 0.0) << "beam " << i;
    } else {
      ++hits;
      EXPECT_NEAR(r[static_cast<std::size_t>(i)], expected, kHalfStep) << "beam " << i;
    }
  }
  // 0.08 m wide at 2 m: 2 atan(0.04 / 2) = 2.3 deg, 4 or 5 beams.
  EXPECT_GE(hits, 4);
  EXPECT_LE(hits, 5);
}

// Guards against moving objects taken where they were at the step's start:
// one 40 ms step casts the whole scan from inputs at t = 0, with a leg at
// x = 2 walking towards the scanner at 1.4 m/s (Perry & Burnfield 2010's
// free walking). Beam i must see it at 2 - 1.4 t_i: beam 270 (t = 15 ms)
// at 1.979 - 0.04 = 1.939 m, not the 1.96 m of the start.
TEST(LaserMoving, MovingLegSeenAtTheBeamsTime) {
  auto u = S300(models::OpenFloor(), 1);
  SetArray(*u, "moving_cylinders", {2.0, 0.0, -1.4, 0.0, 0.04, 0.0, 0.84});
  u->Setup(0, 1000 * kMs);
  u->Initialize();
  ASSERT_EQ(u->DoStep(0, 40 * kMs), cosim::StepResult::kOk) << u->last_error();
  const auto r = Get(*u, "ranges");
  for (int i = 265; i <= 275; ++i) {
    const double expected = CircleRange(BeamAngle(i), 2.0 - 1.4 * BeamTime(i), 0.0, 0.04);
    if (std::isnan(expected)) continue;
    EXPECT_NEAR(r[static_cast<std::size_t>(i)], expected, kHalfStep) << "beam " << i;
  }
  EXPECT_NEAR(r[270], 1.94, 1e-9);
}

// Guards against other robots not seen, or seen where they were at the
// step's start: another Rob@Work 3's body (1.03 x 0.57 m, 0 to 0.4 m high,
// paper 1 Table I) centred 2 m ahead, coming at 1 m/s, and a second robot
// box that is absent (length 0). Beam 270 (straight ahead, t = 15 ms) sees
// the front face at 2 - 0.515 - 1.0 x 0.015 = 1.47 m; a beam 20 deg off
// sees the face's plane at 1.485 / cos 20 deg less the motion, or passes
// the box (its half width 0.285 m at 1.485 m is 10.9 deg): nothing there.
TEST(LaserMoving, OtherRobotSeenAtTheBeamsTime) {
  auto u = S300(models::OpenFloor(), 0, 2);
  SetArray(*u, "moving_boxes", {2.0, 0.0, 0.0, -1.0, 0.0, 0.0, 1.03, 0.57, 0.0, 0.4,  //
                                0.7, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.4});
  u->Setup(0, 1000 * kMs);
  u->Initialize();
  ASSERT_EQ(u->DoStep(0, 40 * kMs), cosim::StepResult::kOk) << u->last_error();
  const auto r = Get(*u, "ranges");
  for (int i = 250; i <= 290; ++i) {
    const double a = BeamAngle(i);
    const double face = 2.0 - 0.515 - 1.0 * BeamTime(i);
    const double y = face * std::tan(a);
    if (std::abs(y) < 0.285 - 0.01) {
      EXPECT_NEAR(r[static_cast<std::size_t>(i)], face / std::cos(a), kHalfStep) << "beam " << i;
    } else if (std::abs(y) > 0.285 + 0.01) {
      EXPECT_EQ(r[static_cast<std::size_t>(i)], 0.0) << "beam " << i;
    }
  }
  EXPECT_NEAR(r[270], 1.47, 1e-9);
  // As the scanner's own robot (own_box), the box is not seen.
  u->variables().SetInteger(*u->variables().Find("own_box"), 0);
  ASSERT_EQ(u->DoStep(40 * kMs, 40 * kMs), cosim::StepResult::kOk) << u->last_error();
  EXPECT_EQ(Get(*u, "ranges")[270], 0.0);
  u->variables().SetInteger(*u->variables().Find("own_box"), -1);
  // Lifted above the scanner's 0.18 m, the body is not seen.
  SetArray(*u, "moving_boxes", {2.0, 0.0, 0.0, -1.0, 0.0, 0.0, 1.03, 0.57, 0.2, 0.6,  //
                                0.7, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.4});
  ASSERT_EQ(u->DoStep(80 * kMs, 40 * kMs), cosim::StepResult::kOk) << u->last_error();
  EXPECT_EQ(Get(*u, "ranges")[270], 0.0);
}

// Guards against moving cylinders changing anything when there are none:
// without the structural key the unit has no such input.
TEST(LaserMoving, NoInputWithoutCylinders) {
  auto u = S300(models::OpenFloor(), 0);
  EXPECT_FALSE(u->variables().Find("moving_cylinders").has_value());
  EXPECT_FALSE(u->variables().Find("moving_boxes").has_value());
}

}  // namespace
}  // namespace linesim::sensors
