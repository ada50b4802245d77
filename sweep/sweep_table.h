#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "loader/reference.h"

namespace linesim::sweep {

/// The finished runs of a sweep, as the report (summary.json, the terminal
/// table and the plots) reads them: one row per run, sorted by run id.
struct SweepTable {
  std::string name;
  /// The varied parameters by dotted path, in the sweep file's order.
  std::vector<std::string> parameters;
  /// For each parameter, its distinct values in plan order as the YAML text
  /// the run was given ("0.05", "true", "jacobi"); empty for a parameter
  /// drawn at random (every run has its own value).
  std::vector<std::vector<std::string>> levels;
  /// Metric names as results.csv writes them; the last one is "wall_s",
  /// the run's wall-clock time.
  std::vector<std::string> metrics;
  /// True for `combine: grid`; false for Monte-Carlo draws.
  bool grid = true;

  /// Published figures to print beside the sweep's own (empty title:
  /// none); each of its metrics is one of `metrics`.
  loader::Reference reference;
  /// What the results depend on beyond the sweep file (platform::ProvenanceJson).
  nlohmann::json provenance;

  struct Row {
    std::int64_t id = 0;
    std::vector<std::string> values;  // one per parameter
    std::uint64_t seed = 0;
    bool ok = false;
    std::vector<double> metrics;  // one per metric; NaN when not ok
    std::string error;            // empty when ok
    /// The first failure's fields, as results.csv has them (empty when ok
    /// or when the field does not apply).
    std::string error_unit;
    std::optional<double> error_time_s;
    std::string error_phase;
    std::string error_variable;
    std::string error_cause;
  };
  std::vector<Row> rows;
};

}  // namespace linesim::sweep
