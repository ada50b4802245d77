#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "cosim/master.h"
#include "cosim/system.h"

namespace linesim::cosim {

/// One recorded scalar: a Real, Integer or Boolean variable, or one element
/// of a real array.
struct Probe {
  std::string label;  // "unit.variable" or "unit.variable[i]"
  System::Resolved where;
  VarType type;
};

/// Resolves names to probes: "unit.variable", "unit.variable[i]", a whole
/// array (one probe per element) or "unit.*" (every output of the unit).
/// Throws ConfigError listing every name that does not resolve.
std::vector<Probe> ResolveProbes(const System& system, const std::vector<std::string>& names);

double ReadProbe(const System& system, const Probe& probe);

/// Streams chosen variables to CSV: `time` in seconds, then one column per
/// probe. Rows are flushed in small batches and at the end of the run, also
/// a failed one, so that the file keeps what was recorded.
class CsvRecorder : public Observer {
 public:
  /// `interval` is the time between rows; 0 records every base step.
  CsvRecorder(std::ostream& out, std::vector<Probe> probes, TimeNs interval = 0);
  void OnStart(const Master& master) override;
  void OnSample(TimeNs t, const System& system) override;
  void OnEnd(TimeNs t, bool ok) override;
  std::int64_t rows() const { return rows_; }

 private:
  std::ostream& out_;
  std::vector<Probe> probes_;
  TimeNs interval_;
  TimeNs start_ = 0;
  std::int64_t rows_ = 0;
  std::string line_;
};

enum class Reduction { kFinal, kMin, kMax, kMaxAbs, kMean, kRms };
/// Parses "final", "min", "max", "max_abs", "mean", "rms"; false if unknown.
bool ParseReduction(const std::string& text, Reduction* out);
std::vector<std::string> ReductionNames();
/// The name ParseReduction reads.
std::string ToString(Reduction reduction);

struct MetricSpec {
  std::string name;
  Probe probe;
  Reduction reduction = Reduction::kFinal;
};

/// The metrics hook: reduces probes over every sample of a run (min, max,
/// mean over samples, ...) into named numbers.
class MetricsObserver : public Observer {
 public:
  explicit MetricsObserver(std::vector<MetricSpec> specs);
  void OnSample(TimeNs t, const System& system) override;
  /// Name and value of each metric, in the order given.
  std::vector<std::pair<std::string, double>> Results() const;
  /// One message per metric whose value is not finite (a reduction that
  /// overflowed, e.g. a mean of huge values, or no sample at all): a run
  /// with such a metric has failed, its numbers are not to be trusted.
  std::vector<std::string> NonFiniteResults() const;
  /// The same as run errors (phase metric, the metric's name as the
  /// variable), at `end`, the run's last time.
  std::vector<RunError> NonFiniteErrors(TimeNs end) const;

 private:
  struct Accumulator {
    double last = 0, min = 0, max = 0, max_abs = 0, sum = 0, sum_sq = 0;
  };
  std::vector<MetricSpec> specs_;
  std::vector<Accumulator> acc_;
  std::int64_t samples_ = 0;
};

}  // namespace linesim::cosim
