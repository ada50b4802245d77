#include "cosim/time.h"

#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace linesim::cosim {

TimeNs SecondsToNs(double seconds) {
  const double ns = std::round(seconds * 1e9);
  if (!std::isfinite(ns) || std::abs(ns) > 9.2e18) {
    throw std::out_of_range("time of " + std::to_string(seconds) +
                            " s does not fit in int64 nanoseconds");
  }
  return static_cast<TimeNs>(ns);
}

std::string FormatSeconds(TimeNs t) {
  std::string out;
  if (t < 0) {
    out = "-";
    t = -t;
  }
  out += std::to_string(t / kNsPerSecond);
  TimeNs frac = t % kNsPerSecond;
  if (frac != 0) {
    std::string digits = std::to_string(frac);
    digits.insert(0, 9 - digits.size(), '0');
    while (digits.back() == '0') digits.pop_back();
    out.push_back('.');
    out.append(digits);
  }
  return out;
}

}  // namespace linesim::cosim
