// Cost of the laser scanner (units/sensors): one scan and one 1 ms step of a
// SICK S300 / LMS151 in the factory_line scene (models/scenes/factory_line.yaml:
// 4 walls, 10 pillars, 3 carts, a rack, 2 car bodies on their skids on the
// line), read by the loader as a scenario reads it.
#include <benchmark/benchmark.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "loader/scene_file.h"
#include "units/sensors/laser_scanner_unit.h"

namespace linesim::sensors {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr cosim::TimeNs kMs = 1'000'000;

// The scene the laser sees, read as every scenario reads it.
models::Scene FactoryLine() {
  return linesim::loader::LoadSceneFile(LINESIM_SOURCE_DIR "/models/scenes/factory_line.yaml");
}

std::unique_ptr<LaserScannerUnit> FromModel(const std::string& name, const models::Scene& scene) {
  const YAML::Node m =
      YAML::LoadFile(std::string(LINESIM_SOURCE_DIR) + "/models/sensors/" + name + ".yaml");
  std::vector<std::array<double, 2>> field;
  if (m["protective_field"]) {
    for (const auto& p : m["protective_field"])
      field.push_back({p[0].as<double>(), p[1].as<double>()});
  }
  auto u = std::make_unique<LaserScannerUnit>("laser", scene, m["beam_count"].as<int>(),
                                              std::move(field), 42);
  for (const auto& kv : m) {
    const std::string key = kv.first.as<std::string>();
    const auto ref = u->variables().Find(key);
    if (!ref || u->variables().info(*ref).causality != cosim::Causality::kParameter) continue;
    if (u->variables().info(*ref).type == cosim::VarType::kInteger) {
      u->variables().SetInteger(*ref, kv.second.as<std::int64_t>());
    } else {
      u->variables().SetReal(*ref, kv.second.as<double>());
    }
  }
  return u;
}

// A Rob@Work 3 front S300 (mount (0.465, -0.232, 0.178) m, yaw -45 deg;
// raw3-1 calibration, ipa320/cob_robots) on a robot at (1, -2.5) heading
// +x, moving at 0.3 m/s and turning at 0.2 rad/s; the line's car bodies
// ahead and to its left, pillars and walls around it.
std::unique_ptr<LaserScannerUnit> Scanner(const std::string& model, const models::Scene& scene) {
  auto u = FromModel(model, scene);
  auto set = [&](const char* key, double v) {
    u->variables().SetReal(*u->variables().Find(key), v);
  };
  set("mount_x", 0.465);
  set("mount_y", -0.232);
  set("mount_z", 0.178);
  set("mount_yaw", -45.0 * kDeg);
  u->Setup(0, 1'000'000'000 * kMs);
  u->Initialize();
  auto& v = u->variables();
  v.SetRealArray(*v.Find("position_3d"), std::vector<double>{1.0, -2.5, 0.0});
  v.SetRealArray(*v.Find("velocity_3d"), std::vector<double>{0.3, 0.0, 0.0});
  v.SetRealArray(*v.Find("angular_velocity"), std::vector<double>{0.0, 0.0, 0.2});
  v.SetRealArray(*v.Find("belt_travel"), std::vector<double>{1.0});
  v.SetRealArray(*v.Find("belt_speed"), std::vector<double>{0.1});
  return u;
}

// One whole scan: a step as long as the scan period casts all its beams.
void ScanBench(benchmark::State& state, const std::string& model, double period_s) {
  const models::Scene scene = FactoryLine();
  auto u = Scanner(model, scene);
  const cosim::TimeNs period = cosim::SecondsToNs(period_s);
  cosim::TimeNs t = 0;
  for (auto _ : state) {
    u->DoStep(t, period);
    t += period;
  }
  state.counters["beams"] = static_cast<double>(u->beam_count());
}

void BM_LaserS300ScanFactory(benchmark::State& state) { ScanBench(state, "sick_s300", 0.04); }
BENCHMARK(BM_LaserS300ScanFactory);
void BM_LaserLms151ScanFactory(benchmark::State& state) { ScanBench(state, "sick_lms151", 0.02); }
BENCHMARK(BM_LaserLms151ScanFactory);

// The unit as the master drives it: one 1 ms physics step (about 13.5
// beams of the S300's 541 per 40 ms), averaged over whole scans.
void BM_LaserS300Step1ms(benchmark::State& state) {
  const models::Scene scene = FactoryLine();
  auto u = Scanner("sick_s300", scene);
  cosim::TimeNs t = 0;
  for (auto _ : state) {
    u->DoStep(t, kMs);
    t += kMs;
  }
}
BENCHMARK(BM_LaserS300Step1ms);

// The geometry alone: 541 rays of a level scan through RayScene::Cast
// (Embree stream + exact refinement + the two car bodies).
void BM_RaySceneCast541(benchmark::State& state) {
  const models::Scene scene = FactoryLine();
  RayScene rs(scene);
  std::vector<Ray> rays(541);
  std::vector<RayHit> hits(541);
  for (int i = 0; i < 541; ++i) {
    const double a = (-135.0 + 0.5 * i - 45.0) * kDeg;
    rays[static_cast<std::size_t>(i)] = {
        {1.465, -2.732, 0.178}, {std::cos(a), std::sin(a), 0.0}, 44.25, 0.0};
  }
  const std::vector<double> travel{1.0}, speed{0.1};
  for (auto _ : state) {
    rs.Cast(rays, hits, travel, speed);
    benchmark::DoNotOptimize(hits.data());
  }
}
BENCHMARK(BM_RaySceneCast541);

// Building the geometry a scanner sees (once per laser unit: the Embree
// device, the static solids' BVH, the carried objects): about 0.1 ms after
// the process's first (which also starts Embree's and TBB's run-time), so
// sharing one scene between the lasers of a run would not pay for itself.
void BM_RaySceneBuild(benchmark::State& state) {
  const models::Scene scene = FactoryLine();
  for (auto _ : state) {
    RayScene rs(scene);
    benchmark::DoNotOptimize(&rs);
  }
}
BENCHMARK(BM_RaySceneBuild)->Unit(benchmark::kMillisecond);

// A fleet's share of it (BM_Fleet): the same level scan cast as a 5 ms
// step of the S300 casts it (8 calls of about 68 beams), against the other
// robots' bodies as moving boxes, laid out as BM_Fleet lays out N robots
// (two rows of five, 5 m apart along the line, 2 m across), the scanner on
// the middle robot of the first row. Arg: the number of other robots.
void BM_RaySceneCast541MovingBoxes(benchmark::State& state) {
  const models::Scene scene = FactoryLine();
  RayScene rs(scene);
  const std::array<double, 3> origin{0.465, -5.232, 0.178};
  std::vector<Ray> rays(541);
  std::vector<RayHit> hits(541);
  for (int i = 0; i < 541; ++i) {
    const double a = (-135.0 + 0.5 * i - 45.0) * kDeg;
    rays[static_cast<std::size_t>(i)] = {
        origin, {std::cos(a), std::sin(a), 0.0}, 29.5, 0.04 * i / 541.0};
  }
  // Robot k of BM_Fleet at (-10 + 5 (k % 5), k < 5 ? -5 : -3), heading +x at
  // 0.3 m/s: a Rob@Work 3's body box (0.9 x 0.6 m, 0.05..0.4 m high).
  std::vector<double> boxes;
  const int others = static_cast<int>(state.range(0));
  for (int k = 0, placed = 0; placed < others; ++k) {
    if (k == 2) continue;  // the scanner's own robot
    const double x = -10.0 + 5.0 * (k % 5), y = k < 5 ? -5.0 : -3.0;
    boxes.insert(boxes.end(), {x, y, 0.0, 0.3, 0.0, 0.0, 0.9, 0.6, 0.05, 0.4});
    ++placed;
  }
  const std::vector<double> travel{1.0}, speed{0.1};
  for (auto _ : state) {
    for (std::size_t first = 0; first < rays.size(); first += 68) {
      const std::size_t n = std::min<std::size_t>(68, rays.size() - first);
      rs.Cast(std::span<const Ray>(rays).subspan(first, n),
              std::span<RayHit>(hits).subspan(first, n), travel, speed, {}, boxes);
    }
    benchmark::DoNotOptimize(hits.data());
  }
}
BENCHMARK(BM_RaySceneCast541MovingBoxes)->Arg(0)->Arg(2)->Arg(9);

}  // namespace
}  // namespace linesim::sensors
