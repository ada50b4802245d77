// Cost of one ClearanceUnit communication point (UpdateOutputs + DoStep,
// inputs set as the master sets them) in the factory_line scene
// (models/scenes/factory_line.yaml, read by the loader: 30 x 20 m hall, 4
// walls, 10 pillars, 3 carts, a rack, one 20 x 2 m belt at 0.10 m/s
// carrying two car bodies on their skids), with the Rob@Work 3 body (models/robots/raw3.yaml:
// 1.03 x 0.57 x 0.40 m box centred 0.13 m up, so its bottom is 0.07 m below
// base_link). One step is 1 ms of simulated time (the chassis's step).
//
// Cases, each for the "pruned" and the "full" query:
//  - Path: the Husky path of the scene's notes at 0.5 m/s (east along
//    y = -5 from x = -10 to 1, north across the line at x = 1, west along
//    y = 4 to x = -10), 62 s, the belt running: near the line, pillars,
//    carts and in the open; cycled.
//  - Near: standing 0.3 m beside the line (the car bodies pass by 0.4 m
//    away), the belt running.
//  - Contact: pressed into part cart 1, the belt running.
// Pair: one FCL narrow-phase call for two boxes 1 m apart (distance with
// libccd's and FCL's own GJK; collide), the unit of the costs above.
//
// Counters: narrow = narrow-phase calls (distance + collide) per step.
//
// Measured (2026-11-24, this machine kind, 2 cores shared with other
// builds, load 2.7-5; CPU time per step, median of 3-5 runs; pruned / full):
// path 1.00-1.37 us (1.00 narrow-phase calls) / 2.76-2.81 us (2.54-2.59);
// near 0.77-0.85 / 2.14-2.26 us; open (standing, nothing moves near it)
// 0.22 us (0.00 calls: distances reused) / 2.56 us; contact 1.13 / 3.98 us.
// Pair: box-box distance 0.44 us (libccd; FCL's own GJK 0.58), box-cylinder
// 0.52 us, box-box collide 0.063 us. The first version of the pruned query
// (car bodies updated in the tree every step, AABB pruning only) cost
// 2.40 us on the path with 1.74 narrow-phase calls.

#include <benchmark/benchmark.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/distance.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "loader/scene_file.h"
#include "models/scene.h"
#include "units/evaluation/clearance.h"

