#include "plots/sweep_plots.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>
#include <optional>
#include <set>
#include <stdexcept>

#include "cosim/variable_table.h"
#include "plots/figure_style.h"
#include "plots/gnuplot.h"
#include "plots/metric_labels.h"

namespace linesim::plots {

namespace {

constexpr const char* kScript = "sweep_plots.gp";
constexpr style::Canvas kCanvas{800, 500};

// Shortest text that reads back to the same double, independent of the
// locale.
std::string Num(double x) { return cosim::FormatValue(x); }

// A number for a legend: 3 significant digits, independent of the locale.
std::string Short(double x) { return style::Short(x, 3); }

bool IsSafeFileName(const std::string& name) {
  return !name.empty() && name != "." && name != ".." && SafeFileName(name) == name;
}

[[noreturn]] void Refuse(const SweepChart& chart, const std::string& why) {
  throw std::runtime_error("sweep plot '" + chart.file + "': " + why);
}

void CheckChart(const SweepChart& chart) {
  if (!IsSafeFileName(chart.file) || !chart.file.ends_with(".png")) {
    Refuse(chart, "the file name must be made of [A-Za-z0-9._-] and end in .png");
  }
  if (chart.histogram) {
    if (chart.series.size() != 1) Refuse(chart, "a histogram has exactly one series of samples");
    return;
  }
  for (const SweepSeries& s : chart.series) {
    const std::size_t n = s.x.size();
    const bool bars_ok =
        chart.scatter ? (s.min.empty() || s.min.size() == n) && (s.max.empty() || s.max.size() == n)
                      : s.min.size() == n && s.max.size() == n;
    if (s.mean.size() != n || !bars_ok) {
      Refuse(chart, "series '" + s.label + "' has " + std::to_string(n) + " x values but " +
                        std::to_string(s.mean.size()) + " means, " + std::to_string(s.min.size()) +
                        " minima and " + std::to_string(s.max.size()) + " maxima");
    }
    if (chart.categorical_x) continue;
    for (const std::string& x : s.x) {
      if (!cosim::ParseFiniteValue(x))
        Refuse(chart, "x value '" + x + "' is not a number on a numeric axis");
    }
  }
}

// Tic order of a categorical axis: the chart's categories, then any others
// in first-seen order.
std::vector<std::string> Categories(const SweepChart& chart) {
  std::vector<std::string> order = chart.categories;
  for (const SweepSeries& s : chart.series) {
    for (const std::string& x : s.x) {
      if (std::find(order.begin(), order.end(), x) == order.end()) order.push_back(x);
    }
  }
  return order;
}

struct Point {
  double x, mean, min, max;
};

// The drawable points of a series: finite, sorted along a numeric axis (the
// line joins them in x order); categories moved sideways by `shift` so that
// the error bars of several series stay apart.
std::vector<Point> Points(const SweepChart& chart, const SweepSeries& s,
                          const std::vector<std::string>& categories, double shift) {
  std::vector<Point> points;
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    double x = 0.0;
    if (chart.categorical_x) {
      x = static_cast<double>(std::find(categories.begin(), categories.end(), s.x[i]) -
                              categories.begin()) +
          shift;
    } else {
      x = *cosim::ParseFiniteValue(s.x[i]);
    }
    const double lo = i < s.min.size() ? s.min[i] : s.mean[i];
    const double hi = i < s.max.size() ? s.max[i] : s.mean[i];
    if (!std::isfinite(s.mean[i]) || (!chart.scatter && !std::isfinite(lo + hi))) continue;
    points.push_back({x, s.mean[i], lo, hi});
  }
  if (!chart.categorical_x) {
    std::stable_sort(points.begin(), points.end(),
                     [](const Point& a, const Point& b) { return a.x < b.x; });
  }
  return points;
}

// How a chart's values are shown: its metric's caption and unit, the
// values scaled (SI to mm, degrees); or the labels as given.
struct Shown {
  std::string caption, value_label, unit;
  double scale = 1.0;
};
Shown ShownAs(const SweepChart& chart) {
  if (chart.metric.empty()) {
    return {chart.title, chart.histogram ? chart.x_label : chart.y_label, "", 1.0};
  }
  double largest = 0.0;
  const auto take = [&](double v) {
    if (std::isfinite(v)) largest = std::max(largest, std::abs(v));
  };
  for (const SweepSeries& series : chart.series) {
    for (double v : series.mean) take(v);
    for (double v : series.min) take(v);
    for (double v : series.max) take(v);
  }
  if (!chart.reference.label.empty()) take(chart.reference.max_abs);
  const MetricAxis axis = DescribeMetric(chart.metric, largest);
  std::string caption = axis.caption;
  if (!caption.empty()) {
    caption[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(caption[0])));
  }
  return {caption, axis.Label(), axis.unit, axis.scale};
}

