#pragma once

// The spread of a statistic over seeds (or runs): what a test asserting on
// random draws or on a closed loop must check its bound against, since
// another seed or machine lands somewhere else inside it. Printed as
// "min / median / max over N" for the test log and the test's comment.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

namespace linesim::test_spread {

struct Spread {
  std::vector<double> values;  // in seed order
  /// The seed of each value, when known: the text then names the seeds of
  /// the smallest and the largest.
  std::vector<std::uint64_t> seeds = {};

  double min() const {
    return values.empty() ? std::nan("") : *std::min_element(values.begin(), values.end());
  }
  double max() const {
    return values.empty() ? std::nan("") : *std::max_element(values.begin(), values.end());
  }
  /// The k-th smallest value (0-based; the values are few: no copy, no sort).
  double kth(std::size_t k) const {
    for (double x : values) {
      std::size_t below = 0, at_or_below = 0;
      for (double y : values) {
        below += y < x;
        at_or_below += y <= x;
      }
      if (below <= k && k < at_or_below) return x;
    }
    return std::nan("");
  }
  double median() const {
    const std::size_t n = values.size();
    if (n == 0) return std::nan("");
    return n % 2 ? kth(n / 2) : 0.5 * (kth(n / 2 - 1) + kth(n / 2));
  }
  /// The largest magnitude (for signed errors bounded on both sides).
  double max_abs() const {
    double m = 0.0;
    for (double x : values) m = std::max(m, std::abs(x));
    return m;
  }
  std::string Text() const {
    if (values.empty()) return "no values";
    char buf[200];
    if (seeds.size() == values.size()) {
      const auto lo = std::min_element(values.begin(), values.end()) - values.begin();
      const auto hi = std::max_element(values.begin(), values.end()) - values.begin();
      std::snprintf(buf, sizeof buf,
                    "min %.6g (seed %llu) / median %.6g / max %.6g (seed %llu) over %zu", min(),
                    static_cast<unsigned long long>(seeds[static_cast<std::size_t>(lo)]), median(),
                    max(), static_cast<unsigned long long>(seeds[static_cast<std::size_t>(hi)]),
                    values.size());
    } else {
      std::snprintf(buf, sizeof buf, "min %.6g / median %.6g / max %.6g over %zu", min(), median(),
                    max(), values.size());
    }
    return buf;
  }
};

/// Prints `what: min / median / max over N` and returns the spread.
inline Spread Print(const std::string& what, std::vector<double> values) {
  Spread s{std::move(values)};
  std::printf("%s: %s\n", what.c_str(), s.Text().c_str());
  return s;
}

}  // namespace linesim::test_spread
