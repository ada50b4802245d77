// Cost of one DcMotorUnit communication step: 8 motors (a Rob@Work 3 with
// 4 drive and 4 steer motors) in one CVODE system.
//
// Counters: rtf = simulated seconds per second of the benchmark's (single)
// thread, i.e. the real-time factor;
// cvode_steps = CVODE internal steps per communication step;
// restarts = CVODE restarts per communication step.

#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "cosim/time.h"
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

struct Options {
  std::string hold = "zero_order";  // current-only: shaft_speed_hold
  double rel_tol = 1e-8;            // the unit's default
  double abs_tol = 1e-10;           // the unit's default
};

std::unique_ptr<DcMotorUnit> MakeUnit(MotorMode mode, const Options& options) {
  auto u = std::make_unique<DcMotorUnit>("motors", kMotors, mode);
  auto& v = u->variables();
  v.SetReal(*v.Find("rel_tol"), options.rel_tol);
  v.SetReal(*v.Find("abs_tol"), options.abs_tol);
  if (mode == MotorMode::kCurrentOnly) v.SetString(*v.Find("shaft_speed_hold"), options.hold);
  // Motors 0-3 drive (gear 21, eta 0.75), 4-7 steer (belt 4, eta 0.9), as in
  // models/motors/raw3_*.yaml; the loads are rough wheel / module inertias.
  std::vector<double> ratio, eta, j_load;
  for (int k = 0; k < kMotors; ++k) {
    const bool drive = k < kMotors / 2;
    ratio.push_back(drive ? 21.0 : 4.0);
    eta.push_back(drive ? 0.75 : 0.9);
    j_load.push_back(drive ? 0.01 : 0.002);
  }
  v.SetRealArray(*v.Find("gear_ratio"), ratio);
  v.SetRealArray(*v.Find("gear_efficiency"), eta);
  if (mode == MotorMode::kFull) v.SetRealArray(*v.Find("load_inertia"), j_load);
  u->Initialize();
  return u;
}

// A bounded, never-repeating-per-step command so that every step sees a
// bitwise change when asked for.
double Command(std::int64_t k, int motor) {
  return 12.0 + 6.0 * std::sin(0.37 * static_cast<double>(k) + motor);
}

void RunMotors(benchmark::State& state, MotorMode mode, TimeNs dt, Inputs inputs,
               const Options& options) {
  auto unit = MakeUnit(mode, options);
  auto& v = unit->variables();
  const auto voltage = *v.Find("voltage");
  const auto second = *v.Find(mode == MotorMode::kFull ? "load_torque" : "shaft_speed");
  const auto current = *v.Find("current");
  std::vector<double> volts(kMotors, 12.0), other(kMotors, 0.0);
  if (mode == MotorMode::kFull) other.assign(kMotors, -0.5);  // small braking load
  v.SetRealArray(voltage, volts);
  v.SetRealArray(second, other);
  const TimeNs period = 20 * kMs;

  // Warm up past the start transient so that the constant case measures the
  // steady cost, not the first milliseconds.
  TimeNs t = 0;
  std::int64_t k = 0;
  const auto step = [&]() {
    if (inputs == Inputs::kEveryStep || (inputs == Inputs::kEvery20ms && t % period == 0)) {
      for (int m = 0; m < kMotors; ++m) volts[static_cast<std::size_t>(m)] = Command(k, m);
      v.SetRealArray(voltage, volts);
    }
    if (inputs == Inputs::kRobot && t % period == 0) {
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
    unit->DoStep(t, dt);
    t += dt;
    ++k;
  };
  for (int i = 0; i < 100; ++i) step();

  const std::int64_t steps0 = unit->cvode_steps();
  const std::int64_t restarts0 = unit->cvode_restarts();
  const TimeNs t0 = t;
  for (auto _ : state) {
    step();
    benchmark::DoNotOptimize(v.GetRealArray(current).data());
  }
  const auto n = static_cast<double>(state.iterations());
  state.counters["rtf"] =
      benchmark::Counter(linesim::cosim::NsToSeconds(t - t0), benchmark::Counter::kIsRate);
  state.counters["cvode_steps"] = static_cast<double>(unit->cvode_steps() - steps0) / n;
  state.counters["restarts"] = static_cast<double>(unit->cvode_restarts() - restarts0) / n;
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
       {"first_order", 1e-8}},
      {"BM_Motor8CurrentOnly/1ms_robot_zoh_rtol1e-6",
       MotorMode::kCurrentOnly,
       kMs,
       Inputs::kRobot,
       {"zero_order", 1e-6}},
      {"BM_Motor8CurrentOnly/1ms_robot_first_order_rtol1e-8",
       MotorMode::kCurrentOnly,
       kMs,
       Inputs::kRobot,
       {"first_order", 1e-8}},
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
      // The settings of models/robots/raw3.yaml.
      {"BM_Motor8CurrentOnly/1ms_robot_raw3_settings",
       MotorMode::kCurrentOnly,
       kMs,
       Inputs::kRobot,
       {"first_order", 1e-3, 1e-4}},
  };
  for (const Case& c : kCases) {
    benchmark::RegisterBenchmark(c.name, [c](benchmark::State& s) {
      RunMotors(s, c.mode, c.dt, c.inputs, c.options);
    })->Unit(benchmark::kMicrosecond);
  }
}

const bool kRegistered = (Register(), true);

}  // namespace
