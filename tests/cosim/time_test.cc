// Integer nanosecond time: conversion from seconds and exact formatting.

#include "cosim/time.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace linesim::cosim {
namespace {

// Guards against: truncation instead of rounding. k * 0.001 is not exactly
// representable, so k * 0.001 * 1e9 lands just below or above k * 1e6;
// truncating would give k * 1e6 - 1 for some k. Expected: exactly k ms.
TEST(SecondsToNs, RoundsToTheNearestNanosecond) {
  for (int k = 0; k <= 100000; ++k) {
    ASSERT_EQ(SecondsToNs(k * 0.001), static_cast<TimeNs>(k) * 1'000'000) << "k = " << k;
  }
  EXPECT_EQ(SecondsToNs(0.1), 100'000'000);
  EXPECT_EQ(SecondsToNs(1.0000000004), 1'000'000'000);  // 0.4 ns rounds down
  EXPECT_EQ(SecondsToNs(1.0000000006), 1'000'000'001);  // 0.6 ns rounds up
  EXPECT_EQ(SecondsToNs(-0.0014999999), -1'500'000);
  EXPECT_EQ(SecondsToNs(-2.0000000006), -2'000'000'001);
  EXPECT_EQ(SecondsToNs(9e9), 9'000'000'000'000'000'000);  // 285 years fit
}

// Guards against: undefined behavior casting a non-finite or too large value
// to int64 (int64 ns holds about +-9.22e9 s).
TEST(SecondsToNs, RefusesValuesThatDoNotFit) {
  EXPECT_THROW(SecondsToNs(std::numeric_limits<double>::quiet_NaN()), std::out_of_range);
  EXPECT_THROW(SecondsToNs(std::numeric_limits<double>::infinity()), std::out_of_range);
  EXPECT_THROW(SecondsToNs(1e10), std::out_of_range);
  EXPECT_THROW(SecondsToNs(-1e10), std::out_of_range);
}

// Guards against: floating-point rounding in CSV time columns and messages
// ("0.30000000000000004", "1e-09") and trailing zeros. Expected strings are
// the exact decimal value of the nanosecond count.
TEST(FormatSeconds, ExactDecimalSeconds) {
  EXPECT_EQ(FormatSeconds(0), "0");
  EXPECT_EQ(FormatSeconds(1), "0.000000001");
  EXPECT_EQ(FormatSeconds(1'000'000), "0.001");
  EXPECT_EQ(FormatSeconds(300'000'000), "0.3");
  EXPECT_EQ(FormatSeconds(1'500'000'000), "1.5");
  EXPECT_EQ(FormatSeconds(12'000'000'000), "12");
  EXPECT_EQ(FormatSeconds(123'456'789'012), "123.456789012");
  EXPECT_EQ(FormatSeconds(-500'000'000), "-0.5");
  EXPECT_EQ(FormatSeconds(-1), "-0.000000001");
}

// Guards against: overflow when negating the most negative time (undefined
// behavior that printed "--9.-22..." in practice). Expected: the decimal
// value of +-(2^63 - 1) ns and -2^63 ns.
TEST(FormatSeconds, ExtremeValues) {
  EXPECT_EQ(FormatSeconds(std::numeric_limits<TimeNs>::max()), "9223372036.854775807");
  EXPECT_EQ(FormatSeconds(std::numeric_limits<TimeNs>::min()), "-9223372036.854775808");
}

// Guards against: a wrong scale factor in the other direction.
TEST(NsToSeconds, ScalesByOneBillion) {
  EXPECT_EQ(NsToSeconds(1'500'000'000), 1.5);
  EXPECT_EQ(NsToSeconds(-2'000'000), -0.002);
  // Correctly rounded: the nearest doubles to the decimals (9, 11, 13 ms
  // are among those t * 1e-9 misses by one unit in the last place).
  EXPECT_EQ(NsToSeconds(9'000'000), 0.009);
  EXPECT_EQ(NsToSeconds(11'000'000), 0.011);
  EXPECT_EQ(NsToSeconds(13'000'000), 0.013);
  EXPECT_EQ(NsToSeconds(0), 0.0);
}

}  // namespace
}  // namespace linesim::cosim

namespace linesim::cosim {
namespace {

// Guards issue 37's one limit for every time linesim converts: zero and 1 ns
// to kMaxTimeSeconds (4.6e9 s, half of int64 nanoseconds, so that a time
// plus a duration fits: 4.6e18 + 4.6e18 < 9.22e18) of either sign are
// times; nothing else is, and the reason is given.
TEST(TimeProblem, NamesTheLimit) {
  EXPECT_FALSE(TimeProblem(0.0));
  EXPECT_FALSE(TimeProblem(1e-9));
  EXPECT_FALSE(TimeProblem(-2.5));
  EXPECT_FALSE(TimeProblem(kMaxTimeSeconds));
  EXPECT_FALSE(TimeProblem(-kMaxTimeSeconds));
  EXPECT_LT(2.0 * kMaxTimeSeconds * 1e9, 9.2233720368547758e18);
  EXPECT_NE(TimeProblem(9.2e9)->find("beyond +-4.6e9 s"), std::string::npos);
  EXPECT_NE(TimeProblem(-1e10)->find("beyond +-4.6e9 s"), std::string::npos);
  EXPECT_EQ(*TimeProblem(std::numeric_limits<double>::quiet_NaN()), "is nan, not a time");
  EXPECT_EQ(*TimeProblem(-std::numeric_limits<double>::infinity()), "is infinite, not a time");
  EXPECT_NE(TimeProblem(1e-12)->find("below 1 ns"), std::string::npos);
}

}  // namespace
}  // namespace linesim::cosim
