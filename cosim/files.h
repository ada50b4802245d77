#pragma once

#include <optional>
#include <string>

namespace linesim::cosim {

/// The whole of a file as bytes; nothing when it cannot be read.
std::optional<std::string> ReadWholeFile(const std::string& path);

/// Writes `text` to `path` through `path`.tmp, flushed and fsynced, then a
/// rename: a reader never sees half a file, and a crash leaves the old file
/// or the new one. On failure the temporary is removed and
/// std::runtime_error names the file and the cause (disk full, say).
void WriteFileAtomically(const std::string& path, const std::string& text);

}  // namespace linesim::cosim
