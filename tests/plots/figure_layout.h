#pragma once

#include <string>
#include <vector>

/// Where the text and legend of a gnuplot figure landed, for the tests that
/// check that no label overlaps another and no legend covers data.
///
/// How: the figure's script (plots.gp, comparison.gp, sweep_plots.gp, as a
/// run left it) is drawn again on gnuplot's SVG terminal at the size and
/// font size in pixels the PNG has (pngcairo's 10 pt is 13.33 px), with
/// `mouse` so that each legend entry is a group of its own, and with a
/// `print` of GPVAL_TERM_XMIN/XMAX/YMIN/YMAX after every plot command (the
/// plot area gnuplot used, per panel of a multiplot). The SVG lists every
/// text with its anchor, alignment, rotation and font size; its box is
/// computed from DejaVu Sans' advance widths (the face pngcairo draws
/// with), its ascender and descender. gnuplot's own layout is what is
/// checked: positions come from gnuplot, never from the code under test.
namespace linesim::plots::layout {

struct Box {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // px, y down
  bool Overlaps(const Box& o, double tolerance_px = 0.5) const;
  bool Inside(const Box& o, double tolerance_px = 0.5) const;
};

struct Text {
  std::string text;
  Box box;
  bool key = false;    // a legend entry's text
  bool label = false;  // drawn by a plot item (`with labels`): inside the data
};

struct Figure {
  std::string file;  // the SVG drawn in place of the script's picture
  double width_px = 0, height_px = 0;
  std::vector<Text> texts;
  std::vector<Box> key_samples;  // the legend's line and fill samples
  std::vector<Box> plot_areas;   // one per plot command (panel)
};

/// Draws `script` (in `dir`) again as described above, into
/// `dir`/layout_*.svg, and reads each figure's layout. Fails the calling
/// test (ADD_FAILURE) when gnuplot fails.
std::vector<Figure> DrawAndRead(const std::string& dir, const std::string& script);

/// Every problem of a figure's layout, each naming what and where: two
/// texts (or a legend sample and a text) that overlap, a text outside the
/// canvas, a legend entry inside a plot area, a label outside every plot
/// area.
std::vector<std::string> Problems(const Figure& figure);

}  // namespace linesim::plots::layout
