// Cost of one DcMotorUnit communication step: 8 motors (a Rob@Work 3 with
// 4 steering and 4 drive motors) in one CVODE system.
//
// Counters: rtf = simulated seconds per second of the benchmark's (single)
// thread, i.e. the real-time factor;
// cvode_steps = CVODE internal steps per communication step;
// restarts = CVODE restarts per communication step.

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "loader/scenario.h"
#include "units/motors/dc_motor_unit.h"

namespace {

using linesim::cosim::TimeNs;
using linesim::motors::DcMotorUnit;
using linesim::motors::MotorMode;

constexpr int kMotors = 8;
constexpr TimeNs kMs = 1'000'000;

enum class Inputs {
  kConstant,        // voltage set once: CVODE never restarts
  kEvery20ms,       // new voltage every 20 ms (the controller cycle)
  kEveryStep,       // new voltage every communication step
  kSpeedEveryStep,  // current-only: shaft speed changes every step
  kRobot            // current-only: shaft speed every step, voltage every 20 ms
};

// Settings that differ from the unit's defaults.
struct Options {
  std::optional<std::string> hold;  // current-only: shaft_speed_hold
  std::optional<double> rel_tol;
};

// Motors 0-3 steer (belt 4, eta 0.9), 4-7 drive (gear 21, eta 0.75), as the
// robot scenarios order them (models/robots/raw3.yaml); the full-mode loads
// are rough module / wheel inertias.
std::unique_ptr<DcMotorUnit> MakeUnit(MotorMode mode, const Options& options) {
  auto u = std::make_unique<DcMotorUnit>("motors", kMotors, mode);
  auto& v = u->variables();
  if (options.rel_tol) v.SetReal(*v.Find("rel_tol"), *options.rel_tol);
  if (options.hold) v.SetString(*v.Find("shaft_speed_hold"), *options.hold);
  std::vector<double> ratio, eta, j_load;
  for (int k = 0; k < kMotors; ++k) {
    const bool steer = k < kMotors / 2;
    ratio.push_back(steer ? 4.0 : 21.0);
    eta.push_back(steer ? 0.9 : 0.75);
    j_load.push_back(steer ? 0.002 : 0.01);
  }
  v.SetRealArray(*v.Find("gear_ratio"), ratio);
  v.SetRealArray(*v.Find("gear_efficiency"), eta);
  if (mode == MotorMode::kFull) v.SetRealArray(*v.Find("load_inertia"), j_load);
  return u;
}

// A bounded, never-repeating-per-step command so that every step sees a
// bitwise change when asked for.
double Command(std::int64_t k, int motor) {
  return 12.0 + 6.0 * std::sin(0.37 * static_cast<double>(k) + motor);
}

void RunMotors(benchmark::State& state, DcMotorUnit& unit, TimeNs dt, Inputs inputs) {
  unit.Initialize();
  auto& v = unit.variables();
  const bool full = unit.mode() == MotorMode::kFull;
  const auto voltage = *v.Find("voltage");
  const auto second = *v.Find(full ? "load_torque" : "shaft_speed");
  const auto current = *v.Find("current");
  std::vector<double> volts(kMotors, 12.0), other(kMotors, full ? -0.5 : 0.0);
  v.SetRealArray(voltage, volts);
  v.SetRealArray(second, other);
  const TimeNs period = 20 * kMs;

  TimeNs t = 0;
  std::int64_t k = 0;
  bool ok = true;
  const auto step = [&]() {
    const bool controller = inputs == Inputs::kEvery20ms || inputs == Inputs::kRobot;
    if (inputs == Inputs::kEveryStep || (controller && t % period == 0)) {
      for (int m = 0; m < kMotors; ++m) volts[static_cast<std::size_t>(m)] = Command(k, m);
      v.SetRealArray(voltage, volts);
    }
    if (inputs == Inputs::kSpeedEveryStep || inputs == Inputs::kRobot) {
      // Output shaft speeds as the chassis would report them, about 10 rad/s.
      for (int m = 0; m < kMotors; ++m) {
        other[static_cast<std::size_t>(m)] =
            10.0 * std::sin(2.0 * std::numbers::pi * linesim::cosim::NsToSeconds(t) + m);
      }
      v.SetRealArray(second, other);
    }
    ok = ok && unit.DoStep(t, dt) == linesim::cosim::StepResult::kOk;
    t += dt;
    ++k;
  };
  // Warm up past the start transient so that the constant case measures the
  // steady cost, not the first milliseconds.
  for (int i = 0; i < 100; ++i) step();

  const std::int64_t steps0 = unit.cvode_steps();
  const std::int64_t restarts0 = unit.cvode_restarts();
  const TimeNs t0 = t;
  for (auto _ : state) {
    step();
    benchmark::DoNotOptimize(v.GetRealArray(current).data());
  }
  if (!ok) state.SkipWithError(unit.last_error().c_str());
  const auto n = static_cast<double>(state.iterations());
  state.counters["rtf"] =
      benchmark::Counter(linesim::cosim::NsToSeconds(t - t0), benchmark::Counter::kIsRate);
  state.counters["cvode_steps"] = static_cast<double>(unit.cvode_steps() - steps0) / n;
  state.counters["restarts"] = static_cast<double>(unit.cvode_restarts() - restarts0) / n;
}

void Register() {
  struct Case {
    const char* name;
    MotorMode mode;
    TimeNs dt;
    Inputs inputs;
    Options options = {};
  };
  static const Case kCases[] = {
      {"BM_Motor8Full/1ms_const", MotorMode::kFull, kMs, Inputs::kConstant},
      {"BM_Motor8Full/10ms_const", MotorMode::kFull, 10 * kMs, Inputs::kConstant},
      {"BM_Motor8Full/1ms_ctrl20ms", MotorMode::kFull, kMs, Inputs::kEvery20ms},
      {"BM_Motor8Full/1ms_change", MotorMode::kFull, kMs, Inputs::kEveryStep},
      {"BM_Motor8Full/10ms_change", MotorMode::kFull, 10 * kMs, Inputs::kEveryStep},
      {"BM_Motor8CurrentOnly/1ms_speed_change", MotorMode::kCurrentOnly, kMs,
       Inputs::kSpeedEveryStep},
      {"BM_Motor8CurrentOnly/10ms_speed_change", MotorMode::kCurrentOnly, 10 * kMs,
       Inputs::kSpeedEveryStep},
      // The robot's case: voltage from the 20 ms controller, shaft speed from
      // the 1 ms physics, held to first order without restarts.
      {"BM_Motor8CurrentOnly/1ms_speed_change_first_order",
       MotorMode::kCurrentOnly,
       kMs,
       Inputs::kSpeedEveryStep,
       {"first_order", std::nullopt}},
      {"BM_Motor8CurrentOnly/1ms_robot_zoh_rtol1e-6",
       MotorMode::kCurrentOnly,
       kMs,
       Inputs::kRobot,
       {std::nullopt, 1e-6}},
      {"BM_Motor8CurrentOnly/1ms_robot_first_order",
       MotorMode::kCurrentOnly,
       kMs,
       Inputs::kRobot,
       {"first_order", std::nullopt}},
      {"BM_Motor8CurrentOnly/1ms_robot_first_order_rtol1e-6",
       MotorMode::kCurrentOnly,
       kMs,
       Inputs::kRobot,
       {"first_order", 1e-6}},
      {"BM_Motor8CurrentOnly/1ms_robot_first_order_rtol1e-4",
       MotorMode::kCurrentOnly,
       kMs,
       Inputs::kRobot,
       {"first_order", 1e-4}},
  };
  for (const Case& c : kCases) {
    benchmark::RegisterBenchmark(c.name, [c](benchmark::State& s) {
      auto unit = MakeUnit(c.mode, c.options);
      RunMotors(s, *unit, c.dt, c.inputs);
    })->Unit(benchmark::kMicrosecond);
  }
  // The robot scenario's own motor unit, with whatever its robot model sets.
  benchmark::RegisterBenchmark(
      "BM_Motor8CurrentOnly/1ms_robot_cross_line_motors",
      [](benchmark::State& s) {
        linesim::loader::Scenario scenario =
            linesim::loader::LoadScenario(LINESIM_SOURCE_DIR "/scenarios/cross_line.yaml");
        auto& unit =
            dynamic_cast<DcMotorUnit&>(scenario.system->unit(*scenario.system->FindUnit("motors")));
        RunMotors(s, unit, kMs, Inputs::kRobot);
      })
      ->Unit(benchmark::kMicrosecond);
}

const bool kRegistered = (Register(), true);

}  // namespace
