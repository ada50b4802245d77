#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace linesim::plots {

/// `text` as a gnuplot single-quoted string ('' for a quote, line breaks
/// as spaces).
std::string GnuplotQuote(const std::string& text);

/// The file format plots are written in: PNG (the default), or vector
/// output for papers, SVG or PDF.
enum class PlotFormat { kPng, kSvg, kPdf };

/// "png", "svg", "pdf": the file extension and the --format value.
std::string_view PlotExtension(PlotFormat format);

/// The format a --format value names ("png", "svg", "pdf"); nullopt else.
std::optional<PlotFormat> ParsePlotFormat(std::string_view text);

/// `name` + "." + the format's extension.
std::string PlotFile(const std::string& name, PlotFormat format);

/// The script lines that choose a PNG terminal of this size: pngcairo when
/// the installed gnuplot has it, else the libgd png terminal. Labels are
/// printed as written (no enhanced-text markup: names have underscores).
std::string GnuplotPngTerminal(int width_px, int height_px);

/// The script lines that choose the terminal of `format` for a canvas of
/// this size (PNG: GnuplotPngTerminal; SVG: the svg terminal at the same
/// size in pixels; PDF: pdfcairo at 100 pixels to the inch, an error from
/// gnuplot naming the terminal when it lacks it).
std::string GnuplotTerminal(PlotFormat format, int width_px, int height_px);

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
