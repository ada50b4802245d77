#pragma once

#include <charconv>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

/// Appending JSON text by hand, fast and the same on every machine: numbers
/// as std::to_chars writes them (the shortest text that reads back to the
/// same double, independent of the locale, as signals.csv has them), a
/// non-finite number as null (JSON has no NaN or infinity).
namespace linesim::mcap::json {

inline void Number(std::string& out, double v) {
  if (!std::isfinite(v)) {
    out += "null";
    return;
  }
  char buf[32];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, res.ptr);
}

inline void Integer(std::string& out, std::int64_t v) {
  char buf[24];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, res.ptr);
}

/// A quoted string with JSON's escapes.
void String(std::string& out, std::string_view s);

/// A Foxglove time or duration: {"sec":S,"nsec":N} of `ns` nanoseconds
/// (ns >= 0).
inline void Time(std::string& out, std::int64_t ns) {
  out += "{\"sec\":";
  Integer(out, ns / 1'000'000'000);
  out += ",\"nsec\":";
  Integer(out, ns % 1'000'000'000);
  out += '}';
}

}  // namespace linesim::mcap::json
