#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace linesim::cosim {

/// Simulation time: an integer count of nanoseconds, so that step sums are
/// exact and communication points of different rates coincide exactly.
using TimeNs = std::int64_t;

inline constexpr TimeNs kNsPerSecond = 1'000'000'000;

/// The longest time, in seconds, a file, a parameter or a signal may give
/// (146 years): half of what int64 nanoseconds hold (9.22e9 s), so that a
/// time plus a duration (a restart delay added to the time a field
/// cleared) still fits. Every time in seconds that linesim converts to
/// nanoseconds is checked against it where it is read: a parameter whose
/// unit is "s" by its rule (Rule::Time), a file's time by
/// config::YamlReader::Time, a signal by Unit::InputTimeNs.
inline constexpr double kMaxTimeSeconds = 4.6e9;
/// The time resolution, 1 ns: a non-zero time shorter than this would
/// round to 0.
inline constexpr double kTimeResolutionSeconds = 1e-9;

/// Why `seconds` is no time linesim represents ("is nan", "is beyond
/// +-4.6e9 s, ..."), or nothing. Zero and anything from 1 ns to
/// kMaxTimeSeconds (either sign) are times.
std::optional<std::string> TimeProblem(double seconds);

/// Seconds to nanoseconds, rounded to the nearest nanosecond; throws
/// std::out_of_range when the result does not fit in int64 (callers check
/// what they read against kMaxTimeSeconds first, to say so at its key).
TimeNs SecondsToNs(double seconds);

// Division, not multiplication by 1e-9 (which is inexact): 9 ms gives
// exactly the double nearest 0.009.
inline double NsToSeconds(TimeNs t) { return static_cast<double>(t) / 1e9; }

/// Exact decimal seconds ("0.001", "12", "-0.5") with no floating-point
/// rounding: used in CSV time columns and messages.
std::string FormatSeconds(TimeNs t);

}  // namespace linesim::cosim
