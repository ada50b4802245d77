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

// The one pass over the rows: where each starts, the $signals block of the
// columns the time plots draw, the tracks' extent, the other robots' and
// workers' tracks, each belt's last travel and a person's nearest approach.
std::string ReadRows(RobotRun& run) {
  const Columns& c = run.col;
  for (const int col : {c.x, c.y, c.error, c.bound_from, c.flow_reference, c.vx, c.vy, c.cap,
                        c.protective, c.warning, c.distance, c.field_set}) {
    run.data.Use(col);
  }
  for (const auto* list :
       {&c.belt_speeds, &c.belt_ons, &c.flows, &c.flow_truths, &c.flow_filtered}) {
    for (const int col : *list) run.data.Use(col);
  }
  int last_column = std::max(c.x, c.y);
  for (int col : c.belt_travels) last_column = std::max(last_column, col);
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
      const auto d = Column(fields, c.distance);
      if (d && !(*d >= run.closest_m)) {
        run.closest_m = *d;
        run.closest_t = *t;
      }
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

// Where any belt is scheduled on, as a column expression (1 on, 0 off);
// empty without on columns.
std::string AnyBeltOn(const RobotRun& run) {
  std::string any_on;
  for (std::size_t i = 0; i < run.col.belt_ons.size(); ++i) {
    any_on += (i ? " || " : "") + run.data.Expr(run.col.belt_ons[i]) + " > 0.5";
  }
  return any_on;
}

// The line's on state (paper 1 Figs. 5-7 mark it) as a band along the top
// of the plot, on the second y axis, and the data kept clear of it; none
// without on columns.
struct LineOnBand {
  std::string axes;  // set before the plot
  std::vector<PlotItem> items;
};
LineOnBand LineOn(const RobotRun& run) {
  const std::string any_on = AnyBeltOn(run);
  if (any_on.empty()) return {};
  return {style::kLineOnAxes,
          {{"$signals using 1:((" + any_on + ") ? " + style::kLineOnBandFrom + " : 1):(1)",
            style::kLineOnStyle, style::kLineOnTitle}}};
}

// error.png: the deviation (or drift) in mm against time, with the bound
// the run is judged by (paper paper 1 Figs. 5 and 7).
std::string ErrorFigure(RobotRun& run) {
  const RobotPlotSpec& spec = run.spec;
  if (run.col.error == 0) return {};
  const LineOnBand band = LineOn(run);
  std::vector<PlotItem> items = band.items;
  items.push_back({"$signals using 1:(1000 * " + run.data.Expr(run.col.error) + ")",
                   std::string("with lines ") + style::kMeasuredStyle,
                   spec.error_name.empty() ? spec.error_label : spec.error_name});
  const RobotPlotSpec::Bound& bound = spec.error_bound;
  if (bound.value_m > 0.0) {
    const std::string mm = Num(1000.0 * bound.value_m);
    const std::string label =
        bound.label.empty() ? "bound " + style::Short(1000.0 * bound.value_m) + " mm" : bound.label;
    if (run.col.bound_from > 0) {
      items.push_back(
          {"$signals using 1:(" + run.data.Expr(run.col.bound_from) + " > 0.5 ? " + mm + " : NaN)",
           std::string("with lines ") + style::kBoundStyle, label});
    } else {
      items.push_back({mm, std::string("with lines ") + style::kBoundStyle, label});
    }
  }
  std::string what = spec.error_label;
  if (!what.empty()) what[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(what[0])));
  return style::BeginFigure(spec.file_prefix + "error", spec.format, run.outputs) +
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

// The field depth of the active set (a column expression from the field
// set's index; `which` 0 protective, 1 warning).
std::string ActiveDepth(const RobotRun& run, int which) {
  const auto& depths = run.spec.safety.field_depths_m;
  if (run.col.field_set == 0 || depths.empty()) return {};
  std::string e = "NaN";
  for (std::size_t k = depths.size(); k-- > 0;) {
    const double d = depths[k][static_cast<std::size_t>(which)];
    e = "(" + run.data.Expr(run.col.field_set) + " < " + std::to_string(k) + ".5 ? " +
        (std::isfinite(d) ? Num(d) : "NaN") + " : " + e + ")";
  }
  return e;
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
    const std::string protective = ActiveDepth(run, 0), warning = ActiveDepth(run, 1);
    if (!protective.empty()) {
      items.push_back({"$signals using 1:" + protective, "with steps lw 1.5 lc rgb '#CC0000'",
                       "protective field's reach (active set)"});
      items.push_back({"$signals using 1:" + warning, "with steps dt 4 lw 1.5 lc rgb '#E69F00'",
                       "warning field's reach (active set)"});
    }
    std::string setup = "set ylabel 'distance (m)'\nset yrange [0:*]\n";
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
  // Each field a lane: a bar where it is infringed.
  const auto lane = [&](int csv, double at) {
    return "$signals using 1:(" + Num(at - 0.3) + "):(" + expr(csv) + " < 0.5 ? " + Num(at + 0.3) +
           " : " + Num(at - 0.3) + ")";
  };
  panels.push_back({{lane(c.protective, 1.0),
                     "with filledcurves fillcolor rgb '#CC0000' fillstyle solid 1.0 noborder",
                     "protective field infringed (a safe stop)"},
                    {lane(c.warning, 0.0),
                     "with filledcurves fillcolor rgb '#E69F00' fillstyle solid 1.0 noborder",
                     "warning field infringed (slow down)"}});
  setups.push_back(
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
    if (last) {
      for (auto& item : items) item.title.clear();
    }
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
  RobotRun run{spec, signals, FindColumns(spec, signals), {}, 0.0, 0.0, {}, {}, {}, {}, NAN,
               NAN,  &names};
  const std::string script = Script(run);
  return DrawWithGnuplot(dir, spec.file_prefix + kScript, script, names);
}

}  // namespace linesim::plots
