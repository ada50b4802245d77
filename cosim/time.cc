#include "cosim/time.h"

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>

namespace linesim::cosim {

std::optional<std::string> TimeProblem(double seconds) {
  if (!std::isfinite(seconds)) {
    return std::string(std::isnan(seconds) ? "is nan" : "is infinite") + ", not a time";
  }
  if (std::abs(seconds) > kMaxTimeSeconds) {
    return "is beyond +-4.6e9 s, the longest time linesim represents (int64 nanoseconds, "
           "with room for a time plus a duration)";
  }
  if (seconds != 0.0 && std::abs(seconds) < kTimeResolutionSeconds) {
    return std::string("is below 1 ns, the time resolution (it would round to 0)");
  }
  return std::nullopt;
}

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
  // The magnitude as unsigned: -t overflows for the most negative time.
  std::uint64_t magnitude = static_cast<std::uint64_t>(t);
  if (t < 0) {
    out = "-";
    magnitude = 0 - magnitude;
  }
  const auto ns_per_s = static_cast<std::uint64_t>(kNsPerSecond);
  out += std::to_string(magnitude / ns_per_s);
  const std::uint64_t frac = magnitude % ns_per_s;
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
