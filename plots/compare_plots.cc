#include "plots/compare_plots.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "cosim/closest_names.h"
#include "cosim/variable_table.h"
#include "plots/figure_style.h"

namespace linesim::plots {

namespace {

namespace fs = std::filesystem;
using style::PlotItem;

constexpr style::Canvas kCanvas{1000, 600};

// The header of a CSV file, split at commas.
std::vector<std::string> Header(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::string line;
  if (!in || !std::getline(in, line)) throw std::runtime_error("cannot read " + file.string());
  if (!line.empty() && line.back() == '\r') line.pop_back();
  std::vector<std::string> names;
  std::size_t begin = 0;
  while (true) {
    const std::size_t comma = line.find(',', begin);
    names.push_back(line.substr(begin, comma - begin));
    if (comma == std::string::npos) break;
    begin = comma + 1;
  }
  return names;
}

// 1-based column of `name` (gnuplot's numbering), or an error naming the
// closest ones.
int ColumnOf(const std::vector<std::string>& header, const std::string& name,
             const fs::path& file) {
  const auto it = std::find(header.begin(), header.end(), name);
  if (it == header.end()) {
    throw std::runtime_error(file.string() + ": no column '" + name + "'" +
                             cosim::ClosestHint(name, header));
  }
  return static_cast<int>(it - header.begin()) + 1;
}

// The line's on state as a band along the top (as the robot figures mark
// it), from the first run's on columns.
PlotItem LineOnBand(const std::string& dir, const ComparisonPlotSpec& spec) {
  const ComparisonPlotSpec::Run& first = spec.runs.front();
  const fs::path file = fs::path(dir) / first.signals_csv;
  const auto header = Header(file);
  std::string any_on;
  for (std::size_t i = 0; i < spec.belt_on_columns.size(); ++i) {
    any_on += (i ? " || " : "") + std::string("column(") +
              std::to_string(ColumnOf(header, spec.belt_on_columns[i], file)) + ") > 0.5";
  }
  return {GnuplotQuote(first.signals_csv) + " skip 1 using 1:((" + any_on + ") ? " +
              style::kLineOnBandFrom + " : 1):(1)",
          std::string("axes x1y2 with filledcurves ") + style::kLineOnFill, style::kLineOnTitle};
}

}  // namespace

std::string ComparisonScript(const std::string& dir, const ComparisonPlotSpec& spec) {
  if (spec.runs.empty()) throw std::runtime_error("a comparison needs at least one run");
  std::vector<PlotItem> items;
  std::string axes;
  if (!spec.belt_on_columns.empty()) {
    items.push_back(LineOnBand(dir, spec));
    axes = "set y2range [0:1]\nunset y2tics\nset offsets 0, 0, graph 0.1, 0\n";
  }
  for (std::size_t i = 0; i < spec.runs.size(); ++i) {
    const ComparisonPlotSpec::Run& run = spec.runs[i];
    const fs::path file = fs::path(dir) / run.signals_csv;
    const int col = ColumnOf(Header(file), run.error_column, file);
    items.push_back({GnuplotQuote(run.signals_csv) + " skip 1 using 1:(1000 * column(" +
                         std::to_string(col) + "))",
                     std::string("with lines lw 2 lc rgb '") + style::SeriesColour(i) + "'",
                     run.label});
  }
  if (spec.bound_m > 0.0) {
    items.push_back(
        {cosim::FormatValue(1000.0 * spec.bound_m), std::string("with lines ") + style::kBoundStyle,
         spec.bound_label.empty() ? "bound " + style::Short(1000.0 * spec.bound_m) + " mm"
                                  : spec.bound_label});
  }
  std::string what = spec.error_label;
  if (!what.empty()) what[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(what[0])));
  const style::KeyBand key = style::KeyBelow(style::Titles(items), kCanvas);
  std::string s =
      "# Written by linesim (plots/compare_plots.cc). Run `gnuplot comparison.gp` in this\n"
      "# folder to redraw; data come from each run's signals.csv (header skipped).\n" +
      GnuplotTerminal(spec.format, kCanvas.width_px, kCanvas.height_px) +
      style::BeginFigure("comparison", spec.format, nullptr) +
      style::Caption(what + " against time, run by run", spec.run_caption) + key.commands +
      "set bmargin at screen " + style::Short(style::AxisBottomAbove(key.top_screen, kCanvas), 4) +
      "\nset xlabel 'time (s)'\nset autoscale xfix\nset ylabel " +
      GnuplotQuote(spec.error_label + " (mm)") + "\nset yrange [0:*]\n" + axes;
  return s + style::PlotCommand(items) + "unset output\n";
}

std::string WriteComparisonPlot(const std::string& dir, const ComparisonPlotSpec& spec) {
  const std::string script = ComparisonScript(dir, spec);
  return DrawWithGnuplot(dir, "comparison.gp", script, {PlotFile("comparison", spec.format)})
      .front();
}

}  // namespace linesim::plots
