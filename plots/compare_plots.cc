#include "plots/compare_plots.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "cosim/closest_names.h"
#include "cosim/variable_table.h"

namespace linesim::plots {

namespace {

namespace fs = std::filesystem;

constexpr int kWidthPx = 1000, kHeightPx = 600;

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

}  // namespace

std::string ComparisonScript(const std::string& dir, const ComparisonPlotSpec& spec) {
  if (spec.runs.empty()) throw std::runtime_error("a comparison needs at least one run");
  std::string s =
      "# Written by linesim (plots/compare_plots.cc). Run `gnuplot comparison.gp` in this\n"
      "# folder to redraw; data come from each run's signals.csv (header skipped).\n" +
      GnuplotTerminal(spec.format, kWidthPx, kHeightPx) +
      "set datafile separator comma\nset grid\n"
      // The legend (a row per run) at the canvas' foot, under the axes.
      "set bmargin at screen 0.25\nset key at screen 0.5, 0.01 center bottom vertical\n"
      "set output " + GnuplotQuote(PlotFile("comparison", spec.format)) + "\nset title " +
      GnuplotQuote(spec.title) + "\nset xlabel 'time (s)'\nset ylabel " +
      GnuplotQuote(spec.error_label) + "\nset yrange [0:*]\nset offsets 0, 0, graph 0.05, 0\n";
  std::vector<std::string> items;
  if (!spec.belt_on_columns.empty()) {
    const ComparisonPlotSpec::Run& first = spec.runs.front();
    const fs::path file = fs::path(dir) / first.signals_csv;
    const auto header = Header(file);
    std::string any_on;
    for (std::size_t i = 0; i < spec.belt_on_columns.size(); ++i) {
      any_on += (i ? " || " : "") + std::string("column(") +
                std::to_string(ColumnOf(header, spec.belt_on_columns[i], file)) + ") > 0.5";
    }
    s += "set y2range [0:1]\nunset y2tics\nset grid front\n";  // the bands would hide it
    items.push_back(GnuplotQuote(first.signals_csv) + " skip 1 using 1:((" + any_on +
                    ") ? 1 : 0) axes x1y2 with filledcurves y=0 fillcolor rgb '#e4e4e4' "
                    "fillstyle solid 1.0 noborder title 'line on'");
  }
  static const char* kColours[] = {"#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#ff7f0e"};
  for (std::size_t i = 0; i < spec.runs.size(); ++i) {
    const ComparisonPlotSpec::Run& run = spec.runs[i];
    const fs::path file = fs::path(dir) / run.signals_csv;
    const int col = ColumnOf(Header(file), run.error_column, file);
    items.push_back(GnuplotQuote(run.signals_csv) + " skip 1 using 1:" + std::to_string(col) +
                    " with lines lw 2 lc rgb '" + kColours[i % 5] + "' title " +
                    GnuplotQuote(run.label));
  }
  if (spec.bound_m > 0.0) {
    items.push_back(cosim::FormatValue(spec.bound_m) +
                    " with lines dt 2 lw 2 lc rgb 'black' title " +
                    GnuplotQuote(spec.bound_label.empty()
                                     ? "bound " + cosim::FormatValue(spec.bound_m) + " m"
                                     : spec.bound_label));
  }
  s += "plot ";
  for (std::size_t i = 0; i < items.size(); ++i) s += (i ? ", \\\n     " : "") + items[i];
  return s + "\nunset output\n";
}

std::string WriteComparisonPlot(const std::string& dir, const ComparisonPlotSpec& spec) {
  const std::string script = ComparisonScript(dir, spec);
  return DrawWithGnuplot(dir, "comparison.gp", script, {PlotFile("comparison", spec.format)})
      .front();
}

}  // namespace linesim::plots