// The start of a chart's figure: gnuplot's settings reset, its caption and
// the legend in a band under the axes.
std::string BeginChart(const SweepChart& chart, const std::string& caption,
                       const std::vector<std::string>& titles, const std::string& key_title = "") {
  const style::KeyBand key = style::KeyBelow(titles, kCanvas, key_title);
  return style::BeginFigure(chart.file.substr(0, chart.file.size() - 4), PlotFormat::kPng,
                            nullptr) +
         style::Caption(caption, chart.run_caption) + key.commands + "set bmargin at screen " +
         style::Short(style::AxisBottomAbove(key.top_screen, kCanvas), 4) + "\n";
}

// A histogram's samples (finite, scaled for showing) and their bins.
struct Histogram {
  std::vector<double> v;
  double mean = 0.0, sd = 0.0, lo = 0.0, width = 0.0;
  std::vector<int> counts;
};
Histogram Bin(const SweepChart& chart, double scale) {
  Histogram h;
  for (double x : chart.series[0].mean) {
    if (std::isfinite(x)) h.v.push_back(x * scale);
  }
  if (h.v.empty()) return h;
  const double n = static_cast<double>(h.v.size());
  for (double x : h.v) h.mean += x / n;
  double var = 0.0;
  for (double x : h.v) var += (x - h.mean) * (x - h.mean);
  h.sd = h.v.size() > 1 ? std::sqrt(var / (n - 1.0)) : 0.0;
  const auto [lo_it, hi_it] = std::minmax_element(h.v.begin(), h.v.end());
  double lo = *lo_it, hi = *hi_it;
  // Square-root choice of the bin count (at least 5, at most 30); a single
  // value gets one bin of a width that shows it.
  const int bins = std::clamp(static_cast<int>(std::ceil(std::sqrt(n))), 5, 30);
  if (hi - lo <= 0.0) {
    const double half = std::max(std::abs(lo) * 1e-3, 1e-12);
    lo -= half;
    hi += half;
  }
  h.lo = lo;
  h.width = (hi - lo) / bins;
  h.counts.assign(static_cast<std::size_t>(bins), 0);
  for (double x : h.v) {
    const int b = std::min(bins - 1, static_cast<int>((x - lo) / h.width));
    ++h.counts[static_cast<std::size_t>(b)];
  }
  return h;
}

