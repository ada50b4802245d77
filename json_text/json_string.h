#pragma once

#include <string>
#include <string_view>

/// JSON text written by hand where the writers need it fast (run.mcap's
/// messages, replay.html's data): the one place strings are escaped.
namespace linesim::json_text {

/// Appends `s` as a quoted JSON string: '"' and '\' escaped, control
/// characters as \u00XX, bytes that are not well-formed UTF-8 as U+FFFD
/// (one per ill-formed part, as a browser decodes them): the text is
/// always valid UTF-8 JSON. With `inside_html_script` also '<', '>' and
/// '&' as \u00XX, so that no text inside a page's <script> element can
/// close it.
void AppendString(std::string& out, std::string_view s, bool inside_html_script = false);

/// `s` as valid UTF-8, its ill-formed parts as U+FFFD as AppendString
/// writes them, and cut to at most `max_bytes` at a character's boundary
/// (for a binary format's strings, which must be UTF-8: MCAP's).
std::string ValidUtf8(std::string_view s, std::size_t max_bytes = std::string_view::npos);

}  // namespace linesim::json_text
