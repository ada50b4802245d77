#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "models/angle.h"
#include "tests/spread.h"
#include "tests/units/test_helpers.h"
#include "units/evaluation/beacon_localization.h"
#include "units/sensors/laser_scanner_unit.h"

namespace linesim::evaluation {
namespace {

using cosim::TimeNs;
using test_helpers::Get;
using test_helpers::SetAll;
using test_helpers::SetArray;

constexpr TimeNs kMs = 1'000'000;
constexpr double kDeg = std::numbers::pi / 180.0;

// ---------------------------------------------------------------------------
// The van bay of paper 2 (Sobreira et al. 2019, Sec. 6.1) as the scenario
// describes it: a Renault Master L2H2 class cargo interior x 4.0..7.1, y
// +-0.8825 (load length 3.1 m, width 1.765 m), its load floor at z 0.54,
// walls from 0.30 to 2.44, the rear door open at x 4.0; four beacons of
// radius 0.04 m from the floor 0.8 m high at (6.0, +-0.75), (6.95, +-0.75).
constexpr double kFloor = 0.54;
constexpr double kBeaconX[4] = {6.0, 6.0, 6.95, 6.95};
constexpr double kBeaconY[4] = {0.75, -0.75, 0.75, -0.75};

models::Scene Van(const std::vector<int>& beacons = {0, 1, 2, 3}) {
  models::Scene s = models::OpenFloor();
  const double wall = 0.05, half_width = 0.8825, bottom = 0.30, top = 2.44;
  s.obstacles.push_back({"van_left", "vehicle",
                         models::BoxSolid(5.55, half_width + 0.5 * wall, 0.0, 3.1, wall,
                                          top - bottom, bottom)});
  s.obstacles.push_back({"van_right", "vehicle",
                         models::BoxSolid(5.55, -half_width - 0.5 * wall, 0.0, 3.1, wall,
                                          top - bottom, bottom)});
  s.obstacles.push_back({"van_front", "vehicle",
                         models::BoxSolid(7.1 + 0.5 * wall, 0.0, 0.0, wall, 2 * half_width + 2 * wall,
                                          top - bottom, bottom)});
  for (int j : beacons) {
    s.obstacles.push_back({"beacon_" + std::to_string(j), "beacon",
                           models::CylinderSolid(kBeaconX[j], kBeaconY[j], 0.04, 0.8, kFloor)});
  }
  return s;
}

std::vector<BeaconLocalizationUnit::Beacon> KnownBeacons() {
  std::vector<BeaconLocalizationUnit::Beacon> b;
  for (int j = 0; j < 4; ++j) b.push_back({kBeaconX[j], kBeaconY[j], 0.04});
  return b;
}

// The LMS151 on the Husky: base_link (0.45, 0, 0.35) (models/robots/husky.yaml),
// base_link on the van floor: the scan plane at 0.89 m.
constexpr double kMountX = 0.45, kMountZ = 0.35;

// models/sensors/sick_lms151.yaml into a real scanner: every key but the
// structural and descriptive ones as a parameter.
std::unique_ptr<sensors::LaserScannerUnit> Lms151(const models::Scene& scene, std::uint64_t seed) {
  const YAML::Node m =
      YAML::LoadFile(std::string(LINESIM_SOURCE_DIR) + "/models/sensors/sick_lms151.yaml");
  auto u = std::make_unique<sensors::LaserScannerUnit>(
      "laser", scene, m["beam_count"].as<int>(), std::vector<std::array<double, 2>>{}, seed);
  for (const auto& kv : m) {
    const std::string key = kv.first.as<std::string>();
    if (key == "beam_count" || key == "source" || key == "description") continue;
    const auto ref = u->variables().Find(key);
    EXPECT_TRUE(ref.has_value()) << key;
    if (ref) u->variables().SetReal(*ref, kv.second.as<double>());
  }
  SetAll(*u, "mount_x", kMountX);
  SetAll(*u, "mount_z", kMountZ);
  return u;
}

std::unique_ptr<BeaconLocalizationUnit> Beacons(std::vector<BeaconLocalizationUnit::Beacon> b =
                                                    KnownBeacons()) {
  auto u = std::make_unique<BeaconLocalizationUnit>("beacons", std::move(b), 541);
  SetAll(*u, "mount_x", kMountX);
  SetAll(*u, "mount_y", 0.0);
  SetAll(*u, "mount_yaw", 0.0);
  SetAll(*u, "first_beam_angle", -135.0 * kDeg);  // LMS151 (SICK 8012471)
  SetAll(*u, "angular_step", 0.5 * kDeg);
  SetAll(*u, "uncover_delay", 0.0);  // the robot stands from the start
  return u;
}

struct Pose {
  double x, y, yaw;
};

// The robot standing at `p` on the van floor.
void Place(sensors::LaserScannerUnit& laser, const Pose& p) {
  SetArray(laser, "position_3d", {p.x, p.y, kFloor});
  SetArray(laser, "orientation", {std::cos(0.5 * p.yaw), 0.0, 0.0, std::sin(0.5 * p.yaw)});
  SetArray(laser, "velocity_3d", {0.0, 0.0, 0.0});
  SetArray(laser, "angular_velocity", {0.0, 0.0, 0.0});
}

// Laser and beacon localization stepped together as the master does (the
// laser's outputs at t + dt are the localization's inputs of the next step).
struct Rig {
  std::unique_ptr<sensors::LaserScannerUnit> laser;
  std::unique_ptr<BeaconLocalizationUnit> loc;
  TimeNs t = 0;