// The script lines of a histogram chart: counts per bin as boxes, the
// normal density N(mean, std) times n x bin width over them and the mean
// as a line; a source's figures in the bound style. Empty without finite
// samples.
std::string HistogramScript(const SweepChart& chart, std::size_t index) {
  const Shown shown = ShownAs(chart);
  const Histogram h = Bin(chart, shown.scale);
  if (h.v.empty()) return {};
  const double n = static_cast<double>(h.v.size());
  const std::string block = "$hist" + std::to_string(index);
  std::string data = block + " << EOD\n";
  for (std::size_t b = 0; b < h.counts.size(); ++b) {
    data += Num(h.lo + (static_cast<double>(b) + 0.5) * h.width) + "," +
            std::to_string(h.counts[b]) + "\n";
  }
  data += "EOD\n";
  // The x range: the bins, the fitted normal's +-3 std and the source's
  // figures.
  const SweepChart::Reference& ref = chart.reference;
  const bool marked = !ref.label.empty();
  const double ref_max = ref.max_abs * shown.scale, ref_std = ref.std * shown.scale;
  double x0 = h.lo, x1 = h.lo + h.width * static_cast<double>(h.counts.size());
  if (h.sd > 0.0) {
    x0 = std::min(x0, h.mean - 3.0 * h.sd);
    x1 = std::max(x1, h.mean + 3.0 * h.sd);
  }
  if (marked && std::isfinite(ref_max)) {
    x0 = std::min(x0, -ref_max);
    x1 = std::max(x1, ref_max);
  }
  if (marked && std::isfinite(ref_std) && ref_std > 0.0) {
    x0 = std::min(x0, -3.0 * ref_std);
    x1 = std::max(x1, 3.0 * ref_std);
  }
  const double pad = 0.05 * (x1 - x0);
  const int most = *std::max_element(h.counts.begin(), h.counts.end());
  // Values in the legend with their unit; a mean within rounding of 0 as 0.
  const std::string unit = shown.unit.empty() ? "" : " " + shown.unit;
  const auto value = [&](double x) {
    return Short(std::abs(x) < 1e-9 * (std::abs(h.lo) + h.width * 30.0) ? 0.0 : x) + unit;
  };
  std::vector<style::PlotItem> items = {
      {block + " using 1:2",
       "with boxes fillcolor rgb '#56B4E9' fillstyle solid 0.6 border lc rgb '#0072B2'",
       std::to_string(h.v.size()) + " runs, bins of " + value(h.width)}};
  const auto normal = [&](double mean, double sd) {
    const std::string k = Num(n * h.width / (sd * std::sqrt(2.0 * std::numbers::pi)));
    return "[" + Num(mean - 4.0 * sd) + ":" + Num(mean + 4.0 * sd) + "] " + k +
           " * exp(-0.5 * ((x - " + Num(mean) + ") / " + Num(sd) + ") ** 2)";
  };
  if (h.sd > 0.0) {
    items.push_back({normal(h.mean, h.sd), "with lines lw 2 lc rgb '#D55E00'",
                     "normal fit: std " + value(h.sd)});
  }
  std::string arrows = "set arrow from " + Num(h.mean) + ", graph 0 to " + Num(h.mean) +
                       ", graph 1 nohead lw 2 dt 4 lc rgb '#D55E00'\n";
  items.push_back(
      {"keyentry", "with lines lw 2 dt 4 lc rgb '#D55E00'", "mean of the runs: " + value(h.mean)});
  if (marked && std::isfinite(ref_max)) {
    for (const double x : {-ref_max, ref_max}) {
      arrows += "set arrow from " + Num(x) + ", graph 0 to " + Num(x) + ", graph 1 nohead " +
                style::kBoundStyle + "\n";
    }
    items.push_back({"keyentry", std::string("with lines ") + style::kBoundStyle,
                     "source: largest |error| " + value(ref_max)});
  }
  if (marked && std::isfinite(ref_std) && ref_std > 0.0) {
    items.push_back({normal(0.0, ref_std), "with lines dt 3 lw 2 lc rgb '#000000'",
                     "source: std " + value(ref_std) + ", as N(0, std)"});
  }
  return "\n" + data +
         BeginChart(chart,
                    shown.caption + ": distribution over " + std::to_string(h.v.size()) + " runs",
                    style::Titles(items), marked ? "source: " + ref.label : "") +
         "set xlabel " + GnuplotQuote(shown.value_label) + "\nset ylabel 'runs'\nset xrange [" +
         Num(x0 - pad) + ":" + Num(x1 + pad) +
         "]\nset yrange [0:*]\nset offsets 0, 0, graph 0.08, 0\n" +
         (most <= 10 ? "set ytics 1\n" : "") + "set boxwidth " + Num(h.width) + " absolute\n" +
         arrows + style::PlotCommand(items);
}