namespace {

namespace models = linesim::models;
using linesim::cosim::TimeNs;
using linesim::evaluation::ClearanceUnit;

constexpr TimeNs kStepNs = 1'000'000;
constexpr double kStepS = 1e-3;

// The hall, read as every scenario reads it.
models::Scene FactoryLine() {
  return linesim::loader::LoadSceneFile(LINESIM_SOURCE_DIR "/models/scenes/factory_line.yaml");
}

struct Pose {
  double x, y, yaw, travel;
};

// The Husky path at 0.5 m/s, one pose per 1 ms step, the belt at 0.1 m/s.
std::vector<Pose> HuskyPath() {
  std::vector<Pose> p;
  const double v = 0.5 * kStepS;
  double t = 0.0;
  for (double x = -10.0; x < 1.0; x += v, t += kStepS) p.push_back({x, -5.0, 0.0, 0.1 * t});
  for (double y = -5.0; y < 4.0; y += v, t += kStepS) {
    p.push_back({1.0, y, 0.5 * std::numbers::pi, 0.1 * t});
  }
  for (double x = 1.0; x > -10.0; x -= v, t += kStepS) {
    p.push_back({x, 4.0, std::numbers::pi, 0.1 * t});
  }
  return p;
}

void SetUp(ClearanceUnit& u, const std::string& query) {
  auto& v = u.variables();
  v.SetReal(*v.Find("body_length"), 1.03);
  v.SetReal(*v.Find("body_width"), 0.57);
  // models/robots/raw3.yaml's body box: 0.07 to 0.40 m.
  v.SetReal(*v.Find("body_height"), 0.33);
  v.SetReal(*v.Find("body_bottom"), 0.07);
  v.SetString(*v.Find("query"), query);
}

void Run(benchmark::State& state, const std::string& query, const std::vector<Pose>& poses) {
  ClearanceUnit u("clearance", FactoryLine());
  SetUp(u, query);
  auto& v = u.variables();
  const auto pos = *v.Find("position_3d");
  const auto ori = *v.Find("orientation");
  const auto travel = *v.Find("belt_travel");
  const auto clearance = *v.Find("clearance");
  u.Initialize();
  std::size_t k = 0;
  TimeNs t = 0;
  double narrow = 0.0;
  double p3[3] = {0.0, 0.0, 0.0}, q4[4] = {1.0, 0.0, 0.0, 0.0}, s1[1] = {0.0};
  for (auto _ : state) {
    const Pose& p = poses[k];
    k = k + 1 == poses.size() ? 0 : k + 1;
    p3[0] = p.x;
    p3[1] = p.y;
    q4[0] = std::cos(0.5 * p.yaw);
    q4[3] = std::sin(0.5 * p.yaw);
    s1[0] = p.travel;
    v.SetRealArray(pos, p3);
    v.SetRealArray(ori, q4);
    v.SetRealArray(travel, s1);
    u.UpdateOutputs();
    if (u.DoStep(t, kStepNs) != linesim::cosim::StepResult::kOk) {
      state.SkipWithError(u.last_error().c_str());
      return;
    }
    t += kStepNs;
    narrow += u.last_narrow_phase_calls();
    benchmark::DoNotOptimize(v.GetReal(clearance));
  }
  state.counters["narrow"] = narrow / static_cast<double>(state.iterations());
  state.counters["collisions"] = static_cast<double>(v.GetInteger(*v.Find("collisions")));
}

std::vector<Pose> Standing(double x, double y) {
  std::vector<Pose> p;
  for (int i = 0; i < 100'000; ++i) p.push_back({x, y, 0.0, 0.1 * kStepS * i});
  return p;
}

void BM_ClearancePath(benchmark::State& state, const char* query) {
  static const std::vector<Pose> path = HuskyPath();
  Run(state, query, path);
}
// 0.3 m from the belt's edge (y -1): body y -1.585..-1.015 ... the car
// bodies (y -0.9..0.9) pass 0.115 m away.
void BM_ClearanceNear(benchmark::State& state, const char* query) {
  static const std::vector<Pose> poses = Standing(-4.0, -1.3);
  Run(state, query, poses);
}
// In the open: 2.5 m from the nearest pillar (0, -7.5), the belt running.
void BM_ClearanceOpen(benchmark::State& state, const char* query) {
  static const std::vector<Pose> poses = Standing(0.0, -5.0);
  Run(state, query, poses);
}
// Cart 1 spans x -12.6..-11.4: the body's front (x + 0.515) 0.1 m into it.
void BM_ClearanceContact(benchmark::State& state, const char* query) {
  static const std::vector<Pose> poses = Standing(-13.015, -4.0);
  Run(state, query, poses);
}

BENCHMARK_CAPTURE(BM_ClearancePath, pruned, "pruned");
BENCHMARK_CAPTURE(BM_ClearancePath, full, "full");
BENCHMARK_CAPTURE(BM_ClearanceNear, pruned, "pruned");
BENCHMARK_CAPTURE(BM_ClearanceNear, full, "full");
BENCHMARK_CAPTURE(BM_ClearanceOpen, pruned, "pruned");
BENCHMARK_CAPTURE(BM_ClearanceOpen, full, "full");
BENCHMARK_CAPTURE(BM_ClearanceContact, pruned, "pruned");
BENCHMARK_CAPTURE(BM_ClearanceContact, full, "full");

// One narrow-phase call: the body against a cart 1 m away.
void BM_ClearancePair(benchmark::State& state, int kind) {
  fcl::CollisionObjectd a(std::make_shared<fcl::Boxd>(1.03, 0.57, 0.40));
  std::shared_ptr<fcl::CollisionGeometryd> shape = std::make_shared<fcl::Boxd>(1.2, 0.8, 1.0);
  if (kind == 3) shape = std::make_shared<fcl::Cylinderd>(0.25, 4.0);
  fcl::CollisionObjectd b(shape, fcl::Matrix3d::Identity(),
                          fcl::Vector3d(kind == 3 ? 1.765 : 2.115, 0.3, 0.5));
  a.setTranslation(fcl::Vector3d(0.0, 0.0, 0.13));
  a.computeAABB();
  b.computeAABB();
  fcl::DistanceRequestd dreq;
  dreq.gjk_solver_type = kind == 1 ? fcl::GST_INDEP : fcl::GST_LIBCCD;
  fcl::DistanceResultd dres;
  fcl::CollisionRequestd creq;
  fcl::CollisionResultd cres;
  double d = 0.0;
  for (auto _ : state) {
    if (kind == 2) {
      cres.clear();
      d += static_cast<double>(fcl::collide(&a, &b, creq, cres));
    } else {
      dres.clear();
      d += fcl::distance(&a, &b, dreq, dres);
    }
    benchmark::DoNotOptimize(d);
  }
  if (kind != 2) state.counters["distance"] = d / static_cast<double>(state.iterations());
}
BENCHMARK_CAPTURE(BM_ClearancePair, distance_libccd, 0);
BENCHMARK_CAPTURE(BM_ClearancePair, distance_indep, 1);
BENCHMARK_CAPTURE(BM_ClearancePair, collide, 2);
BENCHMARK_CAPTURE(BM_ClearancePair, distance_cylinder_libccd, 3);

}  // namespace