  Rig(const models::Scene& scene, std::uint64_t seed, const Pose& p,
      std::unique_ptr<BeaconLocalizationUnit> l = Beacons())
      : laser(Lms151(scene, seed)), loc(std::move(l)) {
    Place(*laser, p);
    laser->Setup(0, 1'000'000 * kMs);
    laser->Initialize();
    loc->Setup(0, 1'000'000 * kMs);
    Connect();
    loc->Initialize();
  }
  void Connect() {
    SetArray(*loc, "ranges", Get(*laser, "ranges"));
    SetAll(*loc, "scan_count", Get(*laser, "scan_count")[0]);
    SetAll(*loc, "scan_time", Get(*laser, "scan_time")[0]);
  }
  void SetActive(bool a) {
    loc->variables().SetBoolean(*loc->variables().Find("active"), a);
  }
  // Steps of 5 ms until `scans` more scans were processed by the localization.
  void Run(int scans) {
    const double target = Get(*laser, "scan_count")[0] + scans;
    while (Get(*laser, "scan_count")[0] < target) Step();
    Step();  // the localization takes the last scan
  }
  void Step() {
    constexpr TimeNs dt = 5 * kMs;
    ASSERT_EQ(laser->DoStep(t, dt), cosim::StepResult::kOk) << laser->last_error();
    ASSERT_EQ(loc->DoStep(t, dt), cosim::StepResult::kOk) << loc->last_error();
    t += dt;
    Connect();
  }
  bool valid() const { return loc->variables().GetBoolean(*loc->variables().Find("valid")); }
  std::int64_t seen() const {
    return loc->variables().GetInteger(*loc->variables().Find("beacons_seen"));
  }
  std::int64_t used() const {
    return loc->variables().GetInteger(*loc->variables().Find("scans_used"));
  }
  Pose pose() const {
    const auto p = Get(*loc, "position");
    return {p[0], p[1], Get(*loc, "yaw")[0]};
  }
};

// e^T C^-1 e for a row-major 3 x 3 covariance C.
double Mahalanobis3(const std::vector<double>& c, double ex, double ey, double et) {
  const double a = c[0], b = c[1], d = c[2], e = c[4], f = c[5], g = c[8];
  const double c00 = e * g - f * f, c01 = d * f - b * g, c02 = b * f - d * e;
  const double det = a * c00 + b * c01 + d * c02;
  const double i00 = c00 / det, i01 = c01 / det, i02 = c02 / det;
  const double i11 = (a * g - d * d) / det, i12 = (b * d - a * f) / det,
               i22 = (a * e - b * b) / det;
  return i00 * ex * ex + i11 * ey * ey + i22 * et * et + 2 * i01 * ex * ey + 2 * i02 * ex * et +
         2 * i12 * ey * et;
}

double PositionError(const Pose& a, const Pose& b) { return std::hypot(a.x - b.x, a.y - b.y); }
double YawError(const Pose& a, const Pose& b) { return models::WrapAngle(a.yaw - b.yaw); }

// ---------------------------------------------------------------------------

// Guards detection and association: from the work pose (5.9, 0, 0) the
// LMS151 (full noise, bias, spot and mixed pixels) sees all four beacons;
// each fitted centre, put into the map by the true laser pose, lies on its
// beacon within the LMS151's maximum systematic error (40 mm, SICK
// 8012471) plus 3 sigma of the fit, and the first scan already starts the
// filter (geometry, no prior).
TEST(BeaconLocalization, DetectsAllFourBeacons) {
  const Pose truth{5.9, 0.0, 0.0};
  Rig rig(Van(), 7, truth);
  rig.Run(1);
  EXPECT_TRUE(rig.valid());
  EXPECT_EQ(rig.seen(), 4);
  EXPECT_TRUE(rig.loc->started());
  std::vector<int> found(4, 0);
  for (int k = 0; k < rig.loc->detection_count(); ++k) {
    const auto& d = rig.loc->detections()[static_cast<std::size_t>(k)];
    if (d.beacon < 0) continue;
    ASSERT_LT(d.beacon, 4);
    ++found[static_cast<std::size_t>(d.beacon)];
    const double mx = truth.x + kMountX + d.x, my = truth.y + d.y;
    const double sigma = std::sqrt(std::max(d.cxx, d.cyy));
    EXPECT_LT(std::hypot(mx - kBeaconX[d.beacon], my - kBeaconY[d.beacon]), 0.04 + 3 * sigma)
        << "beacon " << d.beacon;
    // A 4 cm beacon at 0.8-1 m spans 4.6-5.7 deg: 9-11 LMS151 beams, less
    // the two trimmed silhouette beams.
    EXPECT_GE(d.points, 5) << "beacon " << d.beacon;
    EXPECT_LE(d.rms, 0.03) << "beacon " << d.beacon;
  }
  EXPECT_EQ(found, (std::vector<int>{1, 1, 1, 1}));
  // The walls are no beacons: every other cluster was refused.
  EXPECT_EQ(rig.loc->detection_count(), 4);
}

// The beacon system's own error over many devices: each seed a new LMS151
// (its per-device bias and its noise), the robot standing for 1 s (50
// scans) at the work pose and at other poses inside the van.
//
// Bound (from the LMS151's figures, SICK 8012471): each fitted centre
// carries the statistical error (12 mm per beam), averaged over the scans
// and beacons, and the device's systematic error (+-30 mm typical), which
// no averaging over scans removes; over the four beacons it averages down
// at most as an independent error would, to 30 mm / sqrt(4) = 15 mm (a
// common range offset moves every centre along its own line of sight, and
// the lines of sight of beacons around the laser cancel in part). RMS
// position error <= 12 mm / sqrt(50 x 4) + 15 mm; RMS yaw error <= that
// over the beacons' lever about the laser (>= 0.6 m at these poses).
// Paper 2 states 5 mm and 0.2 deg for the real system: the measured
// numbers are printed beside. 30 seeds (devices) per pose, 120 in all:
// position error 0.0001 / 0.0011 / 0.0078 m, |yaw error| 0.0004 / 0.019 /
// 0.136 deg; each pose's RMS over its bound 0.004 / 0.056 / 0.169 (position
// and yaw, 8 values); mean NEES 4.0 against the 6 asked.
TEST(BeaconLocalization, OwnErrorOverSeedsWithinTheLms151Figures) {
  const std::vector<Pose> poses = {
      {5.9, 0.0, 0.0}, {5.6, 0.1, 0.1}, {5.9, -0.15, -0.08}, {5.45, 0.0, 0.05}};
  constexpr int kSeeds = 30;
  const double stat = 0.012 / std::sqrt(50.0 * 4.0), sys = 0.030 / std::sqrt(4.0);
  const double position_bound = stat + sys;
  const double yaw_bound = position_bound / 0.6;
  double all_sq = 0.0, all_yaw_sq = 0.0, all_max = 0.0, all_yaw_max = 0.0, all_sum = 0.0,
         all_yaw_sum = 0.0;
  int all_n = 0;
  double nees_sum = 0.0, beacons_sum = 0.0;
  int nees_n = 0;
  std::vector<double> position_errors, yaw_errors, rms_ratio;
  for (const Pose& truth : poses) {
    double sum = 0, sq = 0, max = 0, ysum = 0, ysq = 0, ymax = 0;
    for (int s = 0; s < kSeeds; ++s) {
      Rig rig(Van(), 1000 + static_cast<std::uint64_t>(s), truth);
      rig.Run(50);
      ASSERT_TRUE(rig.valid()) << "seed " << s;
      EXPECT_GE(rig.used(), 50);
      const double e = PositionError(rig.pose(), truth);
      const double ye = std::abs(YawError(rig.pose(), truth));
      // The error against the unit's own covariance (x, y, yaw).
      const auto c = Get(*rig.loc, "covariance");
      const double ex = rig.pose().x - truth.x, ey = rig.pose().y - truth.y,
                   et = YawError(rig.pose(), truth);
      nees_sum += Mahalanobis3(c, ex, ey, et);
      ++nees_n;
      beacons_sum += static_cast<double>(rig.seen());
      position_errors.push_back(e);
      yaw_errors.push_back(ye / kDeg);
      sum += e;
      sq += e * e;
      max = std::max(max, e);
      ysum += ye;
      ysq += ye * ye;
      ymax = std::max(ymax, ye);
    }
    const double rms = std::sqrt(sq / kSeeds), yrms = std::sqrt(ysq / kSeeds);
    std::printf(
        "pose (%.2f, %.2f, %.1f deg): position error mean %.2f RMS %.2f max %.2f mm; yaw error "
        "mean %.3f RMS %.3f max %.3f deg (paper 2: 5 mm, 0.2 deg)\n",
        truth.x, truth.y, truth.yaw / kDeg, 1e3 * sum / kSeeds, 1e3 * rms, 1e3 * max,
        ysum / kSeeds / kDeg, yrms / kDeg, ymax / kDeg);
    EXPECT_LT(rms, position_bound);
    EXPECT_LT(yrms, yaw_bound);
    rms_ratio.push_back(rms / position_bound);
    rms_ratio.push_back(yrms / yaw_bound);
    all_sq += sq;
    all_yaw_sq += ysq;
    all_sum += sum;
    all_yaw_sum += ysum;
    all_max = std::max(all_max, max);
    all_yaw_max = std::max(all_yaw_max, ymax);
    all_n += kSeeds;
  }
  std::printf(
      "all poses, %d devices: position error mean %.2f RMS %.2f max %.2f mm; yaw error mean "
      "%.3f RMS %.3f max %.3f deg; mean NEES %.2f (3 for a consistent covariance); beacons in "
      "the last scan %.2f of 4\n",
      all_n, 1e3 * all_sum / all_n, 1e3 * std::sqrt(all_sq / all_n), 1e3 * all_max,
      all_yaw_sum / all_n / kDeg, std::sqrt(all_yaw_sq / all_n) / kDeg, all_yaw_max / kDeg,
      nees_sum / nees_n, beacons_sum / nees_n);
  test_spread::Print("position error (m), per device", position_errors);
  test_spread::Print("|yaw error| (deg), per device", yaw_errors);
  test_spread::Print("RMS over 30 devices / bound, per pose (position, yaw)", rms_ratio);
  // The covariance (filter plus the systematic part) is not overconfident:
  // the mean normalized squared error of a 3-DoF estimate is 3 when the
  // covariance is right; below 3 it is conservative (as it should be: it
  // takes the bias at its 15 mm sigma, the drawn ones vary).
  EXPECT_LT(nees_sum / nees_n, 3.0 * 2.0);
}

// Guards the statistical part alone: without the device bias (bias_sigma
// 0) the error after 50 scans is a fraction of the 12 mm per beam.
// Ten seeds (devices): position error 0.00047 / 0.00064 / 0.00085 m, RMS
// 0.65 mm against the 1.28 mm bound.
TEST(BeaconLocalization, WithoutBiasOnlyTheAveragedNoiseRemains) {
  const Pose truth{5.9, 0.0, 0.0};
  double sq = 0, ysq = 0;
  constexpr int kSeeds = 10;
  std::vector<double> errors;
  for (int s = 0; s < kSeeds; ++s) {
    models::Scene scene = Van();
    Rig rig(scene, 2000 + static_cast<std::uint64_t>(s), truth);
    SetAll(*rig.laser, "bias_sigma", 0.0);
    rig.laser->Initialize();
    rig.Run(50);
    ASSERT_TRUE(rig.valid());
    errors.push_back(PositionError(rig.pose(), truth));
    sq += std::pow(PositionError(rig.pose(), truth), 2);
    ysq += std::pow(YawError(rig.pose(), truth), 2);
  }
  const double rms = std::sqrt(sq / kSeeds), yrms = std::sqrt(ysq / kSeeds);
  std::printf("no bias: position RMS %.2f mm, yaw RMS %.3f deg\n", 1e3 * rms, yrms / kDeg);
  test_spread::Print("no bias: position error (m), per device", errors);
  // 12 mm per beam over about 7 fitted beams x 4 beacons x 50 scans: 0.5 mm;
  // a factor 4 for the fit's geometry (less than half the circle seen).
  EXPECT_LT(rms, 4 * 0.012 / std::sqrt(7.0 * 4 * 50));
}

// Guards the association by geometry: the heading hint off by 60 deg, and
// a restart after the robot moved while the beacons were covered (the
// filter's old pose a wrong prior), both give the true pose; a hint off by
// 180 deg gives the half-turn about the rectangle's centre, which the van's
// symmetric layout fits as well (the hint exists for that alone).
TEST(BeaconLocalization, GeometryNeedsNoPrior) {
  const Pose a{5.9, 0.0, 0.0};
  {
    auto l = Beacons();
    SetAll(*l, "heading_hint", 60.0 * kDeg);
    Rig rig(Van(), 11, a, std::move(l));
    rig.Run(1);
    ASSERT_TRUE(rig.valid());
    EXPECT_LT(PositionError(rig.pose(), a), 0.05);
    EXPECT_LT(std::abs(YawError(rig.pose(), a)), 2.0 * kDeg);
  }
  {
    auto l = Beacons();
    SetAll(*l, "heading_hint", 180.0 * kDeg);
    Rig rig(Van(), 11, a, std::move(l));
    rig.Run(1);
    ASSERT_TRUE(rig.valid());
    // The laser at (6.35, 0) turned by pi about (6.475, 0): at (6.6, 0)
    // facing -x, base_link 0.45 behind it at (7.05, 0).
    const Pose half{7.05, 0.0, std::numbers::pi};
    EXPECT_LT(PositionError(rig.pose(), half), 0.05);
    EXPECT_LT(std::abs(YawError(rig.pose(), half)), 2.0 * kDeg);
  }
  {
    Rig rig(Van(), 12, a);
    rig.Run(20);
    ASSERT_TRUE(rig.valid());
    EXPECT_LT(PositionError(rig.pose(), a), 0.02);
    // Covered; the robot moves 0.35 m and turns 8 deg; uncovered again.
    rig.SetActive(false);
    rig.Step();
    EXPECT_FALSE(rig.valid());
    const Pose b{5.55, 0.12, 8.0 * kDeg};
    Place(*rig.laser, b);
    rig.Run(3);  // scans of the moving robot, not processed
    EXPECT_FALSE(rig.valid());
    rig.SetActive(true);
    rig.Run(20);
    ASSERT_TRUE(rig.valid());
    EXPECT_LT(PositionError(rig.pose(), b), 0.02);
    EXPECT_LT(std::abs(YawError(rig.pose(), b)), 1.0 * kDeg);
    EXPECT_LE(rig.used(), 21);  // counted since the new activation
  }
  {
    // Moved 0.3 m while active (the unit assumes a standing robot): the
    // gate refuses every beacon, after valid_scans (5) scans without one
    // the filter restarts from geometry.
    Rig rig(Van(), 13, a);
    rig.Run(10);
    ASSERT_TRUE(rig.valid());
    const Pose c{5.6, -0.05, -5.0 * kDeg};
    Place(*rig.laser, c);
    bool lost = false;
    for (int k = 0; k < 15; ++k) {
      rig.Run(1);
      lost = lost || !rig.valid();
    }
    EXPECT_TRUE(lost);
    ASSERT_TRUE(rig.valid());
    EXPECT_LT(PositionError(rig.pose(), c), 0.02);
    EXPECT_LT(std::abs(YawError(rig.pose(), c)), 1.0 * kDeg);
  }
}

// Guards against distractors: a stray pole of the beacons' radius (4 cm)
// at (6.95, 0.2), not in the beacons' map, and a 10 cm pillar at (6.85,
// -0.3) inside the van. The pole is a candidate but joins no hypothesis
// (no beacon within 0.1 m of it at the right pose) nor passes the gate; the
// pillar is wider than a beacon. The pose comes out right.
TEST(BeaconLocalization, DistractorsAreNotBeacons) {
  const Pose truth{5.9, 0.0, 0.0};
  models::Scene scene = Van();
  scene.obstacles.push_back({"pole", "pillar", models::CylinderSolid(6.95, 0.2, 0.04, 0.8, kFloor)});
  scene.obstacles.push_back(
      {"pillar", "pillar", models::CylinderSolid(6.85, -0.3, 0.1, 0.8, kFloor)});
  Rig rig(scene, 16, truth);
  rig.Run(1);
  ASSERT_TRUE(rig.valid());
  EXPECT_EQ(rig.loc->detection_count(), 5);  // four beacons and the pole
  EXPECT_EQ(rig.seen(), 4);
  EXPECT_LT(PositionError(rig.pose(), truth), 0.02);
  rig.Run(20);
  ASSERT_TRUE(rig.valid());
  EXPECT_EQ(rig.seen(), 4);
  EXPECT_LT(PositionError(rig.pose(), truth), 0.005);
  EXPECT_LT(std::abs(YawError(rig.pose(), truth)), 0.2 * kDeg);
}

// Guards the level-plane assumption: the right wheels on paper 2's floor
// irregularity (a 1 cm bump under the right wheels, 0.5708 m from the left
// ones in models/robots/husky.yaml: roll about
// 1 deg) tilt the scan plane; the beacons are vertical, the pose stays
// within millimetres (cos(1 deg) changes a 1 m range by 0.15 mm).
TEST(BeaconLocalization, RolledByTheFloorBumpStaysWithinMillimetres) {
  const Pose truth{5.9, 0.0, 0.0};
  Rig rig(Van(), 17, truth);
  const double roll = std::asin(0.01 / 0.5708);
  SetArray(*rig.laser, "orientation", {std::cos(0.5 * roll), std::sin(0.5 * roll), 0.0, 0.0});
  rig.Run(50);
  ASSERT_TRUE(rig.valid());
  EXPECT_EQ(rig.seen(), 4);
  EXPECT_LT(PositionError(rig.pose(), truth), 0.005);
  EXPECT_LT(std::abs(YawError(rig.pose(), truth)), 0.2 * kDeg);
}

// Guards `valid`: with two of the four beacons gone from the van (the
// laser sees two), no pose from geometry (it needs three) and not valid.
TEST(BeaconLocalization, FewerThanThreeBeaconsIsNotValid) {
  Rig rig(Van({0, 2}), 13, {5.9, 0.0, 0.0});
  rig.Run(10);
  EXPECT_FALSE(rig.valid());
  EXPECT_FALSE(rig.loc->started());
  EXPECT_LE(rig.seen(), 2);
  EXPECT_EQ(rig.used(), 0);
}

// Guards tracking with too few beacons: started with four, then two are
// knocked over (a new scene for a new laser of the same seed): updates with
// the two it still sees keep the pose, but it is not valid.
TEST(BeaconLocalization, TrackingWithTwoBeaconsIsNotValid) {
  const Pose truth{5.9, 0.0, 0.0};
  Rig rig(Van(), 14, truth);
  rig.Run(10);
  ASSERT_TRUE(rig.valid());
  Rig two(Van({1, 3}), 14, truth);
  // The started filter into the rig that sees two.
  two.loc->RestoreState(rig.loc->SaveState());
  two.Run(10);
  EXPECT_FALSE(two.valid());
  EXPECT_EQ(two.seen(), 2);
  EXPECT_LT(PositionError(two.pose(), truth), 0.03);
}

// Guards uncover_delay: scans that start earlier than 0.3 s after `active`
// rose are not used (15 LMS151 scans of 20 ms), the next ones are.
TEST(BeaconLocalization, ScansBeforeTheUncoverDelayAreNotUsed) {
  auto l = Beacons();
  SetAll(*l, "uncover_delay", 0.3);
  Rig rig(Van(), 15, {5.9, 0.0, 0.0}, std::move(l));
  rig.Run(14);
  EXPECT_EQ(rig.used(), 0);
  EXPECT_FALSE(rig.valid());
  rig.Run(3);
  EXPECT_GE(rig.used(), 1);
  EXPECT_TRUE(rig.valid());
}

// Guards Save/Restore: a restored unit continues bit for bit.
TEST(BeaconLocalization, RestoredUnitContinuesIdentically) {
  const Pose truth{5.9, 0.0, 0.0};
  Rig a(Van(), 21, truth);
  a.Run(5);
  const cosim::UnitState laser_state = a.laser->SaveState();
  const cosim::UnitState loc_state = a.loc->SaveState();
  const TimeNs t = a.t;
  a.Run(10);
  Rig b(Van(), 99, truth);
  b.laser->RestoreState(laser_state);
  b.loc->RestoreState(loc_state);
  b.t = t;
  b.Run(10);
  EXPECT_TRUE(test_helpers::SameBits(Get(*a.loc, "position"), Get(*b.loc, "position")));
  EXPECT_TRUE(test_helpers::SameBits(Get(*a.loc, "yaw"), Get(*b.loc, "yaw")));
  EXPECT_TRUE(test_helpers::SameBits(Get(*a.loc, "covariance"), Get(*b.loc, "covariance")));
  EXPECT_EQ(a.used(), b.used());
}

// Guards the installation's survey: without survey_sigma the filter knows
// the beacons where they stand; with it and an installation_seed, every
// run (whatever its seed) shares one installation's errors; their spread is
// survey_sigma. Over 1000 installations x 4 beacons x 2 coordinates (8000
// draws of N(0, 1) by Box-Muller): the mean within 4 standard errors of 0
// (4 / sqrt(8000) = 0.045) and the rms within 4 standard errors of 1
// (4 / sqrt(2 x 8000) = 0.032). Measured once: mean 0.0019, rms 0.9958.
TEST(BeaconLocalization, SurveyErrorsAreTheInstallations) {
  auto exact = Beacons();
  exact->Initialize();
  for (std::size_t j = 0; j < 4; ++j) {
    EXPECT_EQ(exact->surveyed_beacons()[j].x, kBeaconX[j]);
    EXPECT_EQ(exact->surveyed_beacons()[j].y, kBeaconY[j]);
  }
  const double sigma = 0.0062;
  std::vector<BeaconLocalizationUnit::Beacon> first;
  for (std::uint64_t run = 1; run <= 8; ++run) {
    BeaconLocalizationUnit u("beacons", KnownBeacons(), 541, run);
    for (const char* k : {"mount_x", "mount_y", "mount_yaw", "first_beam_angle"}) SetAll(u, k, 0.0);
    SetAll(u, "angular_step", 0.5 * kDeg);
    SetAll(u, "survey_sigma", sigma);
    u.variables().SetInteger(*u.variables().Find("installation_seed"), 7);
    u.Initialize();
    if (first.empty()) first = u.surveyed_beacons();
    for (std::size_t j = 0; j < 4; ++j) {
      EXPECT_EQ(u.surveyed_beacons()[j].x, first[j].x);
      EXPECT_EQ(u.surveyed_beacons()[j].y, first[j].y);
      EXPECT_NE(u.surveyed_beacons()[j].x, kBeaconX[j]);
    }
  }
  double sum = 0.0, sum_sq = 0.0;
  int n = 0;
  for (std::int64_t installation = 0; installation < 1000; ++installation) {
    BeaconLocalizationUnit u("beacons", KnownBeacons(), 541, 1);
    for (const char* k : {"mount_x", "mount_y", "mount_yaw", "first_beam_angle"}) SetAll(u, k, 0.0);
    SetAll(u, "angular_step", 0.5 * kDeg);
    SetAll(u, "survey_sigma", sigma);
    u.variables().SetInteger(*u.variables().Find("installation_seed"), installation);
    u.Initialize();
    for (std::size_t j = 0; j < 4; ++j) {
      for (const double e : {(u.surveyed_beacons()[j].x - kBeaconX[j]) / sigma,
                             (u.surveyed_beacons()[j].y - kBeaconY[j]) / sigma}) {
        sum += e;
        sum_sq += e * e;
        ++n;
      }
    }
  }
  const double mean = sum / n, rms = std::sqrt(sum_sq / n);
  std::printf("survey errors / sigma over %d draws: mean %.4f, rms %.4f\n", n, mean, rms);
  EXPECT_LT(std::abs(mean), 4.0 / std::sqrt(8000.0));
  EXPECT_NEAR(rms, 1.0, 4.0 / std::sqrt(16000.0));
}

// Guards the parameter checks: too few beacons, beacons of two radii.
TEST(BeaconLocalization, RefusesTooFewOrMixedBeacons) {
  auto b = KnownBeacons();
  b.resize(2);
  auto two = Beacons(b);
  EXPECT_THROW(two->Initialize(), cosim::UnitError);
  auto mixed = KnownBeacons();
  mixed[3].radius = 0.05;
  auto m = Beacons(mixed);
  const auto problems = m->CheckParameters();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].variable, "beacons");
}

}  // namespace
}  // namespace linesim::evaluation
