// Cost of the van bay's ground truth (units/evaluation/beacon_localization):
// one LMS151 scan (541 beams) from the work pose (5.9, 0, 0) of paper 2's
// van (Sobreira et al. 2019; four beacons of radius 0.04 m at (6.0, +-0.75),
// (6.95, +-0.75)), taken once from the real scanner; then per scan the
// detection, association and EKF update (tracking), and the association by
// geometry of a restart (the first scan after the beacons are uncovered).
#include <benchmark/benchmark.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "units/evaluation/beacon_localization.h"
#include "units/sensors/laser_scanner_unit.h"

namespace linesim::evaluation {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr cosim::TimeNs kMs = 1'000'000;

models::Scene Van() {
  models::Scene s = models::OpenFloor();
  const double wall = 0.05, half = 0.8825;
  s.obstacles.push_back(
      {"left", "vehicle", models::BoxSolid(5.55, half + 0.5 * wall, 0.0, 3.1, wall, 2.14, 0.3)});
  s.obstacles.push_back(
      {"right", "vehicle", models::BoxSolid(5.55, -half - 0.5 * wall, 0.0, 3.1, wall, 2.14, 0.3)});
  s.obstacles.push_back({"front", "vehicle",
                         models::BoxSolid(7.125, 0.0, 0.0, wall, 2 * half + 2 * wall, 2.14, 0.3)});
  for (double x : {6.0, 6.95}) {
    for (double y : {0.75, -0.75}) {
      s.obstacles.push_back({"beacon", "beacon", models::CylinderSolid(x, y, 0.04, 0.8, 0.54)});
    }
  }
  return s;
}

// Ten scans of the LMS151 (models/sensors/sick_lms151.yaml) on the Husky
// (base_link (0.45, 0, 0.35)) standing at the work pose.
std::vector<std::vector<double>> Scans() {
  const models::Scene scene = Van();
  const YAML::Node m = YAML::LoadFile(std::string(LINESIM_SOURCE_DIR) +
                                      "/models/sensors/sick_lms151.yaml");
  sensors::LaserScannerUnit laser("laser", scene, m["beam_count"].as<int>(), {}, 42);
  for (const auto& kv : m) {
    const auto ref = laser.variables().Find(kv.first.as<std::string>());
    if (ref && laser.variables().info(*ref).causality == cosim::Causality::kParameter) {
      laser.variables().SetReal(*ref, kv.second.as<double>());
    }
  }
  auto& v = laser.variables();
  v.SetReal(*v.Find("mount_x"), 0.45);
  v.SetReal(*v.Find("mount_z"), 0.35);
  const std::vector<double> position{5.9, 0.0, 0.54}, orientation{1.0, 0.0, 0.0, 0.0};
  v.SetRealArray(*v.Find("position_3d"), position);
  v.SetRealArray(*v.Find("orientation"), orientation);
  laser.Setup(0, 1000000 * kMs);
  laser.Initialize();
  std::vector<std::vector<double>> scans;
  double count = 0;
  for (cosim::TimeNs t = 0; scans.size() < 10; t += 5 * kMs) {
    (void)laser.DoStep(t, 5 * kMs);
    if (v.GetReal(*v.Find("scan_count")) != count) {
      count = v.GetReal(*v.Find("scan_count"));
      const auto r = v.GetRealArray(*v.Find("ranges"));
      scans.emplace_back(r.begin(), r.end());
    }
  }
  return scans;
}

std::unique_ptr<BeaconLocalizationUnit> Unit() {
  std::vector<BeaconLocalizationUnit::Beacon> b;
  for (double x : {6.0, 6.95}) {
    for (double y : {0.75, -0.75}) b.push_back({x, y, 0.04});
  }
  auto u = std::make_unique<BeaconLocalizationUnit>("beacons", b, 541);
  auto& v = u->variables();
  v.SetReal(*v.Find("mount_x"), 0.45);
  v.SetReal(*v.Find("mount_y"), 0.0);
  v.SetReal(*v.Find("mount_yaw"), 0.0);
  v.SetReal(*v.Find("first_beam_angle"), -135.0 * kDeg);
  v.SetReal(*v.Find("angular_step"), 0.5 * kDeg);
  v.SetReal(*v.Find("uncover_delay"), 0.0);
  u->Setup(0, 1000000 * kMs);
  u->Initialize();
  return u;
}

// One new scan per iteration while tracking (the filter started).
void BM_BeaconTrackScan(benchmark::State& state) {
  const auto scans = Scans();
  auto u = Unit();
  auto& v = u->variables();
  const auto ranges = *v.Find("ranges"), count = *v.Find("scan_count"),
             time = *v.Find("scan_time");
  double n = 0;
  cosim::TimeNs t = 0;
  for (auto _ : state) {
    v.SetRealArray(ranges, scans[static_cast<std::size_t>(n) % scans.size()]);
    n += 1;
    v.SetReal(count, n);
    v.SetReal(time, 0.02 * n);
    benchmark::DoNotOptimize(u->DoStep(t, 20 * kMs));
    t += 20 * kMs;
  }
  state.counters["valid"] = v.GetBoolean(*v.Find("valid")) ? 1 : 0;
}
BENCHMARK(BM_BeaconTrackScan);

// The first scan after the beacons are uncovered: association by geometry
// and the filter's start (each iteration covers and uncovers them).
void BM_BeaconRestartScan(benchmark::State& state) {
  const auto scans = Scans();
  auto u = Unit();
  auto& v = u->variables();
  const auto ranges = *v.Find("ranges"), count = *v.Find("scan_count"),
             time = *v.Find("scan_time"), active = *v.Find("active");
  double n = 0;
  cosim::TimeNs t = 0;
  for (auto _ : state) {
    v.SetBoolean(active, false);
    benchmark::DoNotOptimize(u->DoStep(t, kMs));
    v.SetBoolean(active, true);
    v.SetRealArray(ranges, scans[static_cast<std::size_t>(n) % scans.size()]);
    n += 1;
    v.SetReal(count, n);
    v.SetReal(time, cosim::NsToSeconds(t + kMs));
    benchmark::DoNotOptimize(u->DoStep(t + kMs, kMs));
    t += 2 * kMs;
  }
  state.counters["valid"] = v.GetBoolean(*v.Find("valid")) ? 1 : 0;
}
BENCHMARK(BM_BeaconRestartScan);

}  // namespace
}  // namespace linesim::evaluation
