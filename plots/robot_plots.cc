#include "plots/robot_plots.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "cosim/variable_table.h"
#include "plots/figure_style.h"
#include "plots/gnuplot.h"
#include "plots/robot_run.h"

namespace linesim::plots {

namespace {

namespace fs = std::filesystem;
using robot::Columns;
using robot::RobotRun;
using style::PlotItem;

constexpr const char* kSignals = "signals.csv";
constexpr const char* kScript = "plots.gp";
constexpr style::Canvas kCanvas{1000, 800};

// Shortest text that reads back to the same double: deterministic and
// independent of the locale.
std::string Num(double x) { return cosim::FormatValue(x); }

// The columns the spec names, every unknown one reported at once.
Columns FindColumns(const RobotPlotSpec& spec, const table::Signals& signals) {
  if (spec.x_column.empty() || spec.y_column.empty()) {
    throw std::runtime_error("robot plots need the x and y columns of the robot position");
  }
  table::ColumnFinder column(signals.header, signals.file);
  Columns c;
  c.x = column(spec.x_column, "robot x");
  c.y = column(spec.y_column, "robot y");
  c.yaw = column(spec.yaw_column, "robot yaw");
  c.z = column(spec.z_column, "robot height");
  for (const auto& [wx, wy] : spec.wheel_columns) {
    c.wheels.emplace_back(column(wx, "wheel x"), column(wy, "wheel y"));
  }
  c.error = column(spec.error_column, "error");
  c.bound_from = column(spec.error_bound.from_column, "bound from");
  const auto all = [&](const std::vector<std::string>& names, const char* role) {
    std::vector<int> cols;
    for (const auto& name : names) cols.push_back(column(name, role));
    return cols;
  };
  c.belt_speeds = all(spec.belt_speed_columns, "belt speed");
  c.belt_ons = all(spec.belt_on_columns, "belt on");
  c.belt_travels = all(spec.belt_travel_columns, "belt travel");
  c.flows = all(spec.flow_columns, "optic flow");
  c.flow_truths = all(spec.flow_truth_columns, "optic flow truth");
  c.flow_filtered = all(spec.flow_filtered_columns, "filtered optic flow");
  c.flow_reference = column(spec.flow_reference_column, "ground-truth surface speed");
  for (const auto& o : spec.others) {
    c.others.push_back({column(o.x_column, "other robot x"), column(o.y_column, "other robot y"),
                        column(o.yaw_column, "other robot yaw")});
  }
  for (const auto& w : spec.workers) {
    Columns::Worker cw{column(w.x_column, "worker x"), column(w.y_column, "worker y"), {}};
    for (std::size_t k = 0; k < 4; ++k) cw.legs[k] = column(w.leg_columns[k], "worker legs");
    c.workers.push_back(cw);
  }
  c.ranges = all(spec.scan.range_columns, "scan range");
  c.scan_time = column(spec.scan.scan_time_column, "scan start time");
  const RobotPlotSpec::Safety& safety = spec.safety;
  if (!safety.cap_column.empty()) {
    c.vx = column(safety.velocity_x_column, "robot vx");
    c.vy = column(safety.velocity_y_column, "robot vy");
    c.cap = column(safety.cap_column, "speed cap");
    c.protective = column(safety.protective_column, "protective field");
    c.warning = column(safety.warning_column, "warning field");
    c.distance = column(safety.distance_column, "person distance");
    c.field_set = column(safety.field_set_column, "field set");
  }
  column.ThrowIfUnknown();
  if (!c.belt_travels.empty() && c.belt_travels.size() != spec.scene.belts.size()) {
    throw std::runtime_error("robot plots: " + std::to_string(c.belt_travels.size()) +
                             " belt travel columns for " + std::to_string(spec.scene.belts.size()) +
                             " belts of the scene: expected one per belt");
  }
  if (!c.ranges.empty() && c.yaw == 0) {
    throw std::runtime_error("the scan plot needs the robot's yaw column");
  }
  return c;
}

// Spans of time where a state holds, from one row after another.
class SpanTracker {
 public:
  void Row(double t, bool holds, std::vector<std::array<double, 2>>& spans) {
    if (holds && !open_) spans.push_back({t, t});
    // A span reaches to the next row: the state held until then.
    if (holds || open_) spans.back()[1] = t;
    open_ = holds;
  }

