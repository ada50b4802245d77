#include "loader/reference.h"

#include <algorithm>
#include <limits>

namespace linesim::loader {

using config::Child;
using config::JoinPath;

Reference ReadReference(const YAML::Node& node, config::YamlReader& r) {
  Reference ref;
  if (!node.IsDefined() || !r.ExpectMap(node, "reference")) return ref;
  r.CheckKeys(node, "reference", {"title", "file", "metrics"});
  ref.title = r.String(node, "reference", "title", std::nullopt);
  ref.file = r.String(node, "reference", "file", "reference");
  const bool safe_file =
      !ref.file.empty() && std::all_of(ref.file.begin(), ref.file.end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
               c == '_' || c == '-';
      });
  if (!safe_file) {
    r.Error(Child(node, "file"), "reference.file",
            "expected a file name of [A-Za-z0-9_-] (without extension), got '" + ref.file + "'");
    ref.file = "reference";
  }
  const YAML::Node metrics = Child(node, "metrics");
  if (!metrics.IsDefined()) {
    r.Error(node, "reference.metrics",
            "missing required key: a map from metric name to {label, max_abs, std, mean_abs}");
    return ref;
  }
  if (!r.ExpectMap(metrics, "reference.metrics")) return ref;
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  for (const auto& kv : metrics) {
    ReferenceFigures m;
    m.metric = kv.first.IsScalar() ? kv.first.Scalar() : "";
    const std::string path = JoinPath("reference.metrics", m.metric);
    if (!r.ExpectMap(kv.second, path)) continue;
    r.CheckKeys(kv.second, path, {"label", "max_abs", "std", "mean_abs", "note"});
    m.label = r.String(kv.second, path, "label", m.metric);
    m.note = r.String(kv.second, path, "note", "");
    const auto figure = [&](const char* key) {
      return Child(kv.second, key).IsDefined() ? r.Real(kv.second, path, key, 0.0, {0.0, 1e300})
                                               : kNaN;
    };
    m.max_abs = figure("max_abs");
    m.std = figure("std");
    m.mean_abs = figure("mean_abs");
    ref.metrics.push_back(m);
  }
  return ref;
}

void CheckReferenceMetrics(const Reference& reference, const std::vector<std::string>& metrics,
                           const YAML::Node& root, const std::string& what,
                           config::YamlReader& r) {
  for (const auto& m : reference.metrics) {
    if (std::find(metrics.begin(), metrics.end(), m.metric) != metrics.end()) continue;
    const YAML::Node key = Child(Child(Child(root, "reference"), "metrics"), m.metric);
    r.Error(key, "reference.metrics." + m.metric,
            "'" + m.metric + "' is not a metric " + what +
                (metrics.empty() ? " (there are none)" : ": " + config::JoinNames(metrics)));
  }
}

}  // namespace linesim::loader
