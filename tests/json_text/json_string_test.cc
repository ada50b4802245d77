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

// Guards against invalid JSON from a name that is not UTF-8 (a YAML file's
// bytes pass through as they are): JSON text must be UTF-8 (RFC 8259, 8.1),
// and a strict reader (nlohmann's, Python's) refuses the whole file. Each
// ill-formed part becomes one U+FFFD, as a browser's decoder (WHATWG
// Encoding, "UTF-8 decode") shows it; well-formed text, up to U+10FFFF,
// passes unchanged.
TEST(JsonString, BytesThatAreNotUtf8BecomeReplacementCharacters) {
  const std::string fffd = "\xEF\xBF\xBD";
  EXPECT_EQ(Quoted("a\xff"
                   "b",
                   false),
            "\"a" + fffd + "b\"");
  // A lone continuation byte, a lead byte cut off at the end, an overlong
  // '/' (C0 AF), a surrogate (ED A0 80), beyond U+10FFFF (F4 90 80 80).
  EXPECT_EQ(Quoted("\x80", false), "\"" + fffd + "\"");
  EXPECT_EQ(Quoted("x\xe2\x82", false), "\"x" + fffd + "\"");
  EXPECT_EQ(Quoted("\xc0\xaf", false), "\"" + fffd + fffd + "\"");
  EXPECT_EQ(Quoted("\xed\xa0\x80", false), "\"" + fffd + fffd + fffd + "\"");
  EXPECT_EQ(Quoted("\xf4\x90\x80\x80", false), "\"" + fffd + fffd + fffd + fffd + "\"");
  // A three-byte sequence cut by an ASCII byte: one U+FFFD for its two
  // bytes, then the character.
  EXPECT_EQ(Quoted("\xe2\x82<", true), "\"" + fffd + "\\u003c\"");
  // Well-formed: the euro sign, U+10FFFF, U+FFFD itself.
  for (const char* ok : {"\xe2\x82\xac", "\xf4\x8f\xbf\xbf", "\xef\xbf\xbd"}) {
    EXPECT_EQ(Quoted(ok, false), "\"" + std::string(ok) + "\"") << ok;
  }
}

// Guards the strings of a binary format (MCAP's metadata must be UTF-8): the
// same replacement, and a cut never inside a character.
TEST(JsonString, ValidUtf8ReplacesAndCutsAtACharactersBoundary) {
  EXPECT_EQ(ValidUtf8(std::string("a\xff") + "b"), std::string("a\xEF\xBF\xBD") + "b");
  EXPECT_EQ(ValidUtf8("ab\xe2\x82\xac", 4), "ab");  // the euro sign takes 3 bytes
  EXPECT_EQ(ValidUtf8("ab\xe2\x82\xac", 5), "ab\xe2\x82\xac");
  EXPECT_EQ(ValidUtf8("plain", 3), "pla");
}

}  // namespace
}  // namespace linesim::json_text
