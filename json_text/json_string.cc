#include "json_text/json_string.h"

namespace linesim::json_text {

void AppendString(std::string& out, std::string_view s, bool inside_html_script) {
  static constexpr char kHex[] = "0123456789abcdef";
  out += '"';
  for (const char c : s) {
    const auto u = static_cast<unsigned char>(c);
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
  }
  out += '"';
}

}  // namespace linesim::json_text
