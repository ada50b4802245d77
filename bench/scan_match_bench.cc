// Cost of the laser-only localization (units/estimation): one hector-style
// scan match of a 541-beam S300 scan over 3 levels, the map's build, and
// (map: mapping) a match plus a map update, on
// the factory_line scene (models/scenes/factory_line.yaml) read by the
// loader as a scenario reads it. The scan comes from the real laser_scanner
// unit (units/sensors) on that scene.
#include <benchmark/benchmark.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "loader/scene_file.h"
#include "units/estimation/laser_localization_unit.h"
#include "units/estimation/occupancy_grid.h"
#include "units/estimation/scan_matcher.h"
#include "units/sensors/laser_scanner_unit.h"

namespace linesim::estimation {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

models::Scene FactoryLine() {
  return linesim::loader::LoadSceneFile(LINESIM_SOURCE_DIR "/models/scenes/factory_line.yaml");
}

// The Rob@Work 3 front S300 (0.465, -0.232, 0.178, yaw -45 deg) on a robot
// at (1, -2.5) heading +x, one scan of the real laser_scanner unit.
struct Scan {
  std::vector<double> x, y;  // base_link points
};

Scan FrontScan(const models::Scene& scene, double rx, double ry, double ryaw) {
  const YAML::Node m =
      YAML::LoadFile(std::string(LINESIM_SOURCE_DIR) + "/models/sensors/sick_s300.yaml");
  sensors::LaserScannerUnit u("laser", scene, 541, {}, 42);
  for (const auto& kv : m) {
    const auto ref = u.variables().Find(kv.first.as<std::string>());
    if (!ref || u.variables().info(*ref).causality != cosim::Causality::kParameter) continue;
    if (u.variables().info(*ref).type == cosim::VarType::kInteger) {
      u.variables().SetInteger(*ref, kv.second.as<std::int64_t>());
    } else if (u.variables().info(*ref).type == cosim::VarType::kReal) {
      u.variables().SetReal(*ref, kv.second.as<double>());
    }
  }
  auto set = [&](const char* k, double v) { u.variables().SetReal(*u.variables().Find(k), v); };
  set("mount_x", 0.465);
  set("mount_y", -0.232);
  set("mount_z", 0.178);
  set("mount_yaw", -45.0 * kDeg);
  u.Setup(0, 1'000'000'000'000);
  u.Initialize();
  auto& v = u.variables();
  v.SetRealArray(*v.Find("position_3d"), std::vector<double>{rx, ry, 0.0});
  v.SetRealArray(*v.Find("orientation"),
                 std::vector<double>{std::cos(0.5 * ryaw), 0.0, 0.0, std::sin(0.5 * ryaw)});
  v.SetRealArray(*v.Find("belt_travel"), std::vector<double>{1.0});
  const cosim::TimeNs period = cosim::SecondsToNs(0.04);
  u.DoStep(0, period);
  const auto ranges = v.GetRealArray(*v.Find("ranges"));
  Scan s;
  for (int i = 0; i < 541; ++i) {
    const double r = ranges[static_cast<std::size_t>(i)];
    if (!(r >= 0.4 && r <= 30.0)) continue;
    const double a = -45.0 * kDeg - 135.0 * kDeg + i * 0.5 * kDeg;
    s.x.push_back(0.465 + r * std::cos(a));
    s.y.push_back(-0.232 + r * std::sin(a));
  }
  return s;
}

std::vector<double> Planes() { return {0.178}; }

// The map's build: 3 levels over 31 x 21 m (floor + 0.5 m margin).
void BM_OccupancyGridBuildFactory(benchmark::State& state) {
  const models::Scene scene = FactoryLine();
  const auto planes = Planes();
  std::size_t cells = 0;
  for (auto _ : state) {
    OccupancyGrid g(scene, planes, {});
    cells = 0;
    for (int i = 0; i < g.levels(); ++i) cells += g.level(i).value.size();
    benchmark::DoNotOptimize(g.level(0).value.data());
  }
  state.counters["cells"] = static_cast<double>(cells);
}
BENCHMARK(BM_OccupancyGridBuildFactory)->Unit(benchmark::kMillisecond);

// One match: 3 levels (3 + 3 + 5 iterations at most), started 5 cm, 3 cm,
// 2 deg off the truth. Counters: points, and the match's error (mm, mrad).
// Argument 1: hector's fixed iteration counts (no early exit).
void BM_ScanMatch541Factory(benchmark::State& state) {
  const models::Scene scene = FactoryLine();
  const auto planes = Planes();
  const OccupancyGrid g(scene, planes, {});
  ScanMatcher::Options o;
  if (state.range(0) == 1) o.min_step_position = o.min_step_yaw = 0.0;
  const ScanMatcher m(g, o);
  const double tx = 1.0, ty = -2.5, tyaw = 0.0;
  const Scan s = FrontScan(scene, tx, ty, tyaw);
  ScanMatcher::Result r;
  for (auto _ : state) {
    r = m.Match(s.x, s.y, {tx + 0.05, ty + 0.03, tyaw + 2.0 * kDeg});
    benchmark::DoNotOptimize(r);
  }
  state.counters["points"] = r.points;
  state.counters["err_mm"] = 1e3 * std::hypot(r.pose.x - tx, r.pose.y - ty);
  state.counters["err_mrad"] = 1e3 * std::abs(r.pose.yaw - tyaw);
  state.counters["cost"] = r.cost;
  state.counters["iterations"] = r.iterations;
}
BENCHMARK(BM_ScanMatch541Factory)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// map: mapping: one match of the 541-beam scan against a learned map (the
// map built by entering the same scan at the truth, as the unit's first
// scan does) and one map update with it (every level: Bresenham misses and
// the hit of each beam). The match starts where the unit's would, from the
// last estimate: one S300 scan (40 ms) of 0.3 m/s and 0.3 rad/s off (12 mm,
// 12 mrad); the learned map's peaked cells have a narrower basin than the
// scene map's profile (from the 5 cm, 3 cm, 2 deg start above it ends
// about 6 cm off). Argument 0: the match only; 1: match + update.
// Counters: the cells of the map, and the match's error (mm, mrad).
void BM_ScanMatchAndMapUpdate541Factory(benchmark::State& state) {
  const models::Scene scene = FactoryLine();
  OccupancyGrid g(scene.floor, {}, {});
  const ScanMatcher m(g, {});
  const double tx = 1.0, ty = -2.5, tyaw = 0.0;
  const Scan s = FrontScan(scene, tx, ty, tyaw);
  // The laser at its mount (0.465, -0.232) in base_link.
  g.UpdateByScan(s.x, s.y, 0.465, -0.232, tx, ty, tyaw);
  const OccupancyGrid start = g;
  ScanMatcher::Result r;
  std::int64_t updates = 0;
  for (auto _ : state) {
    r = m.Match(s.x, s.y, {tx + 0.012, ty, tyaw + 0.012});
    if (state.range(0) == 1) {
      g.UpdateByScan(s.x, s.y, 0.465, -0.232, r.pose.x, r.pose.y, r.pose.yaw);
      ++updates;
    }
    benchmark::DoNotOptimize(r);
    benchmark::DoNotOptimize(g.level(0).value.data());
  }
  std::size_t cells = 0;
  for (int i = 0; i < start.levels(); ++i) cells += start.level(i).value.size();
  state.counters["cells"] = static_cast<double>(cells);
  state.counters["points"] = r.points;
  state.counters["err_mm"] = 1e3 * std::hypot(r.pose.x - tx, r.pose.y - ty);
  state.counters["err_mrad"] = 1e3 * std::abs(r.pose.yaw - tyaw);
  state.counters["iterations"] = r.iterations;
}
BENCHMARK(BM_ScanMatchAndMapUpdate541Factory)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace linesim::estimation
