// Cost of one ChassisUnit communication step (1 ms, one ODE dWorldStep).
//
// Rob@Work 3 (four hinge2 modules, sphere wheels; 5.3 us per step for this
// variant in a stand-alone reference program on this machine kind) on the floor and straddling
// the edge of a running belt (the two front wheels on it), with drive
// torques. Each simulated second starts from the state saved after
// Initialize (restored with the timing paused): +2 N.m on every wheel for
// 0.5 s, then -2 N.m for 0.5 s, so the robot comes back to rest near where
// it started instead of driving off the belt edge.
//
// Scene cost: the same robot on the floor of a factory scene (a belt 4 m
// away, 20 static obstacles and 3 car bodies on the belt moving with
// belt_travel, none within reach of the robot) against the same scene
// without obstacles and car bodies. Far objects should cost an AABB test
// each (a few % of a step at most).
//
// Husky A200 (four fixed wheels, two coupled pairs): the same torque
// pattern on its two drive motors.
//
// Terrain cost: the Husky with paper 2's arm payload (a second body geom)
// on the van bay scene (models/scenes/van_bay.yaml: ramp, van floor slab,
// bump, the van's walls and beacons), standing inside the van on its floor
// and the bump (terrain near: every wheel collides with the slab or the bump
// besides the floor plane, the body boxes test the near pieces' AABBs), and
// in the hall 8 m from the van (terrain and van far: one AABB test per
// step), against the same robot on an open floor.
//
// Counters: rtf = simulated seconds per second (real-time factor);
// wheels_on_belt = mean number of wheels on the belt (2 while straddling).

#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"
#include "loader/scene_file.h"
#include "tests/units/chassis/robots.h"
#include "units/chassis/chassis_unit.h"

