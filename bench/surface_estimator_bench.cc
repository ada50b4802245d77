// Cost of the surface velocity estimator (units/estimation/surface_velocity_estimator.h).
//
// BM_SteadyStateKalmanUpdate: one scalar filter step x + K (z - x).
//
// BM_SurfaceEstimatorStep: one estimator step with 4 sensors and 4 wheels
// (paper 1: the Rob@Work 3's corner PX4Flows and its four wheels), the robot
// straddling a belt's edge while it drives and turns, so that the map puts
// two sensors and two wheels over the belt. Each 20 ms step is timed; a new
// message arrives every 5th step (10 Hz messages, 50 Hz steps), one sensor's
// every other message invalid (the hold path). Target: well under 1 us.
//
// BM_SurfaceFusionStep: one step of the fused surface sensing
// (surface_fusion_unit.h) in the same straddle, 4 sensors, 4 wheels, one
// belt (a 4-state filter): the dead reckoning, the prediction, a match
// every other step (two S300 at 25 Hz seen together) with both switch
// detectors, and a PX4Flow message every 5th step.

#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "cosim/time.h"
#include "units/estimation/steady_state_kalman.h"
#include "units/estimation/surface_fusion_unit.h"
#include "units/estimation/surface_velocity_estimator.h"

namespace {

using linesim::cosim::TimeNs;
namespace estimation = linesim::estimation;
namespace models = linesim::models;

void BM_SteadyStateKalmanUpdate(benchmark::State& state) {
  const estimation::SteadyStateKalman f((0.01 / 3) * (0.01 / 3), 0.03 * 0.03);
  double x = 0.0, z = 0.1;
  for (auto _ : state) {
    benchmark::DoNotOptimize(z);
    x = f.Update(x, z);
    benchmark::DoNotOptimize(x);
  }
}
BENCHMARK(BM_SteadyStateKalmanUpdate);

void SetArray(estimation::SurfaceVelocityEstimator& u, const char* name,
              const std::vector<double>& v) {
  u.variables().SetRealArray(*u.variables().Find(name), v);
}

void BM_SurfaceEstimatorStep(benchmark::State& state) {
  models::Scene scene;
  scene.surfaces.push_back({"concrete", 0.8, 0.2, 500.0});
  scene.surfaces.push_back({"belt", 0.8, 0.1, 500.0});
  scene.floor = {-50, 50, -50, 50, 0};
  models::Belt b;
  b.area = {0.0, 0.0, 20.0, 0.6, 0.0};
  b.surface = 1;
  scene.belts.push_back(b);
  estimation::SurfaceVelocityEstimator u("est", 4, 4, scene);
  SetArray(u, "sensor_x", {0.3, 0.3, -0.3, -0.3});
  SetArray(u, "sensor_y", {0.25, -0.25, 0.25, -0.25});
  SetArray(u, "sensor_yaw", {0.0, 0.0, 0.0, 0.0});
  SetArray(u, "wheel_x", {0.25, 0.25, -0.25, -0.25});
  SetArray(u, "wheel_y", {0.2, -0.2, 0.2, -0.2});
  u.Setup(0, TimeNs{1} << 60);
  u.Initialize();
  // base_link straddling the belt's edge (y = 0.3): two sensors over it.
  SetArray(u, "position", {0.0, 0.3});
  SetArray(u, "velocity", {0.1, 0.05});
  u.variables().SetReal(*u.variables().Find("yaw_rate"), 0.05);
  u.variables().SetReal(*u.variables().Find("yaw"), 0.01);
  SetArray(u, "sensor_velocity", {0.0, -0.05, 0.0, -0.05, -0.1, -0.05, -0.1, -0.05});
  SetArray(u, "sensor_quality", {200, 200, 200, 200});
  const auto count_ref = *u.variables().Find("sensor_message_count");
  const auto valid_ref = *u.variables().Find("sensor_valid");
  constexpr TimeNs kStep = 20'000'000;
  TimeNs t = 0;
  std::int64_t step = 0;
  for (auto _ : state) {
    if (step % 5 == 0) {
      const double count = static_cast<double>(step / 5 + 1);
      for (std::size_t i = 0; i < 4; ++i) u.variables().SetRealElement(count_ref, i, count);
      u.variables().SetRealElement(valid_ref, 0, (step / 5) % 2 == 0 ? 1.0 : 0.0);
    }
    benchmark::DoNotOptimize(u.DoStep(t, kStep));
    t += kStep;
    ++step;
  }
}
BENCHMARK(BM_SurfaceEstimatorStep);

void SetFusionArray(estimation::SurfaceFusionUnit& u, const char* name,
                    const std::vector<double>& v) {
  u.variables().SetRealArray(*u.variables().Find(name), v);
}

void BM_SurfaceFusionStep(benchmark::State& state) {
  models::Scene scene;
  scene.surfaces.push_back({"concrete", 0.8, 0.2, 500.0});
  scene.surfaces.push_back({"belt", 0.8, 0.1, 500.0});
  scene.floor = {-50, 50, -50, 50, 0};
  models::Belt b;
  b.area = {0.0, 0.0, 20.0, 0.6, 0.0};
  b.surface = 1;
  scene.belts.push_back(b);
  estimation::SurfaceFusionUnit u("fusion", 4, 4, scene);
  SetFusionArray(u, "sensor_x", {0.3, 0.3, -0.3, -0.3});
  SetFusionArray(u, "sensor_y", {0.25, -0.25, 0.25, -0.25});
  SetFusionArray(u, "sensor_yaw", {0.0, 0.0, 0.0, 0.0});
  SetFusionArray(u, "wheel_x", {0.25, 0.25, -0.25, -0.25});
  SetFusionArray(u, "wheel_y", {0.2, -0.2, 0.2, -0.2});
  u.Setup(0, TimeNs{1} << 60);
  u.Initialize();
  // base_link straddling the belt's edge (y = 0.3): two sensors and two
  // wheels over it.
  SetFusionArray(u, "position", {0.0, 0.3});
  u.variables().SetReal(*u.variables().Find("yaw"), 0.01);
  SetFusionArray(u, "wheel_velocity", {-0.1, 0.0, -0.1, 0.0, 0.0, 0.0, 0.0, 0.0});
  SetFusionArray(u, "sensor_velocity", {0.0, -0.05, 0.0, -0.05, -0.1, -0.05, -0.1, -0.05});
  SetFusionArray(u, "sensor_valid", {1, 1, 1, 1});
  SetFusionArray(u, "sensor_quality", {200, 200, 200, 200});
  const auto count_ref = *u.variables().Find("sensor_message_count");
  const auto match_ref = *u.variables().Find("match_count");
  const auto match_time_ref = *u.variables().Find("match_time");
  const auto laser_ref = *u.variables().Find("laser_position");
  constexpr TimeNs kStep = 20'000'000;
  TimeNs t = 0;
  std::int64_t step = 0;
  for (auto _ : state) {
    if (step % 2 == 0) {
      const double seconds = linesim::cosim::NsToSeconds(t);
      u.variables().SetRealElement(laser_ref, 0, 0.05 * seconds);
      u.variables().SetReal(match_time_ref, seconds - 0.02);
      u.variables().SetReal(match_ref, static_cast<double>(step / 2 + 1));
    }
    if (step % 5 == 0) {
      const double count = static_cast<double>(step / 5 + 1);
      for (std::size_t i = 0; i < 4; ++i) u.variables().SetRealElement(count_ref, i, count);
    }
    benchmark::DoNotOptimize(u.DoStep(t, kStep));
    t += kStep;
    ++step;
  }
}
BENCHMARK(BM_SurfaceFusionStep);

}  // namespace
