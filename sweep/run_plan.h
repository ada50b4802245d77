#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sweep/sweep_spec.h"

namespace linesim::sweep {

/// One run of a sweep: which point, draw and repeat it is, the value of
/// each parameter (YAML text, as `--set` takes it) and its scenario seed.
struct RunSpec {
  std::int64_t id = 0;
  std::int64_t point = 0;   // combination of the listed values (grid order)
  std::int64_t sample = 0;  // Monte-Carlo draw
  std::int64_t repeat = 0;
  std::vector<std::string> values;  // one per parameter
  std::uint64_t seed = 0;
};

/// Points x samples x repeats.
std::int64_t RunCount(const SweepSpec& spec);

/// Run `id` alone. Depends only on the spec and the id, never on which runs
/// were planned before, so any rank or thread plans the same run. Ids count
/// repeats fastest, then samples, then points; points count the last
/// parameter fastest.
RunSpec PlanRun(const SweepSpec& spec, std::int64_t id);

/// The `--set` arguments of a run: its seed, then the sweep's fixed
/// settings, then its parameter values (a later one wins).
std::vector<std::string> RunOverrides(const SweepSpec& spec, const RunSpec& run);

/// A draw in [0, 1) from a 64-bit seed. Written out rather than a
/// std:: distribution, whose algorithms differ between standard libraries:
/// a sweep must draw the same values everywhere.
double UniformDraw(std::uint64_t seed);

}  // namespace linesim::sweep
