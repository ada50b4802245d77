#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

// Helpers the libFuzzer harnesses share. The harnesses feed the input bytes
// to the readers as the text of a file the user writes; only the exceptions
// a reader documents are expected, anything else (another exception type, a
// crash, a sanitizer report, a hang) is a finding.
namespace linesim::fuzz {

/// A folder of this process's own (made once, under $TMPDIR or /tmp).
const std::string& TempDir();

/// Writes `size` bytes to `path` (replacing it); aborts when it cannot.
void WriteFile(const std::string& path, const std::uint8_t* data, std::size_t size);

/// The `--set` arguments an input carries: each line that starts with
/// "#set " (a YAML comment, so the file's meaning is unchanged) gives the
/// rest of the line; at most `max` of them.
std::vector<std::string> SetArgs(const std::string& text, std::size_t max = 4);

}  // namespace linesim::fuzz