 private:
  bool open_ = false;
};

// What the figures draw of states (the line on, the fields infringed, the
// field set, the task done) from one row: spans and change points, so that
// gnuplot draws a few rectangles and steps instead of a curve of every row.
struct StateTrackers {
  SpanTracker line_on, protective, warning;
  void Row(RobotRun& run, const std::vector<std::string_view>& fields, double t) {
    const Columns& c = run.col;
    using table::Column;
    if (!c.belt_ons.empty()) {
      bool on = false;
      for (const int col : c.belt_ons) on = on || Column(fields, col).value_or(0.0) > 0.5;
      line_on.Row(t, on, run.line_on);
    }
    if (c.protective > 0) {
      protective.Row(t, Column(fields, c.protective).value_or(1.0) < 0.5, run.protective_infringed);
      warning.Row(t, Column(fields, c.warning).value_or(1.0) < 0.5, run.warning_infringed);
    }
    if (const auto set = Column(fields, c.field_set)) {
      const int index = static_cast<int>(std::lround(*set));
      if (run.field_sets.empty() || run.field_sets.back().second != index) {
        run.field_sets.emplace_back(t, index);
      }
    }
    if (std::isnan(run.bound_from_t) && Column(fields, c.bound_from).value_or(0.0) > 0.5) {
      run.bound_from_t = t;
    }
    if (const auto d = Column(fields, c.distance); d && !(*d >= run.closest_m)) {
      run.closest_m = *d;
      run.closest_t = t;
    }
  }
};

// The one pass over the rows: where each starts, the $signals block of the
// columns the time plots draw, the tracks' extent, the other robots' and
// workers' tracks, each belt's last travel, the states' spans and a
// person's nearest approach.
std::string ReadRows(RobotRun& run) {
  const Columns& c = run.col;
  run.data.Use(c.x);
  run.data.Use(c.y);
  run.data.UseScaled(c.error, 1000.0);  // drawn in mm
  for (const int col : {c.flow_reference, c.vx, c.vy, c.cap, c.distance}) run.data.Use(col);
  for (const auto* list :
       {&c.belt_speeds, &c.belt_ons, &c.flows, &c.flow_truths, &c.flow_filtered}) {
    for (const int col : *list) run.data.Use(col);
  }
  int last_column = std::max({c.x, c.y, c.bound_from, c.protective, c.warning, c.field_set});
  for (int col : c.belt_travels) last_column = std::max(last_column, col);
  for (int col : c.belt_ons) last_column = std::max(last_column, col);
  for (const auto& o : c.others) last_column = std::max({last_column, o.x, o.y});
  for (const auto& w : c.workers) last_column = std::max({last_column, w.x, w.y});
  const auto needed = std::max(static_cast<std::size_t>(last_column), run.data.last_csv());
  for (const auto& p : run.spec.path_m) run.tracks.Add(p[0], p[1]);
  run.travel_end.assign(c.belt_travels.size(), std::nullopt);
  run.other_tracks.assign(c.others.size(), {});
  run.worker_tracks.assign(c.workers.size(), {});
  std::string block;
  std::vector<std::string_view> fields;
  std::string line;
  table::Signals& signals = run.signals;
  StateTrackers states;
  bool first = true;
  while (true) {
    const std::streamoff start = signals.in.tellg();
    if (!std::getline(signals.in, line)) break;
    if (line.empty() || line == "\r") continue;
    signals.row_starts.push_back(start);
    table::SplitCsv(line, fields, needed);
    run.data.AppendRow(fields, block);
    using table::Column;
    if (const auto t = Column(fields, 1)) {
      if (first) run.t_first = *t;
      first = false;
      run.t_last = *t;
      states.Row(run, fields, *t);
    }
    const auto x = Column(fields, c.x), y = Column(fields, c.y);
    if (x && y) run.tracks.Add(*x, *y);
    for (std::size_t k = 0; k < c.others.size(); ++k) {
      const auto ox = Column(fields, c.others[k].x), oy = Column(fields, c.others[k].y);
      if (!ox || !oy) continue;
      run.tracks.Add(*ox, *oy);
      run.other_tracks[k].push_back({*ox, *oy});
    }
    for (std::size_t k = 0; k < c.workers.size(); ++k) {
      const auto wx = Column(fields, c.workers[k].x), wy = Column(fields, c.workers[k].y);
      if (wx && wy) run.worker_tracks[k].push_back({*wx, *wy});
    }
    for (std::size_t b = 0; b < c.belt_travels.size(); ++b) {
      if (const auto d = Column(fields, c.belt_travels[b])) run.travel_end[b] = d;
    }
  }
  if (signals.row_starts.empty()) {
    throw std::runtime_error(signals.file.string() + " has no data rows");
  }
  return block;
}

// The shared lines of a time plot: the legend in a band at the canvas'
// foot (never over a curve), the axes above it, time from the first row
// to the last.
std::string TimeAxes(const RobotRun& run, const std::vector<std::string>& titles) {
  const style::KeyBand key = style::KeyBelow(titles, kCanvas);
  return key.commands + "set bmargin at screen " +
         style::Short(style::AxisBottomAbove(key.top_screen, kCanvas), 4) +
         "\nset xlabel 'time (s)'\nset xrange [" + Num(run.t_first) + ":" + Num(run.t_last) + "]\n";
}

// Rectangles over time spans, from y0 to y1 in `y_system` (graph or
// first), behind the data.
std::string SpanRectangles(const std::vector<std::array<double, 2>>& spans,
                           const std::string& y_system, const std::string& y0,
                           const std::string& y1, const std::string& fill) {
  std::string s;
  for (const auto& [from, to] : spans) {
    s += "set object rectangle from first " + Num(from) + ", " + y_system + " " + y0 +
         " to first " + Num(to) + ", " + y_system + " " + y1 + " " + fill + " behind\n";
  }
  return s;
}

// The line's on state (paper 1 Figs. 5-7 mark it) as a band along the top
// of the plot where any belt is scheduled on, the data kept clear of it;
// none without on columns.
struct LineOnBand {
  std::string axes;  // set before the plot
  std::vector<PlotItem> items;
};
LineOnBand LineOn(const RobotRun& run) {
  if (run.col.belt_ons.empty()) return {};
  return {SpanRectangles(run.line_on, "graph", style::kLineOnBandFrom, "1", style::kLineOnFill) +
              "set offsets 0, 0, graph 0.1, 0\n",
          {{"keyentry", std::string("with boxes ") + style::kLineOnFill, style::kLineOnTitle}}};
}

// error.png: the deviation (or drift) in mm against time, with the bound
// the run is judged by (paper paper 1 Figs. 5 and 7).
std::string ErrorFigure(RobotRun& run) {
  const RobotPlotSpec& spec = run.spec;
  if (run.col.error == 0) return {};
  const LineOnBand band = LineOn(run);
  std::vector<PlotItem> items = band.items;
  items.push_back({"$signals using 1:" + std::to_string(run.data[run.col.error]),
                   std::string("with lines ") + style::kMeasuredStyle,
                   spec.error_name.empty() ? spec.error_label : spec.error_name});
  const RobotPlotSpec::Bound& bound = spec.error_bound;
  std::string bound_block;
  if (bound.value_m > 0.0) {
    const std::string mm = Num(1000.0 * bound.value_m);
    const std::string label =
        bound.label.empty() ? "bound " + style::Short(1000.0 * bound.value_m) + " mm" : bound.label;
    if (run.col.bound_from > 0) {
      // From the time the task was done to the end (nothing if never).
      const double from = std::isnan(run.bound_from_t) ? run.t_last : run.bound_from_t;
      bound_block =
          "$bound << EOD\n" + Num(from) + "," + mm + "\n" + Num(run.t_last) + "," + mm + "\nEOD\n";
      items.push_back({"$bound using 1:2", std::string("with lines ") + style::kBoundStyle, label});
    } else {
      items.push_back({mm, std::string("with lines ") + style::kBoundStyle, label});
    }
  }
  std::string what = spec.error_label;
  if (!what.empty()) what[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(what[0])));
  return bound_block + style::BeginFigure(spec.file_prefix + "error", spec.format, run.outputs) +
         style::Caption(what + " against time", spec.run_caption) +
         TimeAxes(run, style::Titles(items)) + "set offsets 0, 0, graph 0.08, 0\n" + band.axes +
         "set ylabel " + GnuplotQuote(spec.error_label + " (mm)") + "\nset yrange [0:*]\n" +
         style::PlotCommand(items);
}

// belt.png: each belt's speed, and its schedule as steps on the right axis.
std::string BeltFigure(RobotRun& run) {
  const RobotPlotSpec& spec = run.spec;
  const Columns& c = run.col;
  if (c.belt_speeds.empty() && c.belt_ons.empty()) return {};
  const auto name = [&](std::size_t i) {
    return i < spec.scene.belts.size() && !spec.scene.belts[i].name.empty()
               ? spec.scene.belts[i].name
               : "belt " + std::to_string(i);
  };
  std::vector<PlotItem> items;
  for (std::size_t i = 0; i < c.belt_speeds.size(); ++i) {
    items.push_back({"$signals using 1:" + std::to_string(run.data[c.belt_speeds[i]]),
                     "with lines lw 2 lc rgb '" + std::string(style::SeriesColour(i)) + "'",
                     "speed of " + name(i)});
  }
  for (std::size_t i = 0; i < c.belt_ons.size(); ++i) {
    items.push_back(
        {"$signals using 1:" + std::to_string(run.data[c.belt_ons[i]]),
         "axes x1y2 with steps dt 2 lw 1.5 lc rgb '" + std::string(style::SeriesColour(i)) + "'",
         name(i) + " scheduled on (right axis)"});
  }
  return style::BeginFigure(spec.file_prefix + "belt", spec.format, run.outputs) +
         style::Caption("The line's belts: speed and schedule against time", spec.run_caption) +
         TimeAxes(run, style::Titles(items)) +
         "set ylabel 'belt speed (m/s)'\nset yrange [0:*]\nset offsets 0, 0, graph 0.08, 0\n"
         "set y2label 'scheduled'\nset y2range [-0.05:1.3]\nset y2tics ('off' 0, 'on' 1)\n"
         "set ytics nomirror\n" +
         style::PlotCommand(items);
}

// Panels of a multiplot in a grid of `columns`, filling the area between
// `bottom` and `top` (screen fractions) with a gap for the x tic labels
// (and a panel title: `titled`) between rows; row k's height in
// proportion to weights[k] (equal without).
std::vector<style::Panel> PanelGrid(std::size_t count, std::size_t columns, double bottom,
                                    double top, bool titled, std::vector<double> weights = {}) {
  const std::size_t rows = (count + columns - 1) / columns;
  weights.resize(rows, weights.empty() ? 1.0 : weights.back());
  double total = 0.0;
  for (double w : weights) total += w;
  const double left = 0.08, right = 0.98, hgap = 0.08;
  const double vgap = (titled ? 4.8 : 2.8) * style::kFontPx / kCanvas.height_px;
  const double width =
      (right - left - hgap * static_cast<double>(columns - 1)) / static_cast<double>(columns);
  const double height = top - bottom - vgap * static_cast<double>(rows - 1);
  std::vector<style::Panel> panels;
  double row_top = top;
  for (std::size_t row = 0; row < rows; ++row) {
    const double h = height * weights[row] / total;
    for (std::size_t col = 0; col < columns && row * columns + col < count; ++col) {
      const double l = left + static_cast<double>(col) * (width + hgap);
      panels.push_back({l, l + width, row_top - h, row_top});
    }
    row_top -= h + vgap;
  }
  return panels;
}

// Where a multiplot's panels may go: between the key band and the
// caption's two lines (and a panel title under them: `titled`).
struct PanelArea {
  double bottom, top;
};
PanelArea MultiplotArea(const style::KeyBand& key, bool titled) {
  return {style::AxisBottomAbove(key.top_screen, kCanvas),
          1.0 - (titled ? 6.6 : 4.2) * style::kFontPx / kCanvas.height_px};
}
std::string BeginMultiplot(const std::string& what, const std::string& run_caption) {
  std::string title = GnuplotQuote(what);
  if (!run_caption.empty()) title += " . \"\\n\" . " + GnuplotQuote(run_caption);
  return "set multiplot title " + title + "\n";
}

// optic_flow.png (paper 1, Fig. 4): one panel per PX4Flow, each with what
// it reads (the surface relative to it), the same from ground truth, the
// filter's estimate of the surface speed (Eq. 2) and the belt's ground
// truth (its encoder wheel); one legend for all.
std::string OpticFlowFigure(RobotRun& run) {
  const RobotPlotSpec& spec = run.spec;
  const Columns& c = run.col;
  if (c.flows.empty() || c.flow_reference == 0) return {};
  const LineOnBand band = LineOn(run);
  const auto using_col = [&](int csv) {
    return "$signals using 1:" + std::to_string(run.data[csv]);
  };
  const auto panel_items = [&](std::size_t i) {
    std::vector<PlotItem> items = band.items;
    items.push_back({using_col(c.flows[i]), "with lines lw 1 lc rgb '#56B4E9'",
                     "PX4Flow reading (the surface relative to the sensor)"});
    if (i < c.flow_truths.size()) {
      items.push_back({using_col(c.flow_truths[i]), "with lines dt 2 lw 1.5 lc rgb '#D55E00'",
                       "the same from ground truth"});
    }
    if (i < c.flow_filtered.size()) {
      items.push_back({using_col(c.flow_filtered[i]), "with lines lw 2 lc rgb '#0072B2'",
                       "filtered: the surface speed (Eq. 2)"});
    }
    items.push_back({using_col(c.flow_reference), "with lines lw 1 lc rgb '#000000'",
                     "belt speed, ground truth (encoder wheel)"});
    return items;
  };
  const style::KeyBand key = style::KeyBelow(style::Titles(panel_items(0)), kCanvas);
  const PanelArea area = MultiplotArea(key, true);
  const std::size_t columns = c.flows.size() > 2 ? 2 : 1;
  const auto panels = PanelGrid(c.flows.size(), columns, area.bottom, area.top, true);
  std::string s =
      style::BeginFigure(spec.file_prefix + "optic_flow", spec.format, run.outputs) +
      BeginMultiplot(
          "Optic flow against the belt's ground truth, per PX4Flow (cf. paper 1, Fig. 4)",
          spec.run_caption) +
      band.axes + "set xrange [" + Num(run.t_first) + ":" + Num(run.t_last) + "]\n";
  for (std::size_t i = 0; i < c.flows.size(); ++i) {
    const std::string label = i < spec.flow_labels.size() ? spec.flow_labels[i] : "sensor";
    const bool bottom_row = i + columns >= c.flows.size();
    s += panels[i].Margins() + "set title " + GnuplotQuote(label) + "\n" +
         (bottom_row ? "set xlabel 'time (s)'\n" : "unset xlabel\n") +
         (i % columns == 0 ? "set ylabel 'speed along the belt (m/s)'\n" : "unset ylabel\n") +
         (i == 0 ? key.commands : "unset key\n");
    // The legend is the first panel's: the others' items go untitled.
    std::vector<PlotItem> items = panel_items(i);
    if (i > 0) {
      for (auto& item : items) item.title.clear();
    }
    s += style::PlotCommand(items);
  }
  return s + "unset multiplot\n";
}

// How far the active field set's protective and warning fields reach
// beyond the body's front, as a block of steps from each change of the
// set on ("t,protective,warning"; NaN: no such field); empty without.
std::string ActiveReach(const RobotRun& run) {
  const auto& depths = run.spec.safety.field_depths_m;
  if (run.field_sets.empty() || depths.empty()) return {};
  std::string rows;
  const auto row = [&](double t, int set) {
    const bool known = set >= 0 && static_cast<std::size_t>(set) < depths.size();
    const auto depth = [&](std::size_t which) {
      const double d = known ? depths[static_cast<std::size_t>(set)][which] : NAN;
      return std::isfinite(d) ? Num(d) : std::string("NaN");
    };
    rows += Num(t) + "," + depth(0) + "," + depth(1) + "\n";
  };
  for (const auto& [t, set] : run.field_sets) row(t, set);
  row(run.t_last, run.field_sets.back().second);
  return "$reach << EOD\n" + rows + "EOD\n";
}

// safety.png: the S300's safety function against a person, in panels on
// one time axis: the robot's speed and the speed cap; the distance from
// the body to the nearest person with the active fields' reach beyond the
// front and the closest approach; the fields' states.
std::string SafetyFigure(RobotRun& run) {
  const RobotPlotSpec& spec = run.spec;
  const Columns& c = run.col;
  if (c.cap == 0) return {};
  const auto expr = [&](int csv) { return run.data.Expr(csv); };
  std::vector<std::vector<PlotItem>> panels;
  std::vector<std::string> setups;
  panels.push_back({{"$signals using 1:(sqrt(" + expr(c.vx) + "**2 + " + expr(c.vy) + "**2))",
                     std::string("with lines ") + style::kMeasuredStyle, "robot speed"},
                    {"$signals using 1:(" + expr(c.cap) + " < 0 ? NaN : " + expr(c.cap) + ")",
                     "with lines dt 2 lw 2 lc rgb '#D55E00'", "speed cap (safety function)"}});
  setups.push_back("set ylabel 'speed (m/s)'\nset yrange [0:*]\nset offsets 0, 0, graph 0.1, 0\n");
  if (c.distance > 0) {
    std::vector<PlotItem> items = {{"$signals using 1:" + std::to_string(run.data[c.distance]),
                                    "with lines lw 2 lc rgb '#009E73'",
                                    "distance to the nearest person"}};
    const std::string reach = ActiveReach(run);
    if (!reach.empty()) {
      items.push_back({"$reach using 1:2", "with steps lw 1.5 lc rgb '#CC0000'",
                       "protective field's reach (active set)"});
      items.push_back({"$reach using 1:3", "with steps dt 4 lw 1.5 lc rgb '#E69F00'",
                       "warning field's reach (active set)"});
    }
    std::string setup = reach + "set ylabel 'distance (m)'\nset yrange [0:*]\n";
    if (std::isfinite(run.closest_m)) {
      setup =
          "$closest << EOD\n" + Num(run.closest_t) + "," + Num(run.closest_m) + "\nEOD\n" + setup;
      items.push_back({"$closest using 1:2", "with points pt 6 ps 2 lw 2 lc rgb '#000000'",
                       "closest approach: " + style::Short(run.closest_m) +
                           " m at t = " + style::Short(run.closest_t, 4) + " s"});
    }
    panels.push_back(items);
    setups.push_back(setup);
  }
  // Each field a lane: a bar where it is infringed (rectangles over the
  // spans; the panel plots only the legend's entries).
  const std::string protective_fill = "fillcolor rgb '#CC0000' fillstyle solid 1.0 noborder";
  const std::string warning_fill = "fillcolor rgb '#E69F00' fillstyle solid 1.0 noborder";
  panels.push_back(
      {{"keyentry", "with boxes " + protective_fill, "protective field infringed (a safe stop)"},
       {"keyentry", "with boxes " + warning_fill, "warning field infringed (slow down)"}});
  setups.push_back(
      SpanRectangles(run.protective_infringed, "first", "0.7", "1.3", protective_fill) +
      SpanRectangles(run.warning_infringed, "first", "-0.3", "0.3", warning_fill) +
      "set ylabel 'field'\nset yrange [-0.6:1.6]\nset ytics ('warning' 0, 'protective' 1)\n"
      "set offsets 0, 0, 0, 0\n");

  std::vector<PlotItem> all;
  for (const auto& p : panels) all.insert(all.end(), p.begin(), p.end());
  const style::KeyBand key = style::KeyBelow(style::Titles(all), kCanvas);
  const PanelArea area = MultiplotArea(key, false);
  // The fields' lanes need less height than the curves.
  std::vector<double> weights(panels.size(), 1.0);
  weights.back() = 0.5;
  const auto grid = PanelGrid(panels.size(), 1, area.bottom, area.top, false, weights);
  std::string s =
      style::BeginFigure(spec.file_prefix + "safety", spec.format, run.outputs) +
      BeginMultiplot("The S300's safety function against a person: speed, distance and fields",
                     spec.run_caption) +
      "set xrange [" + Num(run.t_first) + ":" + Num(run.t_last) + "]\n";
  for (std::size_t i = 0; i < panels.size(); ++i) {
    // The last panel's legend lists every panel's entries, in order: its
    // own items are drawn untitled, and all entries given as keyentries.
    const bool last = i + 1 == panels.size();
    std::vector<PlotItem> items = panels[i];
    // The fields' lanes are rectangles: the panel plots nothing of its own
    // (NaN: gnuplot fails on a plot of keyentries alone).
    if (last) items = {{"NaN", "with lines", ""}};
    s += grid[i].Margins() + setups[i] +
         (last ? "set xlabel 'time (s)'\n" + key.commands
               : std::string("unset xlabel\nunset key\n")) +
         style::PlotCommand(items, last ? all : std::vector<PlotItem>{}) +
         "unset ytics\nset ytics\n";
  }
  return s + "unset multiplot\n";
}

// The whole script: the data, then one figure after another.
std::string Script(RobotRun& run) {
  std::string s =
      "# Written by linesim (plots/robot_plots.cc). Run `gnuplot plots.gp` in this folder\n"
      "# to redraw; the data are in its blocks, copied from signals.csv ($signals: the\n"
      "# columns the time plots draw, time first).\n" +
      GnuplotTerminal(run.spec.format, kCanvas.width_px, kCanvas.height_px);
  const std::string block = ReadRows(run);
  s += "$signals << EOD\n" + block + "EOD\n";
  s += robot::TopView(run);
  s += ErrorFigure(run);
  s += BeltFigure(run);
  s += OpticFlowFigure(run);
  s += robot::ScanView(run);
  s += robot::SideView(run);
  s += SafetyFigure(run);
  return s + "unset output\n";
}

}  // namespace

std::vector<std::string> RobotPlotFiles(const std::string& prefix) {
  std::vector<std::string> names = {prefix + kScript};
  for (PlotFormat f : {PlotFormat::kPng, PlotFormat::kSvg, PlotFormat::kPdf}) {
    for (const char* name :
         {"top_view", "error", "belt", "optic_flow", "scan", "side_view", "safety"}) {
      names.push_back(PlotFile(prefix + name, f));
    }
  }
  return names;
}

std::vector<std::string> WriteRobotPlots(const std::string& dir, const RobotPlotSpec& spec) {
  const fs::path folder(dir);
  table::Signals signals = table::OpenSignals(folder / kSignals);
  std::vector<std::string> names;
  RobotRun run(spec, signals, FindColumns(spec, signals), &names);
  const std::string script = Script(run);
  return DrawWithGnuplot(dir, spec.file_prefix + kScript, script, names);
}

}  // namespace linesim::plots
