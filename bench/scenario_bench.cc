// Real-time factor of whole shipped scenarios: load, build and run through
// the master as `linesim run` does, without writing files.
//
// Counters: rtf = simulated seconds per wall second on this (single) thread;
// share_<unit> = that unit's share of the wall time (the master's per-unit
// profile, two clock reads per unit step); the rest is the master itself.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "session/session.h"

namespace {

void BM_Scenario(benchmark::State& state, const std::string& file,
                 const std::vector<std::string>& sets) {
  double simulated_s = 0;
  double total_wall_s = 0;
  std::map<std::string, double> unit_wall_s;
  for (auto _ : state) {
    // Building the system and tearing it down are not part of the cost per
    // simulated second: both are outside the timing.
    state.PauseTiming();
    auto run = std::make_unique<linesim::session::Session>(file, sets);
    state.ResumeTiming();
    const auto result = run->Run().result;
    state.PauseTiming();
    if (!result.ok) {
      state.SkipWithError(result.ErrorText().c_str());
      break;
    }
    const linesim::loader::Scenario& s = run->scenario();
    simulated_s += linesim::cosim::NsToSeconds(result.end_time);
    total_wall_s += s.master->total_wall_seconds();
    for (std::size_t u = 0; u < s.system->unit_count(); ++u) {
      unit_wall_s[s.system->unit(u).name()] += s.master->unit_wall_seconds()[u];
    }
    run.reset();
    state.ResumeTiming();
  }
  state.counters["rtf"] = benchmark::Counter(simulated_s, benchmark::Counter::kIsRate);
  for (const auto& [name, wall_s] : unit_wall_s) {
    state.counters["share_" + name] = total_wall_s > 0 ? wall_s / total_wall_s : 0.0;
  }
}

#define LINESIM_SCENARIO(name, file, ...)                                                  \
  BENCHMARK_CAPTURE(BM_Scenario, name, std::string(LINESIM_SOURCE_DIR "/scenarios/" file), \
                    std::vector<std::string>{__VA_ARGS__})                                 \
      ->Unit(benchmark::kMillisecond)                                                      \
      ->MeasureProcessCPUTime()                                                            \
      ->UseRealTime()

// A fleet of N Rob@Work 3 on the factory line, every sensor on, each on
// ground-truth control following its own 1.5 m path (two rows of five along
// the line, 5 m apart): the cost per simulated second grows with N (each
// chassis, laser and clearance meets the N - 1 others). Issue 22: at most
// N x 1.15 of one robot's.
// Robots first..n-1 of such a fleet (a file per robot for BM_FleetApart).
std::string FleetFile(int n, int first = 0) {
  std::string text =
      "name: fleet_bench\nduration_s: 5\nseed: 1\n"
      "master: {algorithm: gauss_seidel, step_s: 0.005}\nscene: {model: factory_line}\n"
      "robots:\n";
  for (int k = first; k < n; ++k) {
    const std::string x = std::to_string(-10 + 5 * (k % 5)), y = k < 5 ? "-5" : "-3";
    const std::string x1 = std::to_string(-10 + 5 * (k % 5) + 1.5);
    text += "  - {name: r" + std::to_string(k) + ", model: raw3, pose: {x_m: " + x + ", y_m: " + y +
            ", yaw_deg: 0}, task: {type: path, waypoints: [[" + x + ", " + y + "], [" + x1 + ", " +
            y +
            "]], speed_mps: 0.3}, sensing: {surface_velocity: ground_truth}, "
            "localization: {source: ground_truth}}\n";
  }
  const auto path =
      std::filesystem::temp_directory_path() /
      ("linesim_fleet_bench_" + std::to_string(first) + "_" + std::to_string(n) + ".yaml");
  std::ofstream(path) << text;
  return path.string();
}

void BM_Fleet(benchmark::State& state) {
  BM_Scenario(state, FleetFile(static_cast<int>(state.range(0))), {});
  state.counters["robots"] = static_cast<double>(state.range(0));
}
BENCHMARK(BM_Fleet)
    ->Arg(1)
    ->Arg(3)
    ->Arg(10)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// The same N robots, each alone in its own session (a world of its own:
// none sees or touches another), stepped in turn base step by base step
// in one process as BM_Fleet's master steps them: what N robots cost
// without sharing a world, so BM_Fleet / BM_FleetApart at the same N is
// the price of the shared world itself, and BM_FleetApart's growth per
// robot is the memory hierarchy's (no metrics observer here: compare
// BM_FleetApart's N with its own N = 1).
void BM_FleetApart(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  std::vector<std::string> files;
  for (int k = 0; k < n; ++k) files.push_back(FleetFile(k + 1, k));
  for (auto _ : state) {
    state.PauseTiming();
    std::vector<std::unique_ptr<linesim::session::Session>> runs;
    for (const auto& file : files) {
      runs.push_back(std::make_unique<linesim::session::Session>(file, std::vector<std::string>{}));
    }
    state.ResumeTiming();
    for (auto& run : runs) run->scenario().master->Start();
    for (bool more = true; more;) {
      for (auto& run : runs) more = run->scenario().master->Step() && more;
    }
    std::string error;
    for (auto& run : runs) {
      const auto result = run->scenario().master->Finish();
      if (!result.ok && error.empty()) error = result.ErrorText();
    }
    state.PauseTiming();
    runs.clear();
    state.ResumeTiming();
    if (!error.empty()) {
      state.SkipWithError(error.c_str());
      break;
    }
  }
  state.counters["robots"] = n;
}
BENCHMARK(BM_FleetApart)
    ->Arg(1)
    ->Arg(10)
    ->Unit(benchmark::kMillisecond)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

LINESIM_SCENARIO(motor_step, "motor_step.yaml");
LINESIM_SCENARIO(cross_line, "cross_line.yaml");
// Side by side: the same crossing without any sensor (the ground-truth loop
// alone), and with the sensors but without the PX4Flow or the lasers.
LINESIM_SCENARIO(cross_line_no_sensors, "cross_line.yaml", "sensors.default=false");
LINESIM_SCENARIO(cross_line_no_lasers, "cross_line.yaml", "sensors.laser_front=false",
                 "sensors.laser_rear=false");
LINESIM_SCENARIO(cross_line_no_flow, "cross_line.yaml", "sensors.flow_front_left=false",
                 "sensors.flow_rear_left=false", "sensors.flow_rear_right=false",
                 "sensors.flow_front_right=false");
LINESIM_SCENARIO(cross_line_nominal, "cross_line.yaml", "control.compensation=false");
// The closed loop (the robot's own sensors: PX4Flow surface velocity,
// fused odometry and scan matching), at the shipped 5 ms step and at the
// 1 ms step the ground-truth numbers were first measured with.
LINESIM_SCENARIO(cross_line_closed_loop, "cross_line.yaml", "sensing.surface_velocity=px4flow",
                 "localization.source=fused");
LINESIM_SCENARIO(cross_line_closed_loop_1ms, "cross_line.yaml", "sensing.surface_velocity=px4flow",
                 "localization.source=fused", "master.step_s=0.001");
LINESIM_SCENARIO(cross_line_no_sensors_1ms, "cross_line.yaml", "sensors.default=false",
                 "master.step_s=0.001");
LINESIM_SCENARIO(hold_on_belt, "hold_on_belt.yaml");
LINESIM_SCENARIO(hold_straddle, "hold_straddle.yaml");
LINESIM_SCENARIO(husky_floor_path, "husky_floor_path.yaml");
LINESIM_SCENARIO(optic_flow_profile, "optic_flow_profile.yaml");
// Paper 2's van entry with the whole chain (LMS151 in 3D, Perfect Match, the
// EKF, the beacons, the route follower, the Husky on the ramp), beside the
// same route on the ground truth without sensors.
LINESIM_SCENARIO(van_entry, "van_entry.yaml");
// The fleet on the line with the Rob@Work 3s on their own sensors (fused
// flow and fused localization; the Husky on the ground truth, it has no
// PX4Flow), beside one robot's closed loop (cross_line_closed_loop).
LINESIM_SCENARIO(fleet_line, "fleet_line.yaml");
LINESIM_SCENARIO(fleet_line_closed_loop, "fleet_line.yaml",
                 "robots.0.sensing.surface_velocity=fused_flow",
                 "robots.0.localization.source=fused",
                 "robots.1.sensing.surface_velocity=fused_flow",
                 "robots.1.localization.source=fused");
LINESIM_SCENARIO(van_entry_ground_truth, "van_entry.yaml", "sensors.default=false",
                 "localization.source=ground_truth");

}  // namespace
