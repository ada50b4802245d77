#pragma once

#include <charconv>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

#include "json_text/json_string.h"

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

/// `v` rounded to 1e-4 (|v| < 9e14), trailing zeros dropped: "2.35",
/// "-0.0012", "3". A few times cheaper than the shortest round-trip text,
/// for bulk data whose precision is coarser (laser ranges).
inline void TenthMillimetres(std::string& out, double v) {
  if (!std::isfinite(v) || std::abs(v) >= 9e14) {
    Number(out, v);
    return;
  }
  std::int64_t n = std::llround(v * 1e4);
  if (n < 0) {
    out += '-';
    n = -n;
  }
  Integer(out, n / 10000);
  int frac = static_cast<int>(n % 10000);
  if (frac == 0) return;
  char digits[5] = {'.', '0', '0', '0', '0'};
  int end = 5;
  for (int k = 4; k >= 1; --k) {
    digits[k] = static_cast<char>('0' + frac % 10);
    frac /= 10;
  }
  while (digits[end - 1] == '0') --end;
  out.append(digits, static_cast<std::size_t>(end));
}

/// A quoted string with JSON's escapes.
inline void String(std::string& out, std::string_view s) { json_text::AppendString(out, s); }

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
