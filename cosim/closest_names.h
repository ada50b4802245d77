#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace linesim::cosim {

/// Levenshtein edit distance.
std::size_t EditDistance(std::string_view a, std::string_view b);

/// Up to `max_count` candidates close to `name` (by edit distance, with a
/// bonus for a shared prefix or containment), best first, for "did you mean"
/// messages. Empty when nothing is plausibly meant.
std::vector<std::string> ClosestNames(std::string_view name,
                                      const std::vector<std::string>& candidates,
                                      std::size_t max_count = 3);

/// " (closest: a, b)" or "" when there is nothing close.
std::string ClosestHint(std::string_view name, const std::vector<std::string>& candidates);

}  // namespace linesim::cosim
