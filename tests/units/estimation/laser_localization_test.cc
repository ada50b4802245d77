// The laser_localization unit (units/estimation/laser_localization_unit.h),
// driven by hand with synthetic scans of two Rob@Work 3 S300 lasers,
// ray-cast analytically against the test room (scan_matcher_test.cc).
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "config/unit_registry.h"
#include "config/yaml_reader.h"
#include "tests/spread.h"
#include "tests/units/test_helpers.h"
#include "units/estimation/laser_localization_unit.h"

namespace linesim::estimation {

namespace testscene {  // defined in scan_matcher_test.cc
models::Floor RoomFloor();
std::vector<models::Solid> Room();
double Cast(const std::vector<models::Solid>& solids, double x, double y, double heading);
}  // namespace testscene

namespace {

using test_helpers::Get;
using test_helpers::SetAll;
using test_helpers::SetArray;

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr cosim::TimeNs kMs = 1'000'000;
// SICK S300 (operating instructions 8010948): 541 beams, -135 deg, 0.5 deg,
// 40 ms. Rob@Work 3 mounts (raw3-1 calibration, ipa320/cob_robots).
constexpr double kFirst = -135.0 * kDeg, kStep = 0.5 * kDeg, kPeriod = 0.04;
const double kMount[2][4] = {{0.465, -0.232, 0.178, -45.0 * kDeg},
                             {-0.465, 0.232, 0.178, -225.0 * kDeg}};

models::Scene RoomScene() {
  models::Scene s;
  s.floor = testscene::RoomFloor();
  int i = 0;
  for (const auto& solid : testscene::Room()) {
    s.obstacles.push_back({"o" + std::to_string(i++), "wall", solid});
  }
  return s;
}

struct Pose {
  double x, y, yaw;
};

// Truth: a pose as a function of time.
using Trajectory = Pose (*)(double t);
Pose Still(double) { return {1.3, -0.7, 0.4}; }
// 0.3 m/s along x and 0.3 rad/s.
Pose Moving(double t) { return {-1.0 + 0.3 * t, -0.5, 0.2 + 0.3 * t}; }

// Through the room with map: mapping: 0.3 m/s along x over 12 s (3.6 m),
// weaving 0.3 m across and turning +-0.2 rad.
Pose Drive(double t) {
  return {-2.0 + 0.3 * t, -0.5 + 0.3 * std::sin(0.25 * t), 0.2 * std::sin(0.2 * t)};
}

// Laser k's ranges for the scan starting at `start` (each beam from the
// pose at its own time, as the laser_scanner unit times them); no return
// (0) beyond 29.5 m.
std::vector<double> ScanRanges(int k, double start, Trajectory truth,
                               const std::vector<models::Solid>& solids) {
  std::vector<double> r(541, 0.0);
  for (int i = 0; i < 541; ++i) {
    const Pose p = truth(start + i * kStep / (2 * std::numbers::pi) * kPeriod);
    const double c = std::cos(p.yaw), s = std::sin(p.yaw);
    const double ox = p.x + c * kMount[k][0] - s * kMount[k][1];
    const double oy = p.y + s * kMount[k][0] + c * kMount[k][1];
    const double d = testscene::Cast(solids, ox, oy, p.yaw + kMount[k][3] + kFirst + i * kStep);
    r[static_cast<std::size_t>(i)] = d <= 29.5 ? d : 0.0;
  }
  return r;
}

std::unique_ptr<LaserLocalizationUnit> MakeUnit(const models::Scene& scene, Pose initial) {
  auto u = std::make_unique<LaserLocalizationUnit>("loc", scene, std::vector<int>{541, 541});
  auto set2 = [&](const char* key, int j) { SetArray(*u, key, {kMount[0][j], kMount[1][j]}); };
  set2("mount_x", 0);
  set2("mount_y", 1);
  set2("mount_z", 2);
  set2("mount_yaw", 3);
  SetAll(*u, "first_beam_angle", kFirst);
  SetAll(*u, "angular_step", kStep);
  SetAll(*u, "scan_period", kPeriod);
  SetAll(*u, "initial_x", initial.x);
  SetAll(*u, "initial_y", initial.y);
  SetAll(*u, "initial_yaw", initial.yaw);
  return u;
}

// Drives the unit with 20 ms steps: laser 0 completes a scan at every 40 ms,
// laser 1 20 ms later (unsynchronised); `dead[k]` blacks laser k out (all
// ranges 0), `silent[k]` stops its scans.
struct Driver {
  LaserLocalizationUnit& u;
  Trajectory truth;
  std::vector<models::Solid> solids;
  // > 0: Gaussian range noise of this sigma (m), rounded to 1 cm as an S300
  // reports (operating instructions: 1 cm resolution).
  double noise = 0.0;
  std::mt19937_64 rng{3};
  bool dead[2] = {false, false};
  bool silent[2] = {false, false};
  double count[2] = {0, 0};
  cosim::TimeNs t = 0;
  void Step() {
    const cosim::TimeNs end = t + 20 * kMs;
    for (int k = 0; k < 2; ++k) {
      // Scans of laser k start at k * 20 ms + n * 40 ms and complete 40 ms later.
      const cosim::TimeNs phase = k * 20 * kMs;
      if (silent[k] || end < phase + 40 * kMs || (end - phase) % (40 * kMs) != 0) continue;
      const double start = cosim::NsToSeconds(end - 40 * kMs);
      const std::string s = std::to_string(k);
      std::vector<double> r =
          dead[k] ? std::vector<double>(541, 0.0) : ScanRanges(k, start, truth, solids);
      if (noise > 0.0) {
        std::normal_distribution<double> n(0.0, noise);
        for (double& ri : r) {
          if (ri > 0.0) ri = std::round((ri + n(rng)) * 100.0) / 100.0;
        }
      }
      SetArray(u, "ranges_" + s, r);
      count[k] += 1;
      SetAll(u, "scan_count_" + s, count[k]);
      SetAll(u, "scan_time_" + s, start);
    }
    ASSERT_EQ(u.DoStep(t, end - t), cosim::StepResult::kOk) << u.last_error();
    t = end;
  }
  void Run(double seconds) {
    const int n = static_cast<int>(std::lround(seconds / 0.02));
    for (int i = 0; i < n; ++i) Step();
  }
};

// A restored unit's driver `b` continues where `a`'s is (time, scan counts,
// noise draws); both drivers step `steps` control periods and the two
// units' outputs must stay bit for bit alike.
void ExpectSameContinuation(Driver& a, Driver& b, int steps) {
  b.rng = a.rng;
  b.t = a.t;
  b.count[0] = a.count[0];
  b.count[1] = a.count[1];
  for (int i = 0; i < steps; ++i) {
    a.Step();
    b.Step();
    ASSERT_TRUE(test_helpers::SameBits(test_helpers::Outputs(a.u), test_helpers::Outputs(b.u)))
        << i;
  }
}

// Guards against the unit not localizing from an initial pose off by 5 cm,
// 3 cm, 2 deg with two lasers: the matcher's bound (1 mm, 1 mrad; see
// scan_matcher_test.cc), 50 matches per second, the match time at the
// middle of the sweep (540 * 0.5 deg / 360 deg * 40 ms / 2 = 15 ms after the
// scan's start) and the covariance at least its floor.
TEST(LaserLocalization, LocalizesAStillRobotWithTwoLasers) {
  const auto scene = RoomScene();
  const Pose truth = Still(0);
  auto u = MakeUnit(scene, {truth.x + 0.05, truth.y + 0.03, truth.yaw + 2 * kDeg});
  u->Setup(0, 10'000 * kMs);
  u->Initialize();
  EXPECT_EQ(Get(*u, "source")[0], 1.0);  // no match yet
  Driver d{*u, Still, testscene::Room()};
  d.Run(0.2);
  const auto pos = Get(*u, "position");
  EXPECT_NEAR(pos[0], truth.x, 1e-3);
  EXPECT_NEAR(pos[1], truth.y, 1e-3);
  EXPECT_NEAR(Get(*u, "yaw")[0], truth.yaw, 1e-3);
  // 0.2 s: laser 0 completes scans at 40..200 ms (5), laser 1 at 60..180 ms (4).
  EXPECT_EQ(Get(*u, "match_count")[0], 9.0);
  EXPECT_EQ(Get(*u, "laser_status"), (std::vector<double>{0.0, 0.0}));
  EXPECT_EQ(Get(*u, "source")[0], 0.0);
  EXPECT_NEAR(Get(*u, "match_time")[0], 0.16 + 0.015, 1e-9);
  const auto cov = Get(*u, "covariance");
  EXPECT_GE(cov[0], 0.01 * 0.01);
  EXPECT_GE(cov[8], 0.0087 * 0.0087);
  EXPECT_EQ(cov[1], cov[3]);
  EXPECT_GT(Get(*u, "hessian")[0], 0.0);
  EXPECT_LT(Get(*u, "match_cost")[0], 0.01);
  // Still: the velocity from successive matches is below 1 mm / 20 ms.
  EXPECT_LT(std::hypot(Get(*u, "velocity")[0], Get(*u, "velocity")[1]), 0.05);
}

// Guards against a blacked-out laser stopping the localization: laser 0
// reads no return at all (status 2), laser 1 carries on alone.
TEST(LaserLocalization, ABlackedOutLaserIsSkipped) {
  const auto scene = RoomScene();
  const Pose truth = Still(0);
  auto u = MakeUnit(scene, truth);
  u->Setup(0, 10'000 * kMs);
  u->Initialize();
  Driver d{*u, Still, testscene::Room()};
  d.dead[0] = true;
  d.Run(0.2);
  EXPECT_EQ(Get(*u, "laser_status"), (std::vector<double>{2.0, 0.0}));
  EXPECT_EQ(Get(*u, "match_count")[0], 4.0);  // laser 1's four scans
  EXPECT_EQ(Get(*u, "source")[0], 0.0);
  EXPECT_NEAR(Get(*u, "position")[0], truth.x, 1e-3);
  // Laser 0 comes back.
  d.dead[0] = false;
  d.Run(0.08);
  EXPECT_EQ(Get(*u, "laser_status"), (std::vector<double>{0.0, 0.0}));
}

// Guards against a silent laser going unnoticed and a held pose reported
// as fresh: laser 0 never scans (status 1 after scan_timeout 0.2 s); when
// laser 1 stops too, the source becomes 1 and the pose is held.
TEST(LaserLocalization, SilentLasersTimeOut) {
  const auto scene = RoomScene();
  const Pose truth = Still(0);
  auto u = MakeUnit(scene, truth);
  u->Setup(0, 10'000 * kMs);
  u->Initialize();
  Driver d{*u, Still, testscene::Room()};
  d.silent[0] = true;
  d.Run(0.18);
  EXPECT_EQ(Get(*u, "laser_status")[0], 0.0);  // 180 ms: not yet
  d.Run(0.04);
  EXPECT_EQ(Get(*u, "laser_status"), (std::vector<double>{1.0, 0.0}));
  EXPECT_EQ(Get(*u, "source")[0], 0.0);
  const auto held = Get(*u, "position");
  d.silent[1] = true;
  d.Run(0.3);
  EXPECT_EQ(Get(*u, "laser_status"), (std::vector<double>{1.0, 1.0}));
  EXPECT_EQ(Get(*u, "source")[0], 1.0);
  EXPECT_EQ(Get(*u, "position"), held);
}

// Guards against accepting a diverged match: started 1 m off, the scan's
// points land where the map is empty (cost near 1, or a jump beyond
// max_jump): rejected (status 3), nothing accepted, the source stays 1.
TEST(LaserLocalization, RejectsADivergedMatch) {
  const auto scene = RoomScene();
  const Pose truth = Still(0);
  auto u = MakeUnit(scene, {truth.x + 1.0, truth.y - 0.6, truth.yaw + 0.5});
  u->Setup(0, 10'000 * kMs);
  u->Initialize();
  Driver d{*u, Still, testscene::Room()};
  d.Run(0.1);
  EXPECT_EQ(Get(*u, "laser_status"), (std::vector<double>{3.0, 3.0}));
  EXPECT_EQ(Get(*u, "match_count")[0], 0.0);
  EXPECT_EQ(Get(*u, "source")[0], 1.0);
}

// Guards against a moving robot losing track and the odometry prediction
// or deskew being wrong: 0.3 m/s and 0.3 rad/s, odometry given exactly.
// Bound: 2 mm and 2 mrad against the truth at match_time (the matcher's
// 1 mm plus the second-order deskew residual, below 0.1 mm here).
TEST(LaserLocalization, TracksAMovingRobot) {
  const auto scene = RoomScene();
  auto u = MakeUnit(scene, Moving(0));
  u->variables().SetString(*u->variables().Find("motion_prediction"), "odometry");
  u->variables().SetBoolean(*u->variables().Find("deskew"), true);
  u->Setup(0, 10'000 * kMs);
  u->Initialize();
  SetArray(*u, "odometry_velocity", {0.3 * std::cos(0.0), 0.0});  // refined below
  Driver d{*u, Moving, testscene::Room()};
  for (int i = 0; i < 100; ++i) {
    // The twist in base_link: 0.3 m/s along map x, seen from the base.
    const double yaw = Moving(cosim::NsToSeconds(d.t)).yaw;
    SetArray(*u, "odometry_velocity", {0.3 * std::cos(yaw), -0.3 * std::sin(yaw)});
    SetAll(*u, "odometry_yaw_rate", 0.3);
    d.Step();
    if (i < 5) continue;
    const Pose truth = Moving(Get(*u, "match_time")[0]);
    ASSERT_NEAR(Get(*u, "position")[0], truth.x, 2e-3) << i;
    ASSERT_NEAR(Get(*u, "position")[1], truth.y, 2e-3) << i;
    ASSERT_NEAR(Get(*u, "yaw")[0], truth.yaw, 2e-3) << i;
  }
  EXPECT_NEAR(Get(*u, "velocity")[0], 0.3, 0.1);
  EXPECT_NEAR(Get(*u, "yaw_rate")[0], 0.3, 0.1);
}

// Guards against state left out of SaveInternal: a unit restored from a
// saved state continues bit for bit like the original.
TEST(LaserLocalization, RestoredUnitContinuesBitForBit) {
  const auto scene = RoomScene();
  auto a = MakeUnit(scene, Moving(0));
  a->variables().SetString(*a->variables().Find("motion_prediction"), "odometry");
  a->variables().SetBoolean(*a->variables().Find("deskew"), true);
  a->Setup(0, 10'000 * kMs);
  a->Initialize();
  Driver da{*a, Moving, testscene::Room()};
  SetArray(*a, "odometry_velocity", {0.29, 0.01});
  SetAll(*a, "odometry_yaw_rate", 0.31);
  da.Run(0.3);
  const cosim::UnitState saved = a->SaveState();

  auto b = MakeUnit(scene, {0.0, 0.0, 0.0});
  b->variables().SetString(*b->variables().Find("motion_prediction"), "odometry");
  b->variables().SetBoolean(*b->variables().Find("deskew"), true);
  b->Setup(0, 10'000 * kMs);
  b->Initialize();
  b->RestoreState(saved);
  Driver db{*b, Moving, testscene::Room()};
  const double before = Get(*b, "match_count")[0];
  ExpectSameContinuation(da, db, 15);
  // The steps compared include new matches (not only a held pose).
  EXPECT_GT(Get(*b, "match_count")[0], before);
}

// Guards against parameter problems going unnamed: lists of the wrong size,
// required values left out, a scan_timeout shorter than a scan.
TEST(LaserLocalization, NamesParameterProblems) {
  const auto scene = RoomScene();
  auto u = MakeUnit(scene, Still(0));
  try {
    SetArray(*u, "mount_x", {0.1, 0.2, 0.3});
    ADD_FAILURE() << "a 3-element mount_x for 2 lasers was accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("2"), std::string::npos) << e.what();
  }
  SetAll(*u, "scan_timeout", 0.03);
  SetAll(*u, "usable_range_max", 0.1);
  const auto problems = u->CheckParameters();
  std::vector<std::string> names;
  for (const auto& p : problems) names.push_back(p.variable);
  EXPECT_NE(std::find(names.begin(), names.end(), "scan_timeout"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "usable_range_max"), names.end());

  auto v = std::make_unique<LaserLocalizationUnit>("loc", scene, std::vector<int>{541, 541});
  names.clear();
  for (const auto& p : v->CheckParameters()) names.push_back(p.variable);
  for (const char* required :
       {"mount_x", "mount_yaw", "first_beam_angle", "scan_period", "initial_x", "initial_yaw"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), required), names.end()) << required;
  }
  EXPECT_THROW(LaserLocalizationUnit("x", scene, {}), cosim::UnitError);
  EXPECT_THROW(LaserLocalizationUnit("x", scene, {541, 0}), cosim::UnitError);
}

// Guards against the factory accepting bad beam_counts or sizing the
// inputs wrongly.
TEST(LaserLocalization, FactoryReadsBeamCounts) {
  const config::UnitType* type = config::FindUnitType("laser_localization");
  ASSERT_NE(type, nullptr);
  const auto scene = RoomScene();
  const std::string name = "loc", path = "units.loc.parameters", file;
  const YAML::Node none;
  auto make = [&](const std::string& text, std::vector<config::Issue>& issues) {
    config::YamlReader reader("scenario.yaml");
    const YAML::Node params = YAML::Load(text);
    auto unit = type->create({name, 1, reader, params, path, scene, none, file});
    issues = reader.issues();
    return unit;
  };
  std::vector<config::Issue> issues;
  auto ok = make("{beam_counts: [541, 271]}", issues);
  ASSERT_TRUE(ok);
  EXPECT_EQ(ok->variables().info(*ok->variables().Find("ranges_1")).size, 271u);
  EXPECT_EQ(ok->variables().info(*ok->variables().Find("laser_status")).size, 2u);
  EXPECT_FALSE(make("{initial_x: 1}", issues));
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].key_path, "units.loc.parameters");
  EXPECT_FALSE(make("{beam_counts: [541, 0]}", issues));
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues[0].key_path, "units.loc.parameters.beam_counts.1");
  EXPECT_FALSE(make("{beam_counts: []}", issues));
  ASSERT_EQ(issues.size(), 1u);
}

std::unique_ptr<LaserLocalizationUnit> MakeMappingUnit(const models::Scene& scene, Pose initial) {
  auto u = MakeUnit(scene, initial);
  u->variables().SetString(*u->variables().Find("map"), "mapping");
  return u;
}

// Guards against map: mapping losing track or learning a map unlike the
// scene: the robot drives Drive (3.6 m along x, weaving, turning), two
// S300, hector's settings (no motion model, no deskew), with exact ranges
// and with 15 mm noise rounded to 1 cm (S300 operating instructions).
// Bounds, derived:
//  - pose: a learned wall lies at the centres of the cells its hits fell
//    in, up to half a cell (12.5 mm) per axis off the true face, so each
//    match may be off by up to sqrt(2) / 2 cell (17.7 mm); a map update at
//    such a pose can carry that offset into the map once more: 2 cells
//    (0.05 m) in all; yaw: those 2 cells over the ~5 m to the room's walls,
//    0.01 rad.
//  - map updates: each laser's first scan, then one whenever its pose moved
//    more than 0.4 m since; a scan moves the robot 0.3 m/s * 40 ms = 12 mm,
//    so each laser updates at least every 0.412 m of the 3.6 m along x:
//    at least 1 + floor(3.6 / 0.412) = 9 per laser, 18 in all.
//  - every cell the map holds occupied (p > 0.5) lies on a scene outline
//    within the cell's half diagonal (17.7 mm) + the 2-cell pose bound +
//    the yaw bound over the farthest wall (0.01 rad * 8 m) + 3 sigma of the
//    noise and half its 1 cm rounding: 0.148 m exact, 0.198 m noisy.
//  - the final scans' end points (on the scene's solids by construction)
//    find a cell > 0.5 within one cell of them: at least 98% (beams at
//    grazing incidence may fall between earlier hits; measured 1078 to 1080
//    of 1082).
// Exact ranges once (pose 0.0188 m, yaw 0.0015 rad, farthest cell 0.037 m,
// 1080 of 1082 found); with noise, seeds 1..8 of the noise: largest pose
// error 0.0187 / 0.0206 / 0.0218 m (bound 0.05); largest yaw error 0.0027 /
// 0.0038 / 0.0057 rad (0.01); farthest occupied cell 0.0625 / 0.0625 /
// 0.0875 m (0.198); share of end points found 0.9972 / 0.9982 / 1 (0.98).
TEST(LaserLocalizationMapping, TracksAndLearnsTheRoom) {
  const auto scene = RoomScene();
  const OccupancyGrid truth_map(testscene::Room(), testscene::RoomFloor(), {});
  std::vector<double> pose_error, yaw_error, map_error, found_share;
  // Exact ranges once (seed 0 draws nothing), then noisy ones for seeds 1..8.
  for (std::uint64_t seed = 0; seed <= 8; ++seed) {
    const double noise = seed == 0 ? 0.0 : 0.015;
    SCOPED_TRACE(testing::Message() << "noise " << noise << ", seed " << seed);
    auto u = MakeMappingUnit(scene, Drive(0));
    u->Setup(0, 100'000 * kMs);
    u->Initialize();
    Driver d{*u, Drive, testscene::Room()};
    d.noise = noise;
    d.rng.seed(seed);
    d.Step();
    d.Step();
    d.Step();
    // 60 ms: each laser's first scan entered the map, no match yet.
    EXPECT_EQ(Get(*u, "map_updates")[0], 2.0);
    EXPECT_EQ(Get(*u, "match_count")[0], 0.0);
    EXPECT_EQ(Get(*u, "source")[0], 1.0);
    double emax = 0.0, ymax = 0.0;
    for (int i = 3; i < 600; ++i) {
      d.Step();
      if (Get(*u, "match_count")[0] < 1.0) continue;
      const Pose truth = Drive(Get(*u, "match_time")[0]);
      emax = std::max(
          emax, std::hypot(Get(*u, "position")[0] - truth.x, Get(*u, "position")[1] - truth.y));
      ymax = std::max(ymax, std::abs(Get(*u, "yaw")[0] - truth.yaw));
    }
    // 12 s, 50 scans per second, the first two mapped unmatched.
    EXPECT_EQ(Get(*u, "match_count")[0], 597.0);
    EXPECT_LT(emax, 0.05);
    EXPECT_LT(ymax, 0.01);
    EXPECT_GE(Get(*u, "map_updates")[0], 18.0);
    const OccupancyGrid& g = *u->grid();
    ASSERT_TRUE(g.learned());
    const auto& l = g.level(0);
    const double bound = 0.0177 + 0.05 + 0.08 + 3.0 * noise + (noise > 0.0 ? 0.005 : 0.0);
    int occupied = 0;
    double farthest = 0.0;
    for (int iy = 0; iy < l.ny; ++iy) {
      for (int ix = 0; ix < l.nx; ++ix) {
        if (l.value[static_cast<std::size_t>(iy * l.nx + ix)] <= 0.5f) continue;
        ++occupied;
        const double dist = truth_map.SignedDistance(l.origin_x + (ix + 0.5) * l.cell,
                                                     l.origin_y + (iy + 0.5) * l.cell);
        ASSERT_LT(std::abs(dist), bound) << ix << " " << iy;
        farthest = std::max(farthest, std::abs(dist));
      }
    }
    EXPECT_GT(occupied, 1000);
    // The last scans' end points.
    int found = 0, total = 0;
    const double start = cosim::NsToSeconds(d.t) - 0.04;
    const Pose p = Drive(start);
    for (int k = 0; k < 2; ++k) {
      const auto r = ScanRanges(k, start, Drive, testscene::Room());
      const double c = std::cos(p.yaw), sn = std::sin(p.yaw);
      const double ox = p.x + c * kMount[k][0] - sn * kMount[k][1];
      const double oy = p.y + sn * kMount[k][0] + c * kMount[k][1];
      for (int i = 0; i < 541; ++i) {
        const double ri = r[static_cast<std::size_t>(i)];
        if (!(ri >= 0.4)) continue;
        const double a = p.yaw + kMount[k][3] + kFirst + i * kStep;
        int ix = 0, iy = 0;
        ++total;
        if (!g.CellOf(0, ox + ri * std::cos(a), oy + ri * std::sin(a), ix, iy)) continue;
        float best = 0.0f;
        for (int jy = -1; jy <= 1; ++jy) {
          for (int jx = -1; jx <= 1; ++jx) {
            best = std::max(best, l.value[static_cast<std::size_t>((iy + jy) * l.nx + ix + jx)]);
          }
        }
        found += best > 0.5f ? 1 : 0;
      }
    }
    EXPECT_GT(total, 1000);
    EXPECT_GE(found, 0.98 * total);
    if (noise > 0.0) {
      pose_error.push_back(emax);
      yaw_error.push_back(ymax);
      map_error.push_back(farthest);
      found_share.push_back(static_cast<double>(found) / total);
    } else {
      std::printf("exact ranges: pose %.4f m, yaw %.5f rad, map %.4f m, found %d of %d\n", emax,
                  ymax, farthest, found, total);
    }
  }
  test_spread::Print("noisy: largest pose error (m)", pose_error);
  test_spread::Print("noisy: largest yaw error (rad)", yaw_error);
  test_spread::Print("noisy: farthest occupied cell from an outline (m)", map_error);
  test_spread::Print("noisy: share of end points found", found_share);
}

// Guards against the learned map (or the per-laser map bookkeeping) left
// out of SaveInternal: a mapping unit restored at 2 s (after its first
// moved map update at ~1.4 s) continues bit for bit, through the next map
// update (~2.7 s).
TEST(LaserLocalizationMapping, RestoredUnitContinuesBitForBit) {
  const auto scene = RoomScene();
  auto a = MakeMappingUnit(scene, Drive(0));
  a->Setup(0, 100'000 * kMs);
  a->Initialize();
  Driver da{*a, Drive, testscene::Room()};
  da.noise = 0.015;
  da.Run(2.0);
  const cosim::UnitState saved = a->SaveState();
  ASSERT_EQ(saved.strings.size(), 3u);  // the three levels' log-odds
  EXPECT_EQ(saved.strings[0].size(), a->grid()->level(0).log_odds.size() * sizeof(float));

  auto b = MakeMappingUnit(scene, {0.0, 0.0, 0.0});
  b->Setup(0, 100'000 * kMs);
  b->Initialize();
  b->RestoreState(saved);
  for (int i = 0; i < 3; ++i) ASSERT_EQ(b->grid()->level(i).value, a->grid()->level(i).value);
  Driver db{*b, Drive, testscene::Room()};
  db.noise = 0.015;
  const double before = Get(*b, "map_updates")[0];
  ExpectSameContinuation(da, db, 40);
  EXPECT_GT(Get(*b, "map_updates")[0], before);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(b->grid()->level(i).log_odds, a->grid()->level(i).log_odds);
  // A scene-map state does not restore into a mapping unit.
  auto s = MakeUnit(scene, Drive(0));
  s->Setup(0, 100'000 * kMs);
  s->Initialize();
  auto c = MakeMappingUnit(scene, Drive(0));
  c->Setup(0, 100'000 * kMs);
  c->Initialize();
  cosim::UnitState scene_state = s->SaveState();
  EXPECT_TRUE(scene_state.strings.empty());
  scene_state.variables = c->SaveState().variables;  // the parameters say mapping
  EXPECT_THROW(c->RestoreState(scene_state), cosim::UnitError);
}

// Guards against an unknown `map` value being taken for one of the two.
TEST(LaserLocalizationMapping, RefusesAnUnknownMap) {
  const auto scene = RoomScene();
  auto u = MakeUnit(scene, Still(0));
  u->variables().SetString(*u->variables().Find("map"), "slam");
  bool named = false;
  for (const auto& p : u->CheckParameters()) {
    if (p.variable == "map") {
      named = true;
      EXPECT_NE(p.message.find("mapping"), std::string::npos) << p.message;
    }
  }
  EXPECT_TRUE(named);
  u->Setup(0, 1000 * kMs);
  EXPECT_ANY_THROW(u->Initialize());
  // The default is the scene's map.
  auto v = MakeUnit(scene, Still(0));
  v->Setup(0, 1000 * kMs);
  v->Initialize();
  EXPECT_FALSE(v->grid()->learned());
  EXPECT_EQ(Get(*v, "map_updates")[0], 0.0);
}

}  // namespace
}  // namespace linesim::estimation
