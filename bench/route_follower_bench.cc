// Cost of one route_follower sample (paper 2's controller) as the master
// drives it: set the pose, UpdateOutputs, DoStep (each evaluates the global
// closest-parameter search on the current segment: DoStep twice, before and
// after its commit), on the van bay's first edge (a cubic Hermite S-curve)
// with the robot moving along it.
// Counter: rtf = simulated seconds per second at the 20 ms control period.

#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "cosim/time.h"
#include "models/polynomial_path.h"
#include "units/control/route_follower_unit.h"

namespace {

using linesim::cosim::TimeNs;
constexpr TimeNs kCycle = 20'000'000;

void BM_RouteFollowerSample(benchmark::State& state) {
  namespace models = linesim::models;
  const std::vector<models::PolynomialSegment> route = {
      models::HermiteSegment(-1.5, -1.0, 0.0, 1.4, 0.0, 0.0, 0.0, 0),
      models::HermiteSegment(1.4, 0.0, 0.0, 4.4, 0.0, 0.0, 0.0, 0)};
  linesim::control::RouteFollowerUnit u("route", route);
  auto& v = u.variables();
  const auto position = *v.Find("position");
  const auto yaw = *v.Find("yaw");
  v.SetRealArray(position, std::vector<double>{-1.5, -1.0});
  u.Initialize();
  std::vector<double> p(2);
  TimeNs t = 0;
  int k = 0;
  for (auto _ : state) {
    // Along the first edge, 1 cm beside it, and back to the start.
    const double s = static_cast<double>(k % 500) / 500.0;
    const auto f = models::SegmentPosition(route[0], s);
    p[0] = f[0];
    p[1] = f[1] + 0.01;
    v.SetRealArray(position, p);
    v.SetReal(yaw, 0.1);
    u.UpdateOutputs();
    benchmark::DoNotOptimize(u.DoStep(t, kCycle));
    if (++k % 500 == 0) u.Initialize();  // back to segment 0
    t += kCycle;
  }
  state.counters["rtf"] = benchmark::Counter(0.02 * static_cast<double>(state.iterations()),
                                             benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RouteFollowerSample);

void BM_ClosestParameterCubic(benchmark::State& state) {
  namespace models = linesim::models;
  const auto s = models::HermiteSegment(-1.5, -1.0, 0.0, 1.4, 0.0, 0.0);
  double x = 0.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(models::ClosestParameter(s, x, -0.4));
    x = x > 1.0 ? -1.0 : x + 0.001;
  }
}
BENCHMARK(BM_ClosestParameterCubic);

}  // namespace
