// Cost of paper 2's localization (units/estimation/perfect_match.h): one
// Perfect Match of a 541-beam SICK LMS151 scan (the real laser_scanner unit
// with models/sensors/sick_lms151.yaml, mounted as on the Husky at base_link
// (0.45, 0, 0.35)), and the distance map's build, on the factory_line scene
// (models/scenes/factory_line.yaml) sliced at 0.35 m, for lookup grids of
// 10, 20 (the default) and 50 mm (Tribots'). Reference cost: a
// Perfect-Match-style RPROP of 10 iterations over about 1,065 points,
// 130 us on this machine kind.
#include <benchmark/benchmark.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "loader/scene_file.h"
#include "units/estimation/distance_map.h"
#include "units/estimation/perfect_match.h"
#include "units/sensors/laser_scanner_unit.h"

namespace linesim::estimation {
namespace {

constexpr double kMountX = 0.45, kMountZ = 0.35;

models::Scene Factory() {
  return linesim::loader::LoadSceneFile(LINESIM_SOURCE_DIR "/models/scenes/factory_line.yaml");
}

struct Points {
  std::vector<double> x, y;  // base_link
};

// One LMS151 scan of the real laser unit (its noise and bias, seed 42) with
// the robot at (rx, ry, ryaw).
Points Lms151Scan(const models::Scene& scene, double rx, double ry, double ryaw) {
  const YAML::Node m =
      YAML::LoadFile(std::string(LINESIM_SOURCE_DIR) + "/models/sensors/sick_lms151.yaml");
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
  set("mount_x", kMountX);
  set("mount_y", 0.0);
  set("mount_z", kMountZ);
  set("mount_yaw", 0.0);
  u.Setup(0, 1'000'000'000'000);
  u.Initialize();
  auto& v = u.variables();
  v.SetRealArray(*v.Find("position_3d"), std::vector<double>{rx, ry, 0.0});
  v.SetRealArray(*v.Find("orientation"),
                 std::vector<double>{std::cos(0.5 * ryaw), 0.0, 0.0, std::sin(0.5 * ryaw)});
  v.SetRealArray(*v.Find("belt_travel"), std::vector<double>(scene.belts.size(), 1.0));
  u.DoStep(0, cosim::SecondsToNs(0.02));
  const auto ranges = v.GetRealArray(*v.Find("ranges"));
  const double first = m["first_beam_angle"].as<double>(), step = m["angular_step"].as<double>();
  Points s;
  for (int i = 0; i < 541; ++i) {
    const double r = ranges[static_cast<std::size_t>(i)];
    if (!(r >= 0.5 && r <= 50.0)) continue;
    const double a = first + i * step;
    s.x.push_back(kMountX + r * std::cos(a));
    s.y.push_back(r * std::sin(a));
  }
  return s;
}

// The map's build at cell = arg / 1000 m: selection, OccupancyGrid's
// rasterised band, two EDTs, gradient tables.
void BM_DistanceMapBuildFactory(benchmark::State& state) {
  const models::Scene scene = Factory();
  DistanceMap::Options o;
  o.cell = static_cast<double>(state.range(0)) * 1e-3;
  std::size_t bytes = 0, nodes = 0;
  for (auto _ : state) {
    const DistanceMap map(scene, kMountZ, std::nullopt, o);
    bytes = map.bytes();
    nodes = static_cast<std::size_t>(map.nx()) * static_cast<std::size_t>(map.ny());
    benchmark::DoNotOptimize(&map);
  }
  state.counters["nodes"] = static_cast<double>(nodes);
  state.counters["MB"] = static_cast<double>(bytes) / 1e6;
}
BENCHMARK(BM_DistanceMapBuildFactory)->Arg(10)->Arg(20)->Arg(50)->Unit(benchmark::kMillisecond);

// One match, started 5 cm, 3 cm, 1 deg off the truth (a robot at (1, -2.5)
// heading +x, as the hector bench), at cell = arg0 / 1000 m; arg1: the
// refinement's Gauss-Newton steps (0: Tribots' RPROP alone); arg2: 0 the
// gradient tables (Tribots), 1 the interpolant's own gradient. Counters:
// points, the error (mm, mrad; the scan carries the LMS151's noise and a
// per-device bias), iterations.
void BM_PerfectMatch541Factory(benchmark::State& state) {
  const models::Scene scene = Factory();
  DistanceMap::Options o;
  o.cell = static_cast<double>(state.range(0)) * 1e-3;
  const DistanceMap map(scene, kMountZ, std::nullopt, o);
  PerfectMatch::Options po;
  po.refine_iterations = static_cast<int>(state.range(1));
  po.gradient_tables = state.range(2) == 0;
  const PerfectMatch pm(po);
  const double tx = 1.0, ty = -2.5, tyaw = 0.0;
  const Points s = Lms151Scan(scene, tx, ty, tyaw);
  PerfectMatch::Result r;
  for (auto _ : state) {
    r = pm.Match(map, s.x, s.y, {tx + 0.05, ty + 0.03, tyaw + std::numbers::pi / 180.0});
    benchmark::DoNotOptimize(r);
  }
  state.counters["points"] = r.points;
  state.counters["err_mm"] = 1e3 * std::hypot(r.pose.x - tx, r.pose.y - ty);
  state.counters["err_mrad"] = 1e3 * std::abs(r.pose.yaw - tyaw);
  state.counters["sigma_mm"] = 1e3 * std::sqrt(r.covariance[0] + r.covariance[4]);
  state.counters["iterations"] = r.iterations;
}
BENCHMARK(BM_PerfectMatch541Factory)
    ->Args({10, 1, 0})
    ->Args({20, 0, 0})
    ->Args({20, 1, 0})
    ->Args({20, 2, 0})
    ->Args({50, 1, 0})
    ->Args({10, 1, 1})
    ->Args({20, 1, 1})
    ->Args({50, 1, 1})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace linesim::estimation
