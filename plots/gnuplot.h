#pragma once

#include <string>
#include <vector>

namespace linesim::plots {

/// `text` as a gnuplot single-quoted string ('' for a quote, line breaks
/// as spaces).
std::string GnuplotQuote(const std::string& text);

/// The script lines that choose a PNG terminal of this size: pngcairo when
/// the installed gnuplot has it, else the libgd png terminal. Labels are
/// printed as written (no enhanced-text markup: names have underscores).
std::string GnuplotPngTerminal(int width_px, int height_px);

struct GnuplotResult {
  int exit_status = 0;
  std::string errors;  // what gnuplot wrote to stderr
};

/// Runs `gnuplot script_name` in `dir` without a shell (paths with spaces or
/// quotes need no escaping). Throws std::runtime_error when gnuplot cannot
/// be started (not installed, not on PATH).
GnuplotResult RunGnuplot(const std::string& dir, const std::string& script_name);

/// Writes `script` to `dir`/`script_name`, removes stale copies of the
/// `outputs` (file names in `dir`), runs gnuplot there and returns the
/// paths of the outputs. Throws std::runtime_error, naming the script and
/// with gnuplot's error text, when gnuplot fails or leaves an output
/// unwritten.
std::vector<std::string> DrawWithGnuplot(const std::string& dir, const std::string& script_name,
                                         const std::string& script,
                                         const std::vector<std::string>& outputs);

}  // namespace linesim::plots
