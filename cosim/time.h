#pragma once

#include <cstdint>
#include <string>

namespace linesim::cosim {

/// Simulation time: an integer count of nanoseconds, so that step sums are
/// exact and communication points of different rates coincide exactly.
using TimeNs = std::int64_t;

inline constexpr TimeNs kNsPerSecond = 1'000'000'000;

/// Seconds to nanoseconds, rounded to the nearest nanosecond.
TimeNs SecondsToNs(double seconds);

// Division, not multiplication by 1e-9 (which is inexact): 9 ms gives
// exactly the double nearest 0.009.
inline double NsToSeconds(TimeNs t) { return static_cast<double>(t) / 1e9; }

/// Exact decimal seconds ("0.001", "12", "-0.5") with no floating-point
/// rounding: used in CSV time columns and messages.
std::string FormatSeconds(TimeNs t);

}  // namespace linesim::cosim
