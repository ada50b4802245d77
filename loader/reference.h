#pragma once

#include <string>
#include <vector>
#include <yaml-cpp/yaml.h>

#include "config/yaml_reader.h"

namespace linesim::loader {

/// Published figures of one metric over repeated runs: the largest absolute
/// value, the sample standard deviation and the mean absolute value (as
/// paper 2's Table 1 reports its 20 runs); NaN where the source gives none.
struct ReferenceFigures {
  std::string metric;
  std::string label;  // the column's heading, e.g. "X (m)"
  double max_abs = 0.0, std = 0.0, mean_abs = 0.0;
  /// What makes this metric's spread in the simulation (optional, for the
  /// written table).
  std::string note;
};

/// `reference: {title, file, metrics: {METRIC: {label, max_abs, std,
/// mean_abs, note}}}` of a scenario or sweep file: what repeated runs print
/// beside their own figures, and write as FILE.csv and FILE.md beside
/// summary.json (file: [A-Za-z0-9_-], default "reference"). An empty title
/// means none.
struct Reference {
  std::string title;
  std::vector<ReferenceFigures> metrics;
  std::string file = "reference";
};

/// Reads the `reference` node of a file (absent: an empty Reference),
/// reporting problems through `r` at `reference...` key paths.
Reference ReadReference(const YAML::Node& node, config::YamlReader& r);

/// Reports, at `reference.metrics.NAME` of `root`'s `reference`, each metric
/// of `reference` that is not among `metrics` (`what` says whose they are).
void CheckReferenceMetrics(const Reference& reference, const std::vector<std::string>& metrics,
                           const YAML::Node& root, const std::string& what,
                           config::YamlReader& r);

}  // namespace linesim::loader
