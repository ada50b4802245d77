#pragma once

// The spread of a statistic over seeds (or runs): what a test asserting on
// random draws or on a closed loop must check its bound against, since
// another seed or machine lands somewhere else inside it. Printed as
// "min / median / max over N" for the test log and the test's comment.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

namespace linesim::test_spread {

struct Spread {
  std::vector<double> values;  // in seed order

  double min() const { return *std::min_element(values.begin(), values.end()); }
  double max() const { return *std::max_element(values.begin(), values.end()); }
  double median() const {
    std::vector<double> v = values;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  }
  /// The largest magnitude (for signed errors bounded on both sides).
  double max_abs() const {
    double m = 0.0;
    for (double x : values) m = std::max(m, std::abs(x));
    return m;
  }
  std::string Text() const {
    if (values.empty()) return "no values";
    char buf[160];
    std::snprintf(buf, sizeof buf, "min %.6g / median %.6g / max %.6g over %zu", min(), median(),
                  max(), values.size());
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
