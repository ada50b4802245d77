// Cost of the estimation family's wheel odometry and pose fusion, driven
// directly as the master drives them: one odometry sample of the Rob@Work
// 3 (8 encoder channels: set inputs, UpdateOutputs, DoStep), one fusion
// step without a match (the prediction), and one with a new match (the
// prediction plus the correction; "delayed" matches refer to 40 ms
// before now, so two buffered steps are re-predicted after it).
// Counter: rtf = simulated seconds per second at the 20 ms control period.

#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "cosim/time.h"
#include "units/estimation/pose_fusion_unit.h"
#include "units/estimation/wheel_odometry_unit.h"

namespace {

using linesim::cosim::TimeNs;
using linesim::cosim::Value;
namespace estimation = linesim::estimation;

constexpr TimeNs kMs = 1'000'000;
constexpr TimeNs kCycle = 20 * kMs;

void Set(linesim::cosim::Unit& u, const char* name, const Value& v) {
  u.variables().SetValue(*u.variables().Find(name), v);
}

void Rtf(benchmark::State& state) {
  state.counters["rtf"] = benchmark::Counter(0.02 * static_cast<double>(state.iterations()),
                                             benchmark::Counter::kIsRate);
}

void BM_WheelOdometrySwerve8(benchmark::State& state) {
  estimation::WheelOdometryUnit u("odo", estimation::WheelOdometryUnit::Kind::kSwerve, 4);
  Set(u, "wheel_x", std::vector<double>{0.368, -0.368, -0.368, 0.368});
  Set(u, "wheel_y", std::vector<double>{0.186, 0.134, -0.186, -0.134});
  Set(u, "wheel_radius", 0.08);
  Set(u, "counts_per_revolution",
      std::vector<double>{16384, 16384, 16384, 16384, 86016, 86016, 86016, 86016});
  Set(u, "initial_x", 0.0);
  Set(u, "initial_y", 0.0);
  Set(u, "initial_yaw", 0.0);
  u.Setup(0, 0);
  u.Initialize();
  const auto counts = *u.variables().Find("counts");
  const auto surface = *u.variables().Find("surface_velocity");
  std::vector<double> c{1000, 1100, -900, 3000, 0, 0, 0, 0};
  const std::vector<double> s{0.1, 0.0, 0.1, 0.0, 0.0, 0.0, 0.0, 0.0};
  TimeNs t = 0;
  for (auto _ : state) {
    for (std::size_t i = 4; i < 8; ++i) c[i] += 100.0 + static_cast<double>(i);
    u.variables().SetRealArray(counts, c);
    u.variables().SetRealArray(surface, s);
    u.UpdateOutputs();
    benchmark::DoNotOptimize(u.DoStep(t, kCycle));
    t += kCycle;
  }
  Rtf(state);
}
BENCHMARK(BM_WheelOdometrySwerve8);

// match: a new match at every step (else none: prediction only); delay:
// how far before now the match refers to.
void FusionSteps(benchmark::State& state, bool match, TimeNs delay) {
  estimation::PoseFusionUnit u("fusion");
  Set(u, "initial_x", 0.0);
  Set(u, "initial_y", 0.0);
  Set(u, "initial_yaw", 0.0);
  Set(u, "match_covariance", std::vector<double>{1e-4, 0, 0, 0, 1e-4, 0, 0, 0, 2.5e-5});
  Set(u, "odometry_velocity", std::vector<double>{0.3, 0.0});
  Set(u, "odometry_yaw_rate", 0.1);
  u.Setup(0, 0);
  u.Initialize();
  const auto position = *u.variables().Find("match_position");
  const auto yaw = *u.variables().Find("match_yaw");
  const auto time = *u.variables().Find("match_time");
  const auto count = *u.variables().Find("match_count");
  TimeNs t = 0;
  double n = 0.0;
  // A history to match into.
  for (int k = 0; k < 10; ++k) {
    (void)u.DoStep(t, kCycle);
    t += kCycle;
  }
  std::vector<double> p{0.0, 0.0};
  for (auto _ : state) {
    if (match) {
      const double s = linesim::cosim::NsToSeconds(t - delay);
      // Near the pose the odometry gives (the arc of 0.3 m/s, 0.1 rad/s).
      p[0] = 3.0 * std::sin(0.1 * s);
      p[1] = 3.0 * (1.0 - std::cos(0.1 * s));
      u.variables().SetRealArray(position, p);
      u.variables().SetReal(yaw, 0.1 * s);
      u.variables().SetReal(time, s);
      n += 1.0;
      u.variables().SetReal(count, n);
    }
    benchmark::DoNotOptimize(u.DoStep(t, kCycle));
    t += kCycle;
  }
  Rtf(state);
  // The share of matches the gate accepted (1: every correction was done).
  if (match) {
    state.counters["accepted"] = u.variables().GetReal(*u.variables().Find("accepted_matches")) / n;
  }
}

void BM_FusionPredict(benchmark::State& state) { FusionSteps(state, false, 0); }
BENCHMARK(BM_FusionPredict);
void BM_FusionPredictAndCorrectNow(benchmark::State& state) { FusionSteps(state, true, 0); }
BENCHMARK(BM_FusionPredictAndCorrectNow);
void BM_FusionPredictAndCorrectDelayed40ms(benchmark::State& state) {
  FusionSteps(state, true, 40 * kMs);
}
BENCHMARK(BM_FusionPredictAndCorrectDelayed40ms);

}  // namespace