// The script lines of one chart; empty when it has nothing to draw.
std::string ChartScript(const SweepChart& chart, std::size_t index) {
  if (chart.histogram) return HistogramScript(chart, index);
  const Shown shown = ShownAs(chart);
  const std::vector<std::string> categories =
      chart.categorical_x ? Categories(chart) : std::vector<std::string>{};
  const std::size_t count = chart.series.size();
  // Sideways spread of the series at one category: at most 0.6 of the gap.
  const double step = std::min(0.1, 0.6 / static_cast<double>(count));
  std::string blocks;
  std::vector<style::PlotItem> items;
  // What a point is: the series' title, or the legend's when series have labels.
  const std::string what = chart.scatter ? "one point per run" : "mean, bars: min to max";
  bool any_label = false;
  for (std::size_t k = 0; k < count; ++k) {
    const SweepSeries& s = chart.series[k];
    const double shift =
        chart.categorical_x && !chart.scatter
            ? (static_cast<double>(k) - 0.5 * static_cast<double>(count - 1)) * step
            : 0.0;
    const std::vector<Point> points = Points(chart, s, categories, shift);
    if (points.empty()) continue;
    const std::string block = "$chart" + std::to_string(index) + "_" + std::to_string(k);
    blocks += block + " << EOD\n";
    for (const Point& p : points) {
      blocks += Num(p.x) + "," + Num(p.mean * shown.scale);
      if (!chart.scatter) blocks += "," + Num(p.min * shown.scale) + "," + Num(p.max * shown.scale);
      blocks += "\n";
    }
    blocks += "EOD\n";
    any_label = any_label || !s.label.empty();
    std::string style;
    if (chart.scatter) {
      style = "with points pt 7 ps 0.8";
    } else if (chart.categorical_x) {
      style = "with yerrorbars pt 7 ps 1.2 lw 2";
    } else {
      style = "with yerrorlines pt 7 ps 1.2 lw 2";
    }
    items.push_back({block + (chart.scatter ? " using 1:2" : " using 1:2:3:4"),
                     style + " lc rgb '" + style::SeriesColour(k) + "'",
                     s.label.empty() ? what : s.label + (count > 1 ? "" : " (" + what + ")")});
  }
  if (items.empty()) return {};
  const std::string x_label = chart.x_label;
  const bool key_title = any_label && count > 1;
  std::string s =
      "\n" + blocks +
      BeginChart(chart,
                 chart.metric.empty() ? shown.caption : shown.caption + " against " + x_label,
                 style::Titles(items), key_title ? what : "") +
      "set xlabel " + GnuplotQuote(x_label) + "\nset ylabel " + GnuplotQuote(shown.value_label) +
      "\nset offsets graph 0.05, graph 0.05, graph 0.05, graph 0.05\n";
  if (chart.categorical_x) {
    s += "set xrange [-0.5:" + Num(static_cast<double>(categories.size()) - 0.5) + "]\nset xtics (";
    for (std::size_t i = 0; i < categories.size(); ++i) {
      s += (i ? ", " : "") + GnuplotQuote(categories[i]) + " " + std::to_string(i);
    }
    s += ")\n";
  }
  return s + style::PlotCommand(items);
}

}  // namespace

std::string SafeFileName(std::string_view name) {
  std::string out(name);
  for (char& c : out) {
    const bool safe = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '.' || c == '_' || c == '-';
    if (!safe) c = '_';
  }
  return out;
}

std::vector<std::string> WriteSweepPlots(const std::string& dir,
                                         const std::vector<SweepChart>& charts) {
  std::set<std::string> files;
  for (const SweepChart& chart : charts) {
    CheckChart(chart);
    if (!files.insert(chart.file).second) Refuse(chart, "two charts have this file name");
  }
  std::string script =
      "# Written by linesim (plots/sweep_plots.cc). Run `gnuplot sweep_plots.gp` in this\n"
      "# folder to redraw; the data are inline.\n" +
      GnuplotPngTerminal(kCanvas.width_px, kCanvas.height_px);
  std::vector<std::string> outputs;
  for (std::size_t i = 0; i < charts.size(); ++i) {
    const std::string chart = ChartScript(charts[i], i);
    if (chart.empty()) continue;
    script += chart;
    outputs.push_back(charts[i].file);
  }
  if (outputs.empty()) return {};
  script += "unset output\n";
  return DrawWithGnuplot(dir, kScript, script, outputs);
}

}  // namespace linesim::plots
