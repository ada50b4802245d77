#include "sweep/run_plan.h"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "cosim/seed.h"
#include "cosim/variable_table.h"

namespace linesim::sweep {

namespace {

std::int64_t PointCount(const SweepSpec& spec) {
  std::int64_t n = 1;
  for (const auto& p : spec.parameters) {
    if (p.kind != ParameterKind::kRandom) n *= static_cast<std::int64_t>(p.values.size());
  }
  return n;
}

// splitmix64: the next value of a seed-driven stream.
std::uint64_t Mix(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// The draw of a random parameter for one Monte-Carlo sample: seeded by the
// parameter's path and the sample number, so it does not change when other
// parameters are added, removed or reordered, and every grid point sees it.
double Draw(const SweepSpec& spec, const ParameterSpec& p, std::int64_t sample) {
  const std::uint64_t seed =
      cosim::DeriveSeed(spec.seed, "draw " + p.path + " sample " + std::to_string(sample));
  const double u = UniformDraw(seed);
  switch (p.distribution) {
    case Distribution::kUniform:
      return p.a + (p.b - p.a) * u;
    case Distribution::kLogUniform:
      return std::exp(std::log(p.a) + (std::log(p.b) - std::log(p.a)) * u);
    case Distribution::kNormal: {
      // Box-Muller with a second independent draw; 1 - u is in (0, 1].
      const double u2 = UniformDraw(Mix(seed));
      return p.a +
             p.b * std::sqrt(-2.0 * std::log(1.0 - u)) * std::cos(2.0 * std::numbers::pi * u2);
    }
  }
  return p.a;
}

}  // namespace

double UniformDraw(std::uint64_t seed) { return static_cast<double>(Mix(seed) >> 11) * 0x1.0p-53; }

std::int64_t RunCount(const SweepSpec& spec) {
  return PointCount(spec) * spec.samples * spec.repeats;
}

RunSpec PlanRun(const SweepSpec& spec, std::int64_t id) {
  if (id < 0 || id >= RunCount(spec)) {
    throw std::out_of_range("run id " + std::to_string(id) + " is not in the sweep (0 to " +
                            std::to_string(RunCount(spec) - 1) + ")");
  }
  RunSpec run;
  run.id = id;
  run.repeat = id % spec.repeats;
  run.sample = (id / spec.repeats) % spec.samples;
  run.point = id / spec.repeats / spec.samples;
  run.values.resize(spec.parameters.size());
  std::int64_t rest = run.point;
  for (std::size_t i = spec.parameters.size(); i-- > 0;) {
    const ParameterSpec& p = spec.parameters[i];
    if (p.kind == ParameterKind::kRandom) {
      run.values[i] = cosim::FormatValue(Draw(spec, p, run.sample));
    } else {
      const auto n = static_cast<std::int64_t>(p.values.size());
      run.values[i] = p.values[static_cast<std::size_t>(rest % n)];
      rest /= n;
    }
  }
  const std::int64_t stream =
      spec.seeds == SeedPolicy::kCommon ? run.sample * spec.repeats + run.repeat : id;
  // Scenario seeds stay in int64 range: the scenario file reads them as one.
  run.seed = cosim::DeriveSeed(spec.seed, (spec.seeds == SeedPolicy::kCommon ? "seed " : "run ") +
                                              std::to_string(stream)) >>
             1;
  return run;
}

std::vector<std::string> RunOverrides(const SweepSpec& spec, const RunSpec& run) {
  std::vector<std::string> args{"seed=" + std::to_string(run.seed)};
  for (const auto& a : FixedOverrides(spec)) args.push_back(a);
  for (std::size_t i = 0; i < spec.parameters.size(); ++i) {
    args.push_back(spec.parameters[i].path + "=" + run.values[i]);
  }
  return args;
}

}  // namespace linesim::sweep