namespace {

using linesim::chassis::ChassisUnit;
using linesim::cosim::TimeNs;
namespace robots = linesim::chassis::test_robots;
namespace models = linesim::models;

constexpr TimeNs kMs = 1'000'000;
constexpr TimeNs kWindow = 1000 * kMs;
constexpr double kTorqueNm = 2.0;
constexpr double kBeltMps = 0.2;

// A belt along map x centred 4.5 m to the robot's left (3 m wide), with or
// without the hall's furniture: 12 pillars on a 6 m grid, 4 walls, 4 racks,
// and 3 car bodies (4.5 x 1.8 m, on skids 0.3 m up) on the belt.
models::Scene FactoryScene(bool furniture) {
  models::Scene s = robots::OneBelt({0.0, 4.5, 40.0, 3.0, 0.0});
  if (!furniture) return s;
  // Argument order of the calls below: bottom before height.
  const auto box = [](double x, double y, double yaw, double length, double width, double bottom,
                      double height) {
    return models::BoxSolid(x, y, yaw, length, width, height, bottom);
  };
  for (int i = 0; i < 12; ++i) {
    s.obstacles.push_back({"pillar", "pillar",
                           models::CylinderSolid(-15.0 + 6.0 * (i % 6), i < 6 ? -6.0 : 12.0, 0.3,
                                                 6.0)});
  }
  s.obstacles.push_back({"wall", "wall", box(0.0, -10.0, 0.0, 40.0, 0.2, 0.0, 4.0)});
  s.obstacles.push_back({"wall", "wall", box(0.0, 15.0, 0.0, 40.0, 0.2, 0.0, 4.0)});
  s.obstacles.push_back(
      {"wall", "wall", box(-20.0, 2.5, std::numbers::pi / 2, 25.0, 0.2, 0.0, 4.0)});
  s.obstacles.push_back(
      {"wall", "wall", box(20.0, 2.5, std::numbers::pi / 2, 25.0, 0.2, 0.0, 4.0)});
  for (int i = 0; i < 4; ++i) {
    s.obstacles.push_back({"rack", "rack", box(-9.0 + 6.0 * i, -3.5, 0.0, 2.0, 0.8, 0.0, 2.0)});
  }
  for (int i = 0; i < 3; ++i) {
    s.carried.push_back({"car", 0, box(-12.0 + 8.0 * i, 4.5, 0.0, 4.5, 1.8, 0.3, 1.2)});
  }
  return s;
}

// Belt velocity (vx, vy) in map; belt_travel follows its speed.
void Run(benchmark::State& state, ChassisUnit& unit, double belt_vx, double belt_vy) {
  const double belt_mps = std::hypot(belt_vx, belt_vy);
  auto& v = unit.variables();
  unit.Initialize();
  const bool belts = unit.belt_count() > 0;
  if (belts) v.SetRealArray(*v.Find("belt_velocity"), std::vector<double>{belt_vx, belt_vy});
  const linesim::cosim::UnitState start = unit.SaveState();
  const auto drive = *v.Find("drive_torque");
  const auto position = *v.Find("position");
  const auto surface = *v.Find("wheel_surface");
  const auto travel = belts ? v.Find("belt_travel") : std::nullopt;
  const auto motors = static_cast<std::size_t>(unit.drive_motor_count());
  std::vector<double> torque(motors, 0.0);
  // belt_travel of every belt, set in place each step (no allocation in the
  // timed loop).
  std::vector<double> belt_travel(static_cast<std::size_t>(unit.belt_count()), 0.0);
  TimeNs t = 0;       // simulated in all
  TimeNs window = 0;  // since the last restore
  double wheels_on_belt = 0.0;
  for (auto _ : state) {
    if (window == kWindow) {
      state.PauseTiming();
      unit.RestoreState(start);
      torque.assign(motors, 0.0);  // the restored input
      window = 0;
      state.ResumeTiming();
    }
    const double tau = window < kWindow / 2 ? kTorqueNm : -kTorqueNm;
    if (torque[0] != tau) {
      torque.assign(motors, tau);
      v.SetRealArray(drive, torque);
    }
    if (travel) {
      belt_travel.assign(belt_travel.size(), belt_mps * linesim::cosim::NsToSeconds(window));
      v.SetRealArray(*travel, belt_travel);
    }
    if (unit.DoStep(window, kMs) != linesim::cosim::StepResult::kOk) {
      state.SkipWithError(unit.last_error().c_str());
      break;
    }
    benchmark::DoNotOptimize(v.GetRealArray(position).data());
    for (double s : v.GetRealArray(surface)) wheels_on_belt += s == 1.0 ? 1.0 : 0.0;
    t += kMs;
    window += kMs;
  }
  state.counters["rtf"] =
      benchmark::Counter(linesim::cosim::NsToSeconds(t), benchmark::Counter::kIsRate);
  state.counters["wheels_on_belt"] =
      benchmark::Counter(wheels_on_belt, benchmark::Counter::kAvgIterations);
}

void BM_ChassisStep_Floor(benchmark::State& state) {
  auto unit = robots::Raw3(models::OpenFloor());
  Run(state, *unit, 0.0, 0.0);
}

void BM_ChassisStep_StraddlingBelt(benchmark::State& state) {
  // Belt along map y covering x > 0: the front wheels are on it.
  auto unit = robots::Raw3(robots::OneBelt({500.0, 0.0, 1000.0, 1000.0, std::numbers::pi / 2.0}));
  Run(state, *unit, 0.0, kBeltMps);
}

void BM_ChassisStep_FactoryEmpty(benchmark::State& state) {
  auto unit = robots::Raw3(FactoryScene(false));
  Run(state, *unit, kBeltMps, 0.0);
}

void BM_ChassisStep_FactoryFurnished(benchmark::State& state) {
  auto unit = robots::Raw3(FactoryScene(true));
  Run(state, *unit, kBeltMps, 0.0);
}

void BM_ChassisStep_HuskyFloor(benchmark::State& state) {
  auto unit = robots::Husky(robots::Floor(robots::kHuskyMu));
  Run(state, *unit, 0.0, 0.0);
}

models::Scene VanBay() {
  return linesim::loader::LoadSceneFile(LINESIM_SOURCE_DIR "/models/scenes/van_bay.yaml");
}

void BM_ChassisStep_HuskyArmFloor(benchmark::State& state) {
  auto unit = robots::HuskyWithArm(robots::Floor(robots::kHuskyMu));
  Run(state, *unit, 0.0, 0.0);
}

void BM_ChassisStep_HuskyArmTerrainFar(benchmark::State& state) {
  auto unit = robots::HuskyWithArm(VanBay());
  robots::Set(*unit, "initial_x", -3.0);
  Run(state, *unit, 0.0, 0.0);
}

void BM_ChassisStep_HuskyArmTerrainNear(benchmark::State& state) {
  auto unit = robots::HuskyWithArm(VanBay());
  robots::Set(*unit, "initial_x", 5.9);
  Run(state, *unit, 0.0, 0.0);
}

BENCHMARK(BM_ChassisStep_Floor)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_ChassisStep_StraddlingBelt)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_ChassisStep_FactoryEmpty)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_ChassisStep_FactoryFurnished)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_ChassisStep_HuskyFloor)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_ChassisStep_HuskyArmFloor)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_ChassisStep_HuskyArmTerrainFar)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_ChassisStep_HuskyArmTerrainNear)->Unit(benchmark::kNanosecond);

}  // namespace
