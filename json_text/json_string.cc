#include "json_text/json_string.h"

#include <utility>

namespace linesim::json_text {

namespace {

// The sequence starting at s[i] (a byte >= 0x80): its length and true when
// it is well-formed UTF-8 (RFC 3629; the Unicode standard's Table 3-7: no
// overlong form, no surrogate, nothing beyond U+10FFFF); else the length of
// its ill-formed part and false: the lead byte and the continuation bytes
// that could still have begun a well-formed sequence (the "maximal
// subpart", which a browser's decoder replaces with one U+FFFD), at least 1.
std::pair<std::size_t, bool> Sequence(std::string_view s, std::size_t i) {
  const auto lead = static_cast<unsigned char>(s[i]);
  std::size_t need = 0;
  unsigned char lo = 0x80, hi = 0xBF;  // the second byte's range
  if (lead >= 0xC2 && lead <= 0xDF) {
    need = 1;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    need = 2;
    if (lead == 0xE0) lo = 0xA0;
    if (lead == 0xED) hi = 0x9F;
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    need = 3;
    if (lead == 0xF0) lo = 0x90;
    if (lead == 0xF4) hi = 0x8F;
  } else {
    return {1, false};
  }
  std::size_t j = i + 1;
  for (std::size_t got = 0; got < need; ++got, ++j) {
    if (j >= s.size()) return {j - i, false};
    const auto c = static_cast<unsigned char>(s[j]);
    if (c < lo || c > hi) return {j - i, false};
    lo = 0x80;
    hi = 0xBF;
  }
  return {j - i, true};
}

}  // namespace

void AppendString(std::string& out, std::string_view s, bool inside_html_script) {
  static constexpr char kHex[] = "0123456789abcdef";
  out += '"';
  for (std::size_t i = 0; i < s.size();) {
    const char c = s[i];
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x80) {
      // Non-ASCII: a well-formed sequence as it is, anything else as one
      // U+FFFD per ill-formed part, so that the text is valid UTF-8 (JSON
      // text must be, RFC 8259 section 8.1).
      const auto [n, well_formed] = Sequence(s, i);
      if (well_formed) {
        out.append(s.substr(i, n));
      } else {
        out += "\xEF\xBF\xBD";
      }
      i += n;
      continue;
    }
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u < 0x20 || (inside_html_script && (c == '<' || c == '>' || c == '&'))) {
      out += "\\u00";
      out += kHex[u >> 4];
      out += kHex[u & 0xF];
    } else {
      out += c;
    }
    ++i;
  }
  out += '"';
}

std::string ValidUtf8(std::string_view s, std::size_t max_bytes) {
  std::string out;
  for (std::size_t i = 0; i < s.size();) {
    std::size_t n = 1;
    std::string_view piece = s.substr(i, 1);
    if (static_cast<unsigned char>(s[i]) >= 0x80) {
      const auto [length, well_formed] = Sequence(s, i);
      n = length;
      piece = well_formed ? s.substr(i, n) : std::string_view("\xEF\xBF\xBD");
    }
    if (out.size() + piece.size() > max_bytes) break;
    out.append(piece);
    i += n;
  }
  return out;
}

}  // namespace linesim::json_text
