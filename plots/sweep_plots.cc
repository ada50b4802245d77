#include "plots/sweep_plots.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <locale>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include "cosim/variable_table.h"
#include "plots/gnuplot.h"

namespace linesim::plots {

namespace {

constexpr const char* kScript = "sweep_plots.gp";
constexpr int kWidthPx = 800, kHeightPx = 500;

// Shortest text that reads back to the same double, independent of the
// locale.
std::string Num(double x) { return cosim::FormatValue(x); }

// A number for a legend: 4 significant digits, independent of the locale.
std::string Short(double x) {
  std::ostringstream out;
  out.imbue(std::locale::classic());
  out << std::setprecision(4) << x;
  return out.str();
}

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

// The script lines of a histogram chart: counts per bin as boxes and the
// normal density N(mean, std) times n x bin width over them; empty without
// finite samples.
std::string HistogramScript(const SweepChart& chart, std::size_t index) {
  std::vector<double> v;
  for (double x : chart.series[0].mean) {
    if (std::isfinite(x)) v.push_back(x);
  }
  if (v.empty()) return {};
  const double n = static_cast<double>(v.size());
  double mean = 0.0;
  for (double x : v) mean += x / n;
  double var = 0.0;
  for (double x : v) var += (x - mean) * (x - mean);
  const double sd = v.size() > 1 ? std::sqrt(var / (n - 1.0)) : 0.0;
  const auto [lo_it, hi_it] = std::minmax_element(v.begin(), v.end());
  double lo = *lo_it, hi = *hi_it;
  // Square-root choice of the bin count (at least 5, at most 30); a single
  // value gets one bin of a width that shows it.
  const int bins = std::clamp(static_cast<int>(std::ceil(std::sqrt(n))), 5, 30);
  if (hi - lo <= 0.0) {
    const double half = std::max(std::abs(lo) * 1e-3, 1e-12);
    lo -= half;
    hi += half;
  }
  const double width = (hi - lo) / bins;
  std::vector<int> counts(static_cast<std::size_t>(bins), 0);
  for (double x : v) {
    const int b = std::min(bins - 1, static_cast<int>((x - lo) / width));
    ++counts[static_cast<std::size_t>(b)];
  }
  const std::string block = "$hist" + std::to_string(index);
  std::string s = "\n" + block + " << EOD\n";
  for (int b = 0; b < bins; ++b) {
    s += Num(lo + (b + 0.5) * width) + " " + std::to_string(counts[static_cast<std::size_t>(b)]) +
         "\n";
  }
  // The x range: the bins, the fitted normal's +-3 std and the source's
  // marks.
  const SweepChart::Reference& ref = chart.reference;
  const bool marked = !ref.label.empty();
  double x0 = lo, x1 = hi;
  if (sd > 0.0) {
    x0 = std::min(x0, mean - 3.0 * sd);
    x1 = std::max(x1, mean + 3.0 * sd);
  }
  if (marked && std::isfinite(ref.max_abs)) {
    x0 = std::min(x0, -ref.max_abs);
    x1 = std::max(x1, ref.max_abs);
  }
  if (marked && std::isfinite(ref.std) && ref.std > 0.0) {
    x0 = std::min(x0, -3.0 * ref.std);
    x1 = std::max(x1, 3.0 * ref.std);
  }
  const double pad = 0.05 * (x1 - x0);
  s += "EOD\nset output " + GnuplotQuote(chart.file) + "\nset title " +
       GnuplotQuote(chart.title) + "\nset xlabel " + GnuplotQuote(chart.x_label) +
       "\nset ylabel 'runs'\nset xrange [" + Num(x0 - pad) + ":" + Num(x1 + pad) +
       "]\nset xtics autofreq\nset key title ''\n"
       "set yrange [0:*]\nset ytics 1\nunset arrow\n"
       "set boxwidth " + Num(width) + " absolute\nset style fill solid 0.5 border -1\n";
  std::string extra;
  if (marked && std::isfinite(ref.max_abs)) {
    for (const double x : {-ref.max_abs, ref.max_abs}) {
      s += "set arrow from " + Num(x) + ", graph 0 to " + Num(x) +
           ", graph 1 nohead lw 2 lc rgb '#cc0000' dt 2\n";
    }
    std::string what = ref.label + ": max |error| " + Short(ref.max_abs);
    if (std::isfinite(ref.mean_abs)) what += ", mean |error| " + Short(ref.mean_abs);
    extra += ", \\\n     NaN with lines lw 2 lc rgb '#cc0000' dt 2 title " + GnuplotQuote(what);
  }
  if (marked && std::isfinite(ref.std) && ref.std > 0.0) {
    const std::string k = Num(n * width / (ref.std * std::sqrt(2.0 * std::numbers::pi)));
    extra += ", \\\n     [" + Num(-4.0 * ref.std) + ":" + Num(4.0 * ref.std) + "] " + k +
             " * exp(-0.5 * (x / " + Num(ref.std) +
             ") ** 2) with lines lw 2 lc rgb '#cc0000' dt 3 title " +
             GnuplotQuote(ref.label + ": std " + Short(ref.std) + " (as N(0, std))");
  }
  s += "plot " + block + " using 1:2 with boxes lt 1 title " +
       GnuplotQuote(std::to_string(v.size()) + " runs, bins of " + Short(width));
  if (sd > 0.0) {
    const std::string k = Num(n * width / (sd * std::sqrt(2.0 * std::numbers::pi)));
    s += ", \\\n     [" + Num(mean - 4.0 * sd) + ":" + Num(mean + 4.0 * sd) + "] " + k +
         " * exp(-0.5 * ((x - " + Num(mean) + ") / " + Num(sd) +
         ") ** 2) with lines lw 2 lt 2 title " +
         GnuplotQuote("normal: mean " + Short(mean) + ", std " + Short(sd));
  }
  s += extra;
  // The next chart scales its own axes.
  return s + "\nunset arrow\nset autoscale x\nset autoscale y\nset ytics autofreq\n";
}

// The script lines of one chart; empty when it has nothing to draw.
std::string ChartScript(const SweepChart& chart, std::size_t index) {
  if (chart.histogram) return HistogramScript(chart, index);
  const std::vector<std::string> categories =
      chart.categorical_x ? Categories(chart) : std::vector<std::string>{};
  const std::size_t count = chart.series.size();
  // Sideways spread of the series at one category: at most 0.6 of the gap.
  const double step = std::min(0.1, 0.6 / static_cast<double>(count));
  std::string blocks, items;
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
      blocks += Num(p.x) + " " + Num(p.mean);
      if (!chart.scatter) blocks += " " + Num(p.min) + " " + Num(p.max);
      blocks += "\n";
    }
    blocks += "EOD\n";
    any_label = any_label || !s.label.empty();
    std::string style;
    if (chart.scatter) {
      style = "using 1:2 with points pt 7 ps 0.8";
    } else if (chart.categorical_x) {
      style = "using 1:2:3:4 with yerrorbars pt 7 ps 1.2 lw 2";
    } else {
      style = "using 1:2:3:4 with yerrorlines pt 7 ps 1.2 lw 2";
    }
    items += std::string(items.empty() ? "plot " : ", \\\n     ") + block + " " + style + " lt " +
             std::to_string(k + 1) + " title " +
             GnuplotQuote(s.label.empty() ? what : s.label);
  }
  if (items.empty()) return {};

  std::string s = "\n" + blocks + "set output " + GnuplotQuote(chart.file) + "\nset title " +
                  GnuplotQuote(chart.title) + "\nset xlabel " + GnuplotQuote(chart.x_label) +
                  "\nset ylabel " + GnuplotQuote(chart.y_label) + "\n";
  if (chart.categorical_x) {
    s += "set xrange [-0.5:" + Num(static_cast<double>(categories.size()) - 0.5) + "]\nset xtics (";
    for (std::size_t i = 0; i < categories.size(); ++i) {
      s += (i ? ", " : "") + GnuplotQuote(categories[i]) + " " + std::to_string(i);
    }
    s += ")\n";
  } else {
    s += "set autoscale x\nset xtics autofreq\n";
  }
  if (any_label) {
    s += "set key title " + GnuplotQuote(what) + "\n";
  } else {
    s += "set key title ''\n";
  }
  return s + items + "\n";
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
      GnuplotPngTerminal(kWidthPx, kHeightPx) +
      "set grid\n"
      "set key below\n"
      "set offsets graph 0.05, graph 0.05, graph 0.05, graph 0.05\n";
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
