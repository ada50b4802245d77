#include "json_text/json_string.h"

#include <gtest/gtest.h>

#include <string>

namespace linesim::json_text {
namespace {

std::string Quoted(std::string_view s, bool html) {
  std::string out;
  AppendString(out, s, html);
  return out;
}

// Guards the escapes RFC 8259 requires (quote, backslash, control
// characters as \u00XX) and, inside a page's <script>, the three characters
// that could end it: the same text gets the same bytes in run.mcap and
// replay.html.
TEST(JsonString, EscapesWhatJsonAndAScriptElementNeed) {
  EXPECT_EQ(Quoted("laser_front", false), "\"laser_front\"");
  EXPECT_EQ(Quoted("a\"b\\c", false), "\"a\\\"b\\\\c\"");
  EXPECT_EQ(Quoted(std::string("x\ny\x1f", 4), false), "\"x\\u000ay\\u001f\"");
  EXPECT_EQ(Quoted("</script>&", false), "\"</script>&\"");
  EXPECT_EQ(Quoted("</script>&", true), "\"\\u003c/script\\u003e\\u0026\"");
  // UTF-8 passes as it is.
  EXPECT_EQ(Quoted("\xc3\xa4", true), "\"\xc3\xa4\"");
}

}  // namespace
}  // namespace linesim::json_text
