#pragma once

// The beam_counts key both scan localizers' registrations read (see
// config/unit_registry.h).

#include <optional>
#include <string>
#include <vector>

#include "config/unit_registry.h"
#include "units/estimation/scan_localizer.h"

namespace linesim::estimation {

/// One beam count per laser (1..ScanLocalizer::kMaxLasers lasers, each
/// 1..100000 beams) from the unit's `beam_counts`; nullopt after reporting.
/// `example` ends the message when the key is missing ("e.g. ...").
inline std::optional<std::vector<int>> ReadBeamCounts(const config::UnitBuildContext& c,
                                                      const std::string& example) {
  const YAML::Node list = config::Child(c.parameters, "beam_counts");
  const std::string path = config::JoinPath(c.path, "beam_counts");
  if (!list.IsDefined() || list.IsNull()) {
    c.reader.Error(
        c.parameters, c.path,
        "beam_counts is required: one entry per laser, its beam count (" + example + ")");
    return std::nullopt;
  }
  if (!c.reader.ExpectSequence(list, path)) return std::nullopt;
  if (list.size() < 1 || list.size() > ScanLocalizer::kMaxLasers) {
    c.reader.Error(list, path,
                   "beam_counts must list 1 to " + std::to_string(ScanLocalizer::kMaxLasers) +
                       " lasers, got " + std::to_string(list.size()));
    return std::nullopt;
  }
  std::vector<int> beams;
  bool ok = true;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const auto n =
        c.reader.AsInteger(list[i], config::JoinPath(path, std::to_string(i)), 1, 100000);
    if (!n) {
      ok = false;
      continue;
    }
    beams.push_back(static_cast<int>(*n));
  }
  if (!ok) return std::nullopt;
  return beams;
}

}  // namespace linesim::estimation
