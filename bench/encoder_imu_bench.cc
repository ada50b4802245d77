// Cost of one sample (set inputs, UpdateOutputs, DoStep) of the sensors
// family's wheel_encoder (8 channels: the Rob@Work 3's joints), imu (the
// ADIS16470 model: bias walk, white noise, 16-bit quantization) and
// belt_encoder units, driven directly as the master drives them.
// Counter: rtf = simulated seconds per second at the unit's own rate
// (encoders 50 Hz, IMU 200 Hz): how little of the >= 80x real-time budget
// each takes.

#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "cosim/time.h"
#include "units/sensors/belt_encoder_unit.h"
#include "units/sensors/imu_unit.h"
#include "units/sensors/wheel_encoder_unit.h"

namespace {

using linesim::cosim::TimeNs;
using linesim::cosim::Value;
namespace sensors = linesim::sensors;

constexpr TimeNs kMs = 1'000'000;

void Set(linesim::cosim::Unit& u, const char* name, double v) {
  u.variables().SetValue(*u.variables().Find(name), Value{v});
}

void BM_WheelEncoder8(benchmark::State& state) {
  sensors::WheelEncoderUnit u("enc", 8);
  Set(u, "counts_per_revolution", 4096.0 * 21.0);
  u.Setup(0, 0);
  u.Initialize();
  const auto angle = *u.variables().Find("angle");
  std::vector<double> a(8, 0.0);
  const TimeNs dt = 20 * kMs;
  TimeNs t = 0;
  for (auto _ : state) {
    for (std::size_t i = 0; i < a.size(); ++i) a[i] += 0.01 * static_cast<double>(i + 1);
    u.variables().SetRealArray(angle, a);
    u.UpdateOutputs();
    benchmark::DoNotOptimize(u.DoStep(t, dt));
    t += dt;
  }
  state.counters["rtf"] = benchmark::Counter(0.02 * static_cast<double>(state.iterations()),
                                             benchmark::Counter::kIsRate);
}
BENCHMARK(BM_WheelEncoder8);

void BM_ImuAdis16470(benchmark::State& state) {
  sensors::ImuUnit u("imu", 42);
  const double deg = std::numbers::pi / 180.0, g = 9.80665;
  for (const char* p : {"mount_x", "mount_y", "mount_z", "mount_roll", "mount_pitch", "mount_yaw"}) {
    Set(u, p, 0.1);
  }
  Set(u, "gyro_noise_density", 0.008 * deg);
  Set(u, "gyro_bias_instability", 8.0 / 3600.0 * deg);
  Set(u, "gyro_turn_on_bias", 0.2 * deg);
  Set(u, "gyro_range", 2000.0 * deg);
  Set(u, "gyro_resolution", 0.1 * deg);
  Set(u, "accel_noise_density", 23e-6 * g);
  Set(u, "accel_bias_instability", 13e-6 * g);
  Set(u, "accel_turn_on_bias", 5e-3 * g);
  Set(u, "accel_range", 40.0 * g);
  Set(u, "accel_resolution", 1.25e-3 * g);
  Set(u, "bias_instability_time", 100.0);
  u.Setup(0, 0);
  u.Initialize();
  const auto q = *u.variables().Find("orientation");
  const auto v = *u.variables().Find("velocity_3d");
  const auto w = *u.variables().Find("base_angular_velocity");
  std::vector<double> qv{1.0, 0.0, 0.0, 0.0}, vv{0.0, 0.0, 0.0}, wv{0.0, 0.0, 0.3};
  const TimeNs dt = 5 * kMs;
  TimeNs t = 0;
  double yaw = 0.0;
  for (auto _ : state) {
    yaw += 0.3 * 0.005;
    qv[0] = std::cos(yaw / 2);
    qv[3] = std::sin(yaw / 2);
    vv[0] = 0.5 * std::cos(yaw);
    vv[1] = 0.5 * std::sin(yaw);
    u.variables().SetRealArray(q, qv);
    u.variables().SetRealArray(v, vv);
    u.variables().SetRealArray(w, wv);
    u.UpdateOutputs();
    benchmark::DoNotOptimize(u.DoStep(t, dt));
    t += dt;
  }
  state.counters["rtf"] = benchmark::Counter(0.005 * static_cast<double>(state.iterations()),
                                             benchmark::Counter::kIsRate);
}
BENCHMARK(BM_ImuAdis16470);

void BM_BeltEncoder(benchmark::State& state) {
  sensors::BeltEncoderUnit u("belt_gt");
  Set(u, "wheel_radius", 0.0325);
  Set(u, "counts_per_revolution", 800.0);
  u.variables().SetInteger(*u.variables().Find("average_window"), 5);
  u.Setup(0, 0);
  u.Initialize();
  const auto travel = *u.variables().Find("travel");
  const TimeNs dt = 20 * kMs;
  TimeNs t = 0;
  double x = 0.0;
  for (auto _ : state) {
    x += 0.1 * 0.02;
    u.variables().SetReal(travel, x);
    u.UpdateOutputs();
    benchmark::DoNotOptimize(u.DoStep(t, dt));
    t += dt;
  }
  state.counters["rtf"] = benchmark::Counter(0.02 * static_cast<double>(state.iterations()),
                                             benchmark::Counter::kIsRate);
}
BENCHMARK(BM_BeltEncoder);

}  // namespace
