// Cost of one ChassisUnit communication step (1 ms, one ODE dWorldStep):
// the Rob@Work 3 with four hinge2 modules and sphere wheels (FACTS.md:
// 5.3 us per step for this variant in a stand-alone program).
//
// Cases: on the floor with drive torques; straddling the edge of a running
// belt (the two front wheels on it) with drive torques. Each simulated
// second starts from the state saved after Initialize (restored with the
// timing paused): +2 N.m on every wheel for 0.5 s, then -2 N.m for 0.5 s,
// so the robot comes back to rest near where it started instead of driving
// off the belt edge (a steady torque pattern left it drifting at about
// 0.4 m/s, fully off the belt after a few simulated seconds).
// Counters: rtf = simulated seconds per second (real-time factor);
// wheels_on_belt = mean number of wheels on the belt (2 while straddling).

#include <benchmark/benchmark.h>

#include <numbers>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"
#include "units/chassis/chassis_unit.h"

namespace {

using linesim::chassis::ChassisUnit;
using linesim::cosim::TimeNs;

constexpr TimeNs kMs = 1'000'000;
constexpr TimeNs kWindow = 1000 * kMs;
constexpr double kTorqueNm = 2.0;

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
  const linesim::cosim::UnitState start = unit.SaveState();
  const auto drive = *v.Find("drive_torque");
  const auto pose = *v.Find("pose");
  const auto surface = *v.Find("wheel_surface");
  std::vector<double> torque(4, 0.0);
  TimeNs t = 0;       // simulated in all
  TimeNs window = 0;  // since the last restore
  double wheels_on_belt = 0.0;
  for (auto _ : state) {
    if (window == kWindow) {
      state.PauseTiming();
      unit.RestoreState(start);
      torque.assign(4, 0.0);  // the restored input
      window = 0;
      state.ResumeTiming();
    }
    const double tau = window < kWindow / 2 ? kTorqueNm : -kTorqueNm;
    if (torque[0] != tau) {
      torque.assign(4, tau);
      v.SetRealArray(drive, torque);
    }
    if (unit.DoStep(window, kMs) != linesim::cosim::StepResult::kOk) {
      state.SkipWithError(unit.last_error().c_str());
      break;
    }
    benchmark::DoNotOptimize(v.GetRealArray(pose).data());
    for (double s : v.GetRealArray(surface)) wheels_on_belt += s == 1.0 ? 1.0 : 0.0;
    t += kMs;
    window += kMs;
  }
  state.counters["rtf"] =
      benchmark::Counter(linesim::cosim::NsToSeconds(t), benchmark::Counter::kIsRate);
  state.counters["wheels_on_belt"] =
      benchmark::Counter(wheels_on_belt, benchmark::Counter::kAvgIterations);
}

void BM_ChassisStep_Floor(benchmark::State& state) { RunChassis(state, false); }
void BM_ChassisStep_StraddlingBelt(benchmark::State& state) { RunChassis(state, true); }

BENCHMARK(BM_ChassisStep_Floor)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_ChassisStep_StraddlingBelt)->Unit(benchmark::kNanosecond);

}  // namespace
