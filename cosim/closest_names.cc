#include "cosim/closest_names.h"

#include <algorithm>
#include <numeric>

namespace linesim::cosim {

std::size_t EditDistance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  std::iota(row.begin(), row.end(), 0);
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

std::vector<std::string> ClosestNames(std::string_view name,
                                      const std::vector<std::string>& candidates,
                                      std::size_t max_count) {
  struct Scored {
    std::size_t score;
    std::string name;
  };
  std::vector<Scored> scored;
  const std::size_t limit = std::max<std::size_t>(2, name.size() / 2);
  for (const auto& c : candidates) {
    std::size_t d = EditDistance(name, c);
    const bool contains = !name.empty() && (c.find(name) != std::string::npos ||
                                            name.find(c) != std::string_view::npos);
    if (contains) d = std::min<std::size_t>(d, 1);
    if (d <= limit) scored.push_back({d, c});
  }
  std::stable_sort(scored.begin(), scored.end(),
                   [](const Scored& x, const Scored& y) { return x.score < y.score; });
  std::vector<std::string> out;
  for (std::size_t i = 0; i < scored.size() && out.size() < max_count; ++i) {
    if (std::find(out.begin(), out.end(), scored[i].name) == out.end()) {
      out.push_back(scored[i].name);
    }
  }
  return out;
}

std::string ClosestHint(std::string_view name, const std::vector<std::string>& candidates) {
  const auto close = ClosestNames(name, candidates);
  if (close.empty()) return "";
  std::string out = " (closest: ";
  for (std::size_t i = 0; i < close.size(); ++i) out += (i ? ", " : "") + close[i];
  return out + ")";
}

}  // namespace linesim::cosim
