// Cost of one ChassisUnit communication step (1 ms, one ODE dWorldStep):
// the Rob@Work 3 with four hinge2 modules and sphere wheels (FACTS.md:
// 5.3 us per step for this variant in a stand-alone program).
//
// Cases: on the floor with drive torques; straddling the edge of a running
// belt (two wheels on it) with drive torques. Torques reverse every second
// so the robot stays slow however many iterations run.
// Counters: rtf = simulated seconds per second (real-time factor).

#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include "cosim/time.h"
#include "units/chassis/chassis_unit.h"

namespace {

using linesim::chassis::ChassisUnit;
using linesim::cosim::TimeNs;

constexpr TimeNs kMs = 1'000'000;

void RunChassis(benchmark::State& state, bool straddle) {
  ChassisUnit unit("robot", 4, 1);
  auto& v = unit.variables();
  if (straddle) {
    // Belt along map y covering x > 0: the front wheels are on it.
    v.SetValue(*v.Find("belt_center_x"), linesim::cosim::Value{500.0});
    v.SetValue(*v.Find("belt_length"), linesim::cosim::Value{1000.0});
    v.SetValue(*v.Find("belt_width"), linesim::cosim::Value{1000.0});
    v.SetValue(*v.Find("belt_direction"), linesim::cosim::Value{std::numbers::pi / 2.0});
  }
  unit.Initialize();
  v.SetRealArray(*v.Find("belt_velocity"), std::vector<double>{0.0, straddle ? 0.2 : 0.0});
  const auto drive = *v.Find("drive_torque");
  const auto pose = *v.Find("pose");
  std::vector<double> torque(4, 2.0);
  TimeNs t = 0;
  for (auto _ : state) {
    // Reverse every second: bounded speed, and a changed input now and then.
    const double sign = (t / (1000 * kMs)) % 2 == 0 ? 1.0 : -1.0;
    if (torque[0] != 2.0 * sign) {
      torque.assign(4, 2.0 * sign);
      v.SetRealArray(drive, torque);
    }
    if (unit.DoStep(t, kMs) != linesim::cosim::StepResult::kOk) {
      state.SkipWithError(unit.last_error().c_str());
      break;
    }
    benchmark::DoNotOptimize(v.GetRealArray(pose).data());
    t += kMs;
  }
  state.counters["rtf"] =
      benchmark::Counter(linesim::cosim::NsToSeconds(t), benchmark::Counter::kIsRate);
}

void BM_ChassisStep_Floor(benchmark::State& state) { RunChassis(state, false); }
void BM_ChassisStep_StraddlingBelt(benchmark::State& state) { RunChassis(state, true); }

BENCHMARK(BM_ChassisStep_Floor)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_ChassisStep_StraddlingBelt)->Unit(benchmark::kNanosecond);

}  // namespace
