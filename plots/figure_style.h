#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "plots/gnuplot.h"

/// What every figure of linesim shares, in one place: the text's font and
/// sizes, the colours of each kind of series, the paper bounds' line, the
/// captions and where the legend goes. The robot, comparison and sweep
/// figures draw with these and nothing else of their own.
namespace linesim::plots::style {

/// The text: gnuplot's ',10' on pngcairo is 10 pt at 96 pixels to the inch,
/// 13.33 px per em; the SVG terminal is given the same size in pixels so that
/// both lay out alike (PDF: pdfcairo at 100 px to the inch, 13.9 px).
inline constexpr double kFontPx = 40.0 / 3.0;
/// Labels inside the data (time labels, names of robots and workers): 8 pt.
inline constexpr double kSmallFontPx = 32.0 / 3.0;

/// Advance width of `text` in em of DejaVu Sans Book, the face fontconfig
/// gives pngcairo's "Sans" on Debian 12 (its hmtx table, 2048 units per
/// em; characters outside printable ASCII count as an 'M').
double TextWidthEm(std::string_view text);
/// Above and below the baseline (em): DejaVu Sans' ascender of the
/// letters (0.76: 'd', 'l') and its descender (0.24: 'g', 'p').
inline constexpr double kAscentEm = 0.76, kDescentEm = 0.24;

/// Colours, from Okabe & Ito's colour-blind safe set (Color Universal
/// Design, 2008) and greys.
namespace colour {
inline constexpr const char* kBlack = "#000000";
inline constexpr const char* kOrange = "#E69F00";
inline constexpr const char* kSky = "#56B4E9";
inline constexpr const char* kGreen = "#009E73";
inline constexpr const char* kBlue = "#0072B2";
inline constexpr const char* kVermillion = "#D55E00";
inline constexpr const char* kPurple = "#CC79A7";
inline constexpr const char* kGrey = "#7F7F7F";
}  // namespace colour

/// The colour of the k-th named series of a figure (runs compared, other
/// robots, workers), distinct for the first seven.
const char* SeriesColour(std::size_t k);

/// What each kind of series is drawn with (gnuplot line properties).
/// The robot's own track and outline, its wheel contacts; the desired path.
inline constexpr const char* kTrackStyle = "lw 2 lc rgb '#D55E00'";
inline constexpr const char* kOutlineStyle = "lw 1.5 lc rgb '#0072B2'";
inline constexpr const char* kContactStyle = "pt 7 ps 0.7 lc rgb '#009E73'";
inline constexpr const char* kDesiredPathStyle = "dt 2 lw 1.5 lc rgb '#000000'";
/// A measured quantity against time (the deviation, a speed).
inline constexpr const char* kMeasuredStyle = "lw 2 lc rgb '#0072B2'";
/// Scene: belts, obstacles, carried objects.
inline constexpr const char* kBeltFill =
    "fillcolor rgb '#DCE6F2' fillstyle solid 1.0 border lc rgb '#8FA9CC'";
inline constexpr const char* kBeltArrow = "lc rgb '#8FA9CC'";
inline constexpr const char* kObstacleFill =
    "fillcolor rgb '#C8C8C8' fillstyle solid 1.0 border lc rgb '#606060'";
inline constexpr const char* kCarriedFill =
    "fillcolor rgb '#F6D3A8' fillstyle solid 1.0 border lc rgb '#C07020'";
inline constexpr const char* kCarriedEndStyle = "dt 2 lw 1.5 lc rgb '#C07020'";

/// A published bound (paper 1's 4 cm, paper 2's Table 1) and a source's
/// figures: the same black dashed line in every figure.
inline constexpr const char* kBoundStyle = "dt 2 lw 2 lc rgb '#000000'";

/// The line's on state in a time plot (paper 1 Figs. 5-7 mark it): a grey
/// band along the top of the plot (from kLineOnBandFrom of the graph's
/// height up) where any belt is scheduled on, the data kept below it by
/// an offset.
inline constexpr const char* kLineOnBandFrom = "0.97";
inline constexpr const char* kLineOnFill = "fillcolor rgb '#BDBDBD' fillstyle solid 1.0 noborder";
inline constexpr const char* kLineOnTitle = "line on (band along the top)";

/// The pictures' sizes (px).
struct Canvas {
  int width_px = 1000, height_px = 800;
};

/// The first lines of a figure: gnuplot reset to its defaults (no setting
/// of the figure before carries over), the shared settings, and `name`
/// as the next picture in `format` (its file added to `outputs` unless
/// null).
std::string BeginFigure(const std::string& name, PlotFormat format,
                        std::vector<std::string>* outputs);

/// The lines that make a caption the figure's title: what it shows, and
/// under it what run it is from (none when `run` is empty).
std::string Caption(const std::string& what, const std::string& run);

/// Where a legend of `titles` goes: centred in a band at the canvas' foot,
/// under the axes (never over the data), in as many columns as fit; with
/// `key_title` over the entries.
struct KeyBand {
  std::string commands;     // the `set key` lines
  double top_screen = 0.0;  // the band's top (screen fraction)
  int rows = 0;
};
KeyBand KeyBelow(const std::vector<std::string>& titles, Canvas canvas,
                 const std::string& key_title = "");

/// The bottom margin (screen fraction) that keeps the x tic labels and the
/// x axis label above a key band whose top is at `key_top_screen`.
double AxisBottomAbove(double key_top_screen, Canvas canvas);

/// One item of a plot command with its legend entry ("" for none).
struct PlotItem {
  std::string data;   // "$signals using 1:2", a function ("0.04")
  std::string style;  // "with lines lw 2 ..."
  std::string title;
};
/// The `plot` command of `items`, each with its title or notitle; then,
/// for a legend that lists what other panels of a multiplot draw, a
/// `keyentry` of each of `also_in_key` (their data not drawn).
std::string PlotCommand(const std::vector<PlotItem>& items,
                        const std::vector<PlotItem>& also_in_key = {});
/// The titles of `items` that have one.
std::vector<std::string> Titles(const std::vector<PlotItem>& items);

/// A panel of a multiplot in screen fractions, and the lines that put the
/// next plot there.
struct Panel {
  double left = 0.0, right = 1.0, bottom = 0.0, top = 1.0;
  std::string Margins() const;
};

/// A number for a label or legend: at most `digits` significant digits,
/// independent of the locale ("0.0123", "1.5e+03").
std::string Short(double x, int digits = 3);

}  // namespace linesim::plots::style
