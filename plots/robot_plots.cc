#include "plots/robot_plots.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <stdexcept>

#include "cosim/closest_names.h"
#include "cosim/variable_table.h"
#include "plots/gnuplot.h"

namespace linesim::plots {

namespace {

namespace fs = std::filesystem;

constexpr const char* kSignals = "signals.csv";
constexpr const char* kScript = "plots.gp";

// Shortest text that reads back to the same double: deterministic and
// independent of the locale.
std::string Num(double x) { return cosim::FormatValue(x); }

// Views of the first `max_fields` fields of a CSV line (all when 0), into a
// vector reused from row to row: no allocation per field.
void SplitCsv(std::string_view line, std::vector<std::string_view>& fields,
              std::size_t max_fields = 0) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  fields.clear();
  std::size_t begin = 0;
  while (max_fields == 0 || fields.size() < max_fields) {
    const std::size_t comma = line.find(',', begin);
    fields.push_back(line.substr(begin, comma - begin));
    if (comma == std::string_view::npos) break;
    begin = comma + 1;
  }
}

// 1-based column `col` of a split row, as a number.
std::optional<double> Column(const std::vector<std::string_view>& fields, int col) {
  if (col < 1 || static_cast<std::size_t>(col) > fields.size()) return std::nullopt;
  // Non-finite values are left out of the plots like missing ones.
  return cosim::ParseFiniteValue(fields[static_cast<std::size_t>(col - 1)]);
}

/// signals.csv, open after its header: read row by row, never held whole.
struct Signals {
  fs::path file;
  std::ifstream in;
  std::vector<std::string> header;
};

Signals OpenSignals(const fs::path& file) {
  Signals s{file, std::ifstream(file, std::ios::binary), {}};
  if (!s.in) {
    throw std::runtime_error("cannot read " + file.string() + ": " + std::strerror(errno));
  }
  std::string line;
  if (!std::getline(s.in, line)) throw std::runtime_error(file.string() + " is empty");
  std::vector<std::string_view> fields;
  SplitCsv(line, fields);
  s.header.assign(fields.begin(), fields.end());
  return s;
}

/// 1-based column numbers (as gnuplot's `using` counts) by name; every
/// unknown name is collected so that one error lists them all.
class ColumnFinder {
 public:
  ColumnFinder(const std::vector<std::string>& header, fs::path file)
      : header_(header), file_(std::move(file)) {}

  int operator()(const std::string& name, const char* role) {
    const auto it = std::find(header_.begin(), header_.end(), name);
    if (it != header_.end()) return static_cast<int>(it - header_.begin()) + 1;
    unknown_.push_back("no column '" + name + "' (" + role + ")" +
                       cosim::ClosestHint(name, header_));
    return 0;
  }

  void ThrowIfUnknown() const {
    if (unknown_.empty()) return;
    std::string text = file_.string() + ": ";
    for (std::size_t i = 0; i < unknown_.size(); ++i) text += (i ? "; " : "") + unknown_[i];
    throw std::runtime_error(text);
  }

 private:
  const std::vector<std::string>& header_;
  fs::path file_;
  std::vector<std::string> unknown_;
};

struct Point {
  double x, y;
};

// Extent of what the top view shows, ignoring non-finite points.
struct Bounds {
  double x_min = INFINITY, x_max = -INFINITY, y_min = INFINITY, y_max = -INFINITY;
  void Add(double x, double y) {
    if (!std::isfinite(x) || !std::isfinite(y)) return;
    x_min = std::min(x_min, x);
    x_max = std::max(x_max, x);
    y_min = std::min(y_min, y);
    y_max = std::max(y_max, y);
  }
  bool empty() const { return x_min > x_max; }
};

// Canvas and top-view plot area (screen fractions): the ranges are widened
// to the area's aspect ratio, so that an equal-scale view fills it.
constexpr int kCanvasWidthPx = 1000, kCanvasHeightPx = 800;
constexpr double kLeft = 0.09, kRight = 0.97, kBottom = 0.16, kTop = 0.93;
// The time plots' legend: up to four rows (Fig. 4's ten entries, three to a
// row) at the canvas' foot, under the axes' bottom margin.
constexpr const char* kTimeKey =
    "set bmargin at screen 0.17\nset key at screen 0.5, 0.01 center bottom horizontal\n";

// Corners of a rectangle centred at (x, y), `length` along heading `yaw`.
std::array<Point, 4> Rectangle(double x, double y, double yaw, double length, double width) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  const double hl = 0.5 * length, hw = 0.5 * width;
  std::array<Point, 4> corners;
  const double sx[4] = {hl, -hl, -hl, hl}, sy[4] = {hw, hw, -hw, -hw};
  for (int k = 0; k < 4; ++k) {
    corners[k] = {x + c * sx[k] - s * sy[k], y + s * sx[k] + c * sy[k]};
  }
  return corners;
}

void AppendPolygon(std::string& block, const std::array<Point, 4>& corners) {
  for (int k = 0; k <= 4; ++k) {
    const Point& p = corners[k % 4];
    block += Num(p.x) + "," + Num(p.y) + "\n";
  }
  block += "\n";
}

// Names `name` (without extension) as the next picture in the spec's
// format: its `set output` line, and the file among the outputs.
std::string SetOutput(const std::string& name, PlotFormat format,
                      std::vector<std::string>* outputs) {
  const std::string file = PlotFile(name, format);
  outputs->push_back(file);
  return "set output " + GnuplotQuote(file) + "\n";
}

void AppendBlock(std::string& script, const std::string& name, const std::string& data) {
  script += "$" + name + " << EOD\n" + data + "EOD\n";
}

/// The columns of signals.csv the time plots (and the track) draw, copied
/// as text into the script's $signals block in the pass that reads the file
/// anyway: gnuplot reads them there instead of parsing every row of
/// signals.csv once per curve (in a fleet some 60 columns per robot).
/// Block columns in order of first use; time is always the first.
class DataColumns {
 public:
  DataColumns() { Use(1); }
  /// Adds CSV column `csv` (1-based; 0: none, ignored).
  void Use(int csv) {
    if (csv <= 0 || Has(csv)) return;
    if (static_cast<std::size_t>(csv) >= block_of_.size()) block_of_.resize(csv + 1, 0);
    csv_.push_back(csv);
    block_of_[static_cast<std::size_t>(csv)] = static_cast<int>(csv_.size());
  }
  /// The block column (1-based, as gnuplot counts) of CSV column `csv`.
  int operator[](int csv) const {
    if (!Has(csv))
      throw std::logic_error("robot plots: column " + std::to_string(csv) + " not in $signals");
    return block_of_[static_cast<std::size_t>(csv)];
  }
  std::size_t last_csv() const { return block_of_.size() - 1; }
  /// One row of the block from the fields of a row of signals.csv (as
  /// text: gnuplot reads the same characters it would have read there).
  void AppendRow(const std::vector<std::string_view>& fields, std::string& block) const {
    for (std::size_t k = 0; k < csv_.size(); ++k) {
      if (k) block += ',';
      const auto i = static_cast<std::size_t>(csv_[k] - 1);
      if (i < fields.size()) block += fields[i];
    }
    block += '\n';
  }

 private:
  bool Has(int csv) const {
    return csv > 0 && static_cast<std::size_t>(csv) < block_of_.size() &&
           block_of_[static_cast<std::size_t>(csv)] > 0;
  }
  std::vector<int> csv_;       // block column k + 1 holds CSV column csv_[k]
  std::vector<int> block_of_;  // CSV column -> block column (0: not in it)
};

// Solids of the scene as gnuplot data: boxes as closed polygons, cylinders
// as "x,y,radius" rows for `with circles`.
struct SolidLayer {
  std::string polygons, circles;
};

// Footprint corners of `solid` moved by (dx, dy): a box's four, or the
// bounding square of a cylinder.
std::array<Point, 4> Footprint(const models::Solid& solid, double dx, double dy) {
  if (solid.kind == models::Solid::Kind::kCylinder) {
    return Rectangle(solid.x_m + dx, solid.y_m + dy, 0.0, 2.0 * solid.radius_m,
                     2.0 * solid.radius_m);
  }
  return Rectangle(solid.x_m + dx, solid.y_m + dy, solid.yaw_rad, solid.length_m, solid.width_m);
}

void AppendSolid(SolidLayer& layer, const models::Solid& solid, double dx, double dy) {
  if (solid.kind == models::Solid::Kind::kCylinder) {
    layer.circles +=
        Num(solid.x_m + dx) + "," + Num(solid.y_m + dy) + "," + Num(solid.radius_m) + "\n";
  } else {
    AppendPolygon(layer.polygons, Footprint(solid, dx, dy));
  }
}

std::array<Point, 4> BeltCorners(const models::Belt& b) {
  return Rectangle(b.area.center_x_m, b.area.center_y_m, b.area.direction_rad, b.area.length_m,
                   b.area.width_m);
}

// Row indices of `count` instants evenly spaced from the first row to the
// last (rounded to the nearest row).
std::vector<std::size_t> EvenlySpaced(std::size_t rows, int count) {
  std::vector<std::size_t> picks;
  if (count <= 0) return picks;
  if (count == 1) return {0};
  for (int i = 0; i < count; ++i) {
    const double at = static_cast<double>(i) * static_cast<double>(rows - 1) / (count - 1);
    const auto row = static_cast<std::size_t>(std::lround(at));
    if (picks.empty() || picks.back() != row) picks.push_back(row);
  }
  return picks;
}

// One row of signals.csv, split (row_starts from a pass over the file).
void ReadRow(Signals& signals, const std::vector<std::streamoff>& row_starts, std::size_t row,
             std::string& line, std::vector<std::string_view>& fields) {
  signals.in.clear();
  signals.in.seekg(row_starts[row]);
  if (!std::getline(signals.in, line)) {
    throw std::runtime_error("cannot read " + signals.file.string() + " again at row " +
                             std::to_string(row + 1));
  }
  SplitCsv(line, fields);
}

// scan.png (or .svg, .pdf): see RobotPlotSpec::Scan.
std::string ScanPlot(const RobotPlotSpec& spec, Signals& signals,
                     const std::vector<std::streamoff>& row_starts, int ix, int iy, int iyaw,
                     const std::vector<int>& travels, const std::string& title_prefix,
                     std::vector<std::string>* outputs) {
  const RobotPlotSpec::Scan& scan = spec.scan;
  ColumnFinder column(signals.header, signals.file);
  std::vector<int> ranges;
  for (const auto& name : scan.range_columns) ranges.push_back(column(name, "scan range"));
  const int iscan = column(scan.scan_time_column, "scan start time");
  column.ThrowIfUnknown();
  if (iyaw == 0) throw std::runtime_error("the scan plot needs the robot's yaw column");
  std::string line;
  std::vector<std::string_view> fields;
  // Row times are the first column; rows are in time order.
  const auto row_at = [&](double t) {
    std::size_t lo = 0, hi = row_starts.size() - 1;
    while (lo < hi) {
      const std::size_t mid = (lo + hi) / 2;
      ReadRow(signals, row_starts, mid, line, fields);
      const auto tm = Column(fields, 1);
      if (tm && *tm < t) {
        lo = mid + 1;
      } else {
        hi = mid;
      }
    }
    return lo;
  };
  ReadRow(signals, row_starts, row_at(scan.time_s), line, fields);
  std::vector<double> range(ranges.size(), scan.no_return_m);
  for (std::size_t k = 0; k < ranges.size(); ++k) {
    if (const auto r = Column(fields, ranges[k])) range[k] = *r;
  }
  const auto started = Column(fields, iscan);
  const double start_s = started ? *started : scan.time_s;
  ReadRow(signals, row_starts, row_at(start_s), line, fields);
  const auto x = Column(fields, ix), y = Column(fields, iy), yaw = Column(fields, iyaw);
  if (!x || !y || !yaw) throw std::runtime_error("no robot pose at the scan's start time");
  std::vector<double> travel(travels.size(), 0.0);
  for (std::size_t b = 0; b < travels.size(); ++b) {
    if (const auto d = Column(fields, travels[b])) travel[b] = *d;
  }

  const double c = std::cos(*yaw), sn = std::sin(*yaw);
  const double sx = *x + c * scan.mount_x_m - sn * scan.mount_y_m;
  const double sy = *y + sn * scan.mount_x_m + c * scan.mount_y_m;
  std::string rays, hits;
  Bounds view;
  view.Add(sx, sy);
  for (std::size_t k = 0; k < range.size(); ++k) {
    if (!(range[k] != scan.no_return_m) || !std::isfinite(range[k])) continue;
    const double a = *yaw + scan.mount_yaw_rad + scan.first_beam_rad +
                     static_cast<double>(k) * scan.beam_step_rad;
    const double hx = sx + range[k] * std::cos(a), hy = sy + range[k] * std::sin(a);
    hits += Num(hx) + "," + Num(hy) + "\n";
    if (k % 4 == 0) rays += Num(sx) + "," + Num(sy) + "\n" + Num(hx) + "," + Num(hy) + "\n\n";
    view.Add(hx, hy);
  }
  SolidLayer obstacles, carried;
  for (const models::Obstacle& o : spec.scene.obstacles) AppendSolid(obstacles, o.solid, 0, 0);
  for (const models::CarriedObject& o : spec.scene.carried) {
    const auto b = static_cast<std::size_t>(o.belt);
    if (b >= spec.scene.belts.size()) continue;
    const double d = b < travel.size() ? travel[b] : 0.0;
    const auto range_on = models::CarriedTravelRange(spec.scene.belts[b].area, o.solid);
    if (d < range_on[0] || d > range_on[1]) continue;  // lifted off the line
    const double heading = spec.scene.belts[b].area.direction_rad;
    AppendSolid(carried, o.solid, d * std::cos(heading), d * std::sin(heading));
  }
  std::string belts, outline;
  for (const models::Belt& b : spec.scene.belts) AppendPolygon(belts, BeltCorners(b));
  AppendPolygon(outline, Rectangle(*x, *y, *yaw, spec.body_length_m, spec.body_width_m));

  std::string s = "\n# One scan of " + scan.sensor + " (scan.png).\n";
  AppendBlock(s, "scan_rays", rays.empty() ? "\n" : rays);
  AppendBlock(s, "scan_hits", hits.empty() ? "nan,nan\n" : hits);
  AppendBlock(s, "scan_outline", outline);
  if (!belts.empty()) AppendBlock(s, "scan_belts", belts);
  if (!obstacles.polygons.empty()) AppendBlock(s, "scan_obstacles", obstacles.polygons);
  if (!obstacles.circles.empty()) AppendBlock(s, "scan_obstacles_circles", obstacles.circles);
  if (!carried.polygons.empty()) AppendBlock(s, "scan_carried", carried.polygons);
  s += SetOutput(spec.file_prefix + "scan", spec.format, outputs) + "set title " +
       GnuplotQuote(title_prefix + scan.sensor + ", the scan started at t = " + Num(start_s) +
                    " s (" + std::to_string(range.size()) + " beams, every 4th ray drawn)") +
       "\nset xlabel 'x (m)'\nset ylabel 'y (m)'\nset size ratio -1\nset key outside bottom "
       "center horizontal\n";
  if (!view.empty()) {
    const double m = 1.0;
    s += "set xrange [" + Num(view.x_min - m) + ":" + Num(view.x_max + m) + "]\nset yrange [" +
         Num(view.y_min - m) + ":" + Num(view.y_max + m) + "]\n";
  }
  std::vector<std::string> items;
  if (!belts.empty()) {
    items.push_back(
        "$scan_belts using 1:2 with filledcurves closed fillcolor rgb '#dbe6f4' "
        "fillstyle solid 1.0 border lc rgb '#8fa9cc' title 'belt'");
  }
  if (!obstacles.polygons.empty()) {
    items.push_back(
        "$scan_obstacles using 1:2 with filledcurves closed fillcolor rgb '#d0d0d0' "
        "fillstyle solid 1.0 border lc rgb '#606060' title 'obstacle'");
  }
  if (!obstacles.circles.empty()) {
    items.push_back(
        "$scan_obstacles_circles using 1:2:3 with circles fillcolor rgb '#d0d0d0' "
        "fillstyle solid 1.0 border lc rgb '#606060' notitle");
  }
  if (!carried.polygons.empty()) {
    items.push_back(
        "$scan_carried using 1:2 with filledcurves closed fillcolor rgb '#f6d3a8' "
        "fillstyle solid 0.6 border lc rgb '#c07020' title 'carried (then)'");
  }
  items.push_back("$scan_rays using 1:2 with lines lw 0.5 lc rgb '#9ecae1' title 'rays'");
  items.push_back("$scan_hits using 1:2 with points pt 7 ps 0.35 lc rgb '#d62728' title 'hits'");
  items.push_back("$scan_outline using 1:2 with lines lw 2 lc rgb '#1f77b4' title 'robot'");
  s += "plot ";
  for (std::size_t i = 0; i < items.size(); ++i) s += (i ? ", \\\n     " : "") + items[i];
  s += "\nset size noratio\nset autoscale\nset key default\n";
  return s;
}

// Height of the ground at map point (x, y): the highest terrain top face
// over it, else the floor (0).
double GroundAt(const models::Scene& scene, double x, double y) {
  double z = 0.0;
  for (const models::TerrainPiece& t : scene.terrain) {
    if (const auto top = models::TerrainTopAt(t, x, y)) z = std::max(z, *top);
  }
  return z;
}

// side_view.png: base_link's height and the ground under it against the
// distance travelled in the plane.
std::string SideView(const RobotPlotSpec& spec, Signals& signals,
                     const std::vector<std::streamoff>& row_starts, int ix, int iy, int iz,
                     const std::string& title_prefix, std::vector<std::string>* outputs) {
  std::string data;
  std::vector<std::string_view> fields;
  std::string line;
  double travelled_m = 0.0;
  std::optional<Point> last;
  for (std::size_t row = 0; row < row_starts.size(); ++row) {
    ReadRow(signals, row_starts, row, line, fields);
    const auto x = Column(fields, ix), y = Column(fields, iy), z = Column(fields, iz);
    if (!x || !y || !z) continue;
    if (last) travelled_m += std::hypot(*x - last->x, *y - last->y);
    last = Point{*x, *y};
    data += Num(travelled_m) + "," + Num(*z) + "," + Num(GroundAt(spec.scene, *x, *y)) + "\n";
  }
  if (data.empty()) return {};
  std::string s;
  AppendBlock(s, "side", data);
  return s + SetOutput(spec.file_prefix + "side_view", spec.format, outputs) + "set title " +
         GnuplotQuote(title_prefix + "side view: height along the track") +
         "\nset xlabel 'distance travelled in the plane (m)'\nset ylabel 'height (m)'\n"
         "unset y2label\nunset y2tics\nset ytics mirror\n"
         "set autoscale\nset offsets 0, 0, graph 0.1, graph 0.05\nset key top left\n"
         "plot $side using 1:3 with filledcurves y1=0 lc rgb '#c8c8c8' title "
         "'ground under the track (floor, ramp, van floor)', \\\n"
         "     $side using 1:2 with lines lw 2 lc rgb '#d62728' title " +
         GnuplotQuote("robot base_link height (" + spec.z_column + ")") + "\n";
}

std::string Script(const RobotPlotSpec& spec, Signals& signals, std::vector<std::string>* outputs) {
  if (spec.x_column.empty() || spec.y_column.empty()) {
    throw std::runtime_error("robot plots need the x and y columns of the robot position");
  }
  ColumnFinder column(signals.header, signals.file);
  const int ix = column(spec.x_column, "robot x");
  const int iy = column(spec.y_column, "robot y");
  const int iyaw = spec.yaw_column.empty() ? 0 : column(spec.yaw_column, "robot yaw");
  std::vector<std::pair<int, int>> wheels;
  for (const auto& [wx, wy] : spec.wheel_columns) {
    wheels.emplace_back(column(wx, "wheel x"), column(wy, "wheel y"));
  }
  const int ierr = spec.error_column.empty() ? 0 : column(spec.error_column, "error");
  const int iz = spec.z_column.empty() ? 0 : column(spec.z_column, "robot height");
  std::vector<int> speeds, ons;
  for (const auto& name : spec.belt_speed_columns) speeds.push_back(column(name, "belt speed"));
  for (const auto& name : spec.belt_on_columns) ons.push_back(column(name, "belt on"));
  std::vector<int> travels;
  for (const auto& name : spec.belt_travel_columns) travels.push_back(column(name, "belt travel"));
  std::vector<int> flows;
  for (const auto& name : spec.flow_columns) flows.push_back(column(name, "optic flow"));
  std::vector<int> flow_truths;
  for (const auto& name : spec.flow_truth_columns) {
    flow_truths.push_back(column(name, "optic flow truth"));
  }
  std::vector<int> filtered;
  for (const auto& name : spec.flow_filtered_columns) {
    filtered.push_back(column(name, "filtered optic flow"));
  }
  const int iref = spec.flow_reference_column.empty()
                       ? 0
                       : column(spec.flow_reference_column, "ground-truth surface speed");
  std::vector<std::pair<int, int>> workers;
  for (const auto& [wx, wy] : spec.worker_columns) {
    workers.emplace_back(column(wx, "worker x"), column(wy, "worker y"));
  }
  struct OtherColumns {
    int x, y, yaw;
  };
  std::vector<OtherColumns> others;
  for (const auto& o : spec.others) {
    others.push_back({column(o.x_column, "other robot x"), column(o.y_column, "other robot y"),
                      column(o.yaw_column, "other robot yaw")});
  }
  const RobotPlotSpec::Safety& safety = spec.safety;
  const bool has_safety = !safety.cap_column.empty();
  const int ivx = has_safety ? column(safety.velocity_x_column, "robot vx") : 0;
  const int ivy = has_safety ? column(safety.velocity_y_column, "robot vy") : 0;
  const int icap = has_safety ? column(safety.cap_column, "speed cap") : 0;
  const int iprot = has_safety ? column(safety.protective_column, "protective field") : 0;
  const int iwarn = has_safety ? column(safety.warning_column, "warning field") : 0;
  const int idist = has_safety && !safety.distance_column.empty()
                        ? column(safety.distance_column, "person distance")
                        : 0;
  column.ThrowIfUnknown();
  DataColumns data;
  for (const int c : {ix, iy, ierr, iref, ivx, ivy, icap, iprot, iwarn, idist}) data.Use(c);
  for (const auto* list : {&speeds, &ons, &flows, &flow_truths, &filtered}) {
    for (const int c : *list) data.Use(c);
  }
  if (!travels.empty() && travels.size() != spec.scene.belts.size()) {
    throw std::runtime_error("robot plots: " + std::to_string(travels.size()) +
                             " belt travel columns for " + std::to_string(spec.scene.belts.size()) +
                             " belts of the scene: expected one per belt");
  }

  std::string s =
      "# Written by linesim (plots/robot_plots.cc). Run `gnuplot plots.gp` in this folder\n"
      "# to redraw; the data are in its blocks, copied from signals.csv ($signals: the\n"
      "# columns the time plots draw, time first).\n" +
      GnuplotTerminal(spec.format, kCanvasWidthPx, kCanvasHeightPx) +
      "set datafile separator comma\n"
      "set grid\n";

  // Belt rectangles, and arrows about every metre along each centre line showing
  // the direction of motion (only those in view are drawn).
  std::string belts, arrows;
  for (const models::Belt& belt : spec.scene.belts) {
    const models::Rect& b = belt.area;
    AppendPolygon(belts, BeltCorners(belt));
    const double c = std::cos(b.direction_rad), sn = std::sin(b.direction_rad);
    const int n = std::clamp(static_cast<int>(b.length_m), 1, 200);
    for (int k = 0; k < n; ++k) {
      const double along_m = (k + 0.5) * b.length_m / n - 0.5 * b.length_m - 0.15;
      arrows += Num(b.center_x_m + c * along_m) + "," + Num(b.center_y_m + sn * along_m) + "," +
                Num(0.3 * c) + "," + Num(0.3 * sn) + "\n";
    }
  }
  std::string path;
  for (const auto& p : spec.path_m) path += Num(p[0]) + "," + Num(p[1]) + "\n";

  // Outlines (with a heading tick from the centre to the front), wheel
  // contact points and time labels at the chosen instants.
  std::string outlines, contacts, labels, other_outlines;
  Bounds view;
  for (const auto& p : spec.path_m) view.Add(p[0], p[1]);
  // One pass over the rows: the track's extent, and where each row starts
  // (to come back to the few rows the outlines are drawn at).
  std::vector<std::streamoff> row_starts;
  // Each belt's travel at the last row that gives one.
  std::vector<std::optional<double>> travel(travels.size());
  // The other robots' and the workers' tracks, drawn from data blocks
  // (thinned below) rather than by gnuplot reading signals.csv once more
  // for each: in a fleet of N, N - 1 more passes over a row of some 60 N
  // columns, for each of the N robots' top views.
  std::vector<std::vector<Point>> other_tracks(others.size()), worker_tracks(workers.size());
  std::string data_block;
  {
    std::vector<std::string_view> fields;
    std::string line;
    int last_column = std::max(ix, iy);
    for (int col : travels) last_column = std::max(last_column, col);
    for (const auto& o : others) last_column = std::max({last_column, o.x, o.y});
    for (const auto& [wx, wy] : workers) last_column = std::max({last_column, wx, wy});
    const auto needed = std::max(static_cast<std::size_t>(last_column), data.last_csv());
    while (true) {
      const std::streamoff start = signals.in.tellg();
      if (!std::getline(signals.in, line)) break;
      if (line.empty() || line == "\r") continue;
      row_starts.push_back(start);
      SplitCsv(line, fields, needed);
      data.AppendRow(fields, data_block);
      const auto x = Column(fields, ix), y = Column(fields, iy);
      if (x && y) view.Add(*x, *y);
      for (std::size_t k = 0; k < others.size(); ++k) {
        const auto ox = Column(fields, others[k].x), oy = Column(fields, others[k].y);
        if (!ox || !oy) continue;
        view.Add(*ox, *oy);
        other_tracks[k].push_back({*ox, *oy});
      }
      for (std::size_t k = 0; k < workers.size(); ++k) {
        const auto wx = Column(fields, workers[k].first), wy = Column(fields, workers[k].second);
        if (wx && wy) worker_tracks[k].push_back({*wx, *wy});
      }
      for (std::size_t b = 0; b < travels.size(); ++b) {
        if (const auto d = Column(fields, travels[b])) travel[b] = d;
      }
    }
  }
  if (row_starts.empty()) throw std::runtime_error(signals.file.string() + " has no data rows");
  // At most about 1,000 points a track (the last one kept): at the usual
  // 100 Hz recording a 10 s stretch stays whole, and a robot at 1 m/s
  // moves 1 cm between points; tracks separated by a blank line.
  const auto tracks_block = [](const std::vector<std::vector<Point>>& tracks) {
    std::string block;
    for (const auto& track : tracks) {
      if (track.empty()) continue;
      const std::size_t step = (track.size() + 999) / 1000;
      for (std::size_t i = 0; i < track.size(); i += step) {
        block += Num(track[i].x) + "," + Num(track[i].y) + "\n";
      }
      if ((track.size() - 1) % step != 0) {
        block += Num(track.back().x) + "," + Num(track.back().y) + "\n";
      }
      block += "\n";
    }
    return block;
  };
  const std::string other_track_block = tracks_block(other_tracks);
  const std::string worker_track_block = tracks_block(worker_tracks);
  if (iyaw > 0) {
    // A robot standing still would get its labels printed over each other:
    // an instant closer than a quarter body length to the last label joins
    // it ("t = 0 / 6 / 12 s"; commas would split the data line).
    struct Label {
      Point at;
      std::string times;
    };
    std::vector<Label> placed;
    std::vector<std::string_view> fields;
    std::string line;
    for (std::size_t row : EvenlySpaced(row_starts.size(), spec.footprint_count)) {
      ReadRow(signals, row_starts, row, line, fields);
      const auto get = [&](int col) { return Column(fields, col); };
      const auto t = get(1), x = get(ix), y = get(iy), yaw = get(iyaw);
      if (!x || !y || !yaw || !std::isfinite(*x + *y + *yaw)) continue;
      const auto corners = Rectangle(*x, *y, *yaw, spec.body_length_m, spec.body_width_m);
      for (const Point& c : corners) view.Add(c.x, c.y);
      AppendPolygon(outlines, corners);
      outlines += Num(*x) + "," + Num(*y) + "\n" +
                  Num(*x + 0.5 * spec.body_length_m * std::cos(*yaw)) + "," +
                  Num(*y + 0.5 * spec.body_length_m * std::sin(*yaw)) + "\n\n";
      if (t) {
        const bool crowded =
            !placed.empty() && std::hypot(*x - placed.back().at.x, *y - placed.back().at.y) <
                                   0.25 * spec.body_length_m;
        if (crowded) {
          placed.back().times += " / " + Num(*t);
        } else {
          placed.push_back({{*x, *y}, Num(*t)});
        }
      }
      for (std::size_t k = 0; k < others.size(); ++k) {
        const auto ox = get(others[k].x), oy = get(others[k].y), oyaw = get(others[k].yaw);
        if (!ox || !oy || !oyaw || !std::isfinite(*ox + *oy + *oyaw)) continue;
        const auto& o = spec.others[k];
        const auto c = Rectangle(*ox, *oy, *oyaw, o.body_length_m, o.body_width_m);
        for (const Point& p : c) view.Add(p.x, p.y);
        AppendPolygon(other_outlines, c);
        other_outlines += Num(*ox) + "," + Num(*oy) + "\n" +
                          Num(*ox + 0.5 * o.body_length_m * std::cos(*oyaw)) + "," +
                          Num(*oy + 0.5 * o.body_length_m * std::sin(*oyaw)) + "\n\n";
      }
      for (const auto& [wx, wy] : wheels) {
        const auto px = get(wx), py = get(wy);
        if (px && py) {
          contacts += Num(*px) + "," + Num(*py) + "\n";
          view.Add(*px, *py);
        }
      }
    }
    // Above the outline whatever the heading (half the body's diagonal),
    // so that the label's box hides no wheel contact.
    const double above_m = 0.5 * std::hypot(spec.body_length_m, spec.body_width_m);
    for (const auto& [at, times] : placed) {
      labels += Num(at.x) + "," + Num(at.y + above_m) + ",t = " + times + " s\n";
    }
  }
  // The scene's solids: obstacles, and carried objects at time zero and
  // (with travel columns) at the end, moved along their belt.
  SolidLayer obstacles, carried, carried_end;
  std::vector<std::array<Point, 4>> footprints;  // for framing
  for (const models::Obstacle& o : spec.scene.obstacles) {
    AppendSolid(obstacles, o.solid, 0.0, 0.0);
    footprints.push_back(Footprint(o.solid, 0.0, 0.0));
  }
  for (const models::CarriedObject& c : spec.scene.carried) {
    AppendSolid(carried, c.solid, 0.0, 0.0);
    footprints.push_back(Footprint(c.solid, 0.0, 0.0));
    const auto b = static_cast<std::size_t>(c.belt);
    // An object past its belt's end has been lifted off the line (as the
    // chassis simulates it): nothing is drawn at the end.
    const auto on_belt = [&](double d) {
      const auto range = models::CarriedTravelRange(spec.scene.belts[b].area, c.solid);
      return range[0] <= d && d <= range[1];
    };
    if (b < travel.size() && travel[b] && b < spec.scene.belts.size() && on_belt(*travel[b])) {
      const double heading = spec.scene.belts[b].area.direction_rad;
      const double dx = *travel[b] * std::cos(heading), dy = *travel[b] * std::sin(heading);
      AppendSolid(carried_end, c.solid, dx, dy);
      footprints.push_back(Footprint(c.solid, dx, dy));
    }
  }
  for (const models::Belt& b : spec.scene.belts) footprints.push_back(BeltCorners(b));

  // Frame: the robot's neighbourhood and the parts of the scene within
  // near_m of it (a wall along the path shows, not the whole hall); or,
  // when asked, the whole scene.
  if (spec.whole_scene) {
    const models::Floor& f = spec.scene.floor;
    // A floor as large as models::OpenFloor()'s is unbounded: not framed.
    if (std::max({std::abs(f.min_x_m), std::abs(f.max_x_m), std::abs(f.min_y_m),
                  std::abs(f.max_y_m)}) < 1e5) {
      view.Add(f.min_x_m, f.min_y_m);
      view.Add(f.max_x_m, f.max_y_m);
    }
    for (const auto& corners : footprints) {
      for (const Point& c : corners) view.Add(c.x, c.y);
    }
  } else if (!view.empty()) {
    const Bounds near{view.x_min - spec.near_m, view.x_max + spec.near_m, view.y_min - spec.near_m,
                      view.y_max + spec.near_m};
    for (const auto& corners : footprints) {
      Bounds box;
      for (const Point& c : corners) box.Add(c.x, c.y);
      const double x0 = std::max(box.x_min, near.x_min), x1 = std::min(box.x_max, near.x_max);
      const double y0 = std::max(box.y_min, near.y_min), y1 = std::min(box.y_max, near.y_max);
      if (x0 > x1 || y0 > y1) continue;
      view.Add(x0, y0);
      view.Add(x1, y1);
    }
  }

  if (!belts.empty()) AppendBlock(s, "belts", belts);
  if (!obstacles.polygons.empty()) AppendBlock(s, "obstacles", obstacles.polygons);
  if (!obstacles.circles.empty()) AppendBlock(s, "obstacles_circles", obstacles.circles);
  if (!carried.polygons.empty()) AppendBlock(s, "carried", carried.polygons);
  if (!carried.circles.empty()) AppendBlock(s, "carried_circles", carried.circles);
  if (!carried_end.polygons.empty()) AppendBlock(s, "carried_end", carried_end.polygons);
  if (!carried_end.circles.empty()) AppendBlock(s, "carried_end_circles", carried_end.circles);
  if (!arrows.empty()) AppendBlock(s, "belt_direction", arrows);
  if (!path.empty()) AppendBlock(s, "path", path);
  if (!outlines.empty()) AppendBlock(s, "outlines", outlines);
  if (!other_outlines.empty()) AppendBlock(s, "other_outlines", other_outlines);
  if (!other_track_block.empty()) AppendBlock(s, "other_tracks", other_track_block);
  if (!worker_track_block.empty()) AppendBlock(s, "worker_tracks", worker_track_block);
  if (!contacts.empty()) AppendBlock(s, "contacts", contacts);
  if (!labels.empty()) AppendBlock(s, "labels", labels);
  AppendBlock(s, "signals", data_block);
  data_block = std::string();  // the script holds it now

  const std::string title_prefix = spec.title.empty() ? "" : spec.title + ": ";
  // A curve's data: `using 1:` + expression, columns by their CSV number
  // through data[].
  const std::string signals_data = "$signals";

  // Top view of the robot's neighbourhood (path, track, outlines), not of
  // the whole line: belts are clipped to it.
  s += "\n" + SetOutput(spec.file_prefix + "top_view", spec.format, outputs) + "set title " +
       GnuplotQuote(title_prefix + "top view (map frame)") +
       "\n"
       "set xlabel 'x (m)'\nset ylabel 'y (m)'\n"
       "set lmargin at screen " +
       Num(kLeft) + "\nset rmargin at screen " + Num(kRight) + "\nset bmargin at screen " +
       Num(kBottom) + "\nset tmargin at screen " + Num(kTop) +
       "\nset key at screen 0.5, 0.04 center bottom horizontal maxrows 2\n"
       "set style textbox opaque noborder\n"
       "set size ratio -1\n";
  if (!view.empty()) {
    const double area_aspect =
        (kRight - kLeft) * kCanvasWidthPx / ((kTop - kBottom) * kCanvasHeightPx);
    const double margin_m = 0.3 + 0.05 * std::max(view.x_max - view.x_min, view.y_max - view.y_min);
    double half_x = 0.5 * (view.x_max - view.x_min) + margin_m;
    double half_y = 0.5 * (view.y_max - view.y_min) + margin_m;
    half_x = std::max(half_x, half_y * area_aspect);
    half_y = std::max(half_y, half_x / area_aspect);
    const double cx = 0.5 * (view.x_min + view.x_max), cy = 0.5 * (view.y_min + view.y_max);
    s += "set xrange [" + Num(cx - half_x) + ":" + Num(cx + half_x) + "]\nset yrange [" +
         Num(cy - half_y) + ":" + Num(cy + half_y) + "]\n";
  }
  s += "plot ";
  std::vector<std::string> items;
  if (!belts.empty()) {
    items.push_back(
        "$belts using 1:2 with filledcurves closed fillcolor rgb '#dbe6f4' fillstyle solid 1.0 "
        "border lc rgb '#8fa9cc' noautoscale title 'belt'");
  }
  if (!arrows.empty()) {
    items.push_back(
        "$belt_direction using 1:2:3:4 with vectors lc rgb '#8fa9cc' noautoscale "
        "title 'belt motion'");
  }
  // One legend entry per kind of thing, whether boxes or circles draw it.
  const auto solids = [&](const SolidLayer& layer, const std::string& name,
                          const std::string& style, const std::string& title) {
    if (!layer.polygons.empty()) {
      items.push_back("$" + name + " using 1:2 with filledcurves closed " + style +
                      " noautoscale title " + GnuplotQuote(title));
    }
    if (!layer.circles.empty()) {
      items.push_back("$" + name + "_circles using 1:2:3 with circles " + style + " noautoscale " +
                      (layer.polygons.empty() ? "title " + GnuplotQuote(title) : "notitle"));
    }
  };
  solids(obstacles, "obstacles",
         "fillcolor rgb '#b8b8b8' fillstyle solid 1.0 border lc rgb '#606060'", "obstacle");
  solids(carried, "carried", "fillcolor rgb '#f6d3a8' fillstyle solid 1.0 border lc rgb '#c07020'",
         "carried object (t = 0)");
  if (!carried_end.polygons.empty()) {
    items.push_back(
        "$carried_end using 1:2 with lines dt 2 lw 1.5 lc rgb '#c07020' noautoscale "
        "title 'carried object (end)'");
  }
  if (!carried_end.circles.empty()) {
    items.push_back(
        "$carried_end_circles using 1:2:3 with circles fillstyle empty border lc rgb '#c07020' "
        "noautoscale " +
        std::string(carried_end.polygons.empty() ? "title 'carried object (end)'" : "notitle"));
  }
  if (spec.path_m.size() == 1) {
    items.push_back(
        "$path using 1:2 with points pt 3 ps 3 lw 2 lc rgb 'black' title 'hold target'");
  } else if (!path.empty()) {
    items.push_back("$path using 1:2 with lines dt 2 lw 1.5 lc rgb 'black' title 'desired path'");
  }
  items.push_back(signals_data + " using " + std::to_string(data[ix]) + ":" +
                  std::to_string(data[iy]) +
                  " with lines lw 2 lc rgb '#d62728' title 'actual path'");
  if (!outlines.empty()) {
    items.push_back(
        "$outlines using 1:2 with lines lw 1 lc rgb '#1f77b4' title " +
        GnuplotQuote(spec.others.empty() ? "robot outline" : spec.robot_name + " outline"));
  }
  if (!other_track_block.empty()) {
    items.push_back(
        "$other_tracks using 1:2 with lines lw 2 lc rgb '#17becf' title 'other robots (path, "
        "outline)'");
  }
  if (!other_outlines.empty()) {
    items.push_back("$other_outlines using 1:2 with lines lw 1 lc rgb '#17becf' notitle");
  }
  if (!worker_track_block.empty()) {
    items.push_back("$worker_tracks using 1:2 with lines lw 2 lc rgb '#9467bd' title 'worker'");
  }
  if (!contacts.empty()) {
    items.push_back(
        "$contacts using 1:2 with points pt 7 ps 0.8 lc rgb '#2ca02c' title 'wheel contacts'");
  }
  if (!labels.empty()) {
    items.push_back("$labels using 1:2:3 with labels boxed offset 0,0.6 font ',8' notitle");
  }
  for (std::size_t i = 0; i < items.size(); ++i) s += (i ? ", \\\n     " : "") + items[i];
  s += "\n\n# Back to defaults for the time plots.\n"
       "set size noratio\nset autoscale\nset key default\n"
       "set lmargin -1\nset rmargin -1\nset bmargin -1\nset tmargin -1\n";

  // The time plots: legends in a band of the canvas below the axes (never
  // over a curve: "set key below" would share its row with the x label),
  // time from the first row to the last.
  const std::string time_plot =
      "set xlabel 'time (s)'\nunset y2label\nunset y2tics\nset ytics mirror\n"
      "set autoscale\nset offsets 0, 0, 0, 0\n" +
      std::string(kTimeKey);
  // Where any belt is scheduled on, as a column expression (1 on, 0 off).
  std::string any_on;
  for (std::size_t i = 0; i < ons.size(); ++i) {
    any_on += (i ? " || " : "") + std::string("column(") + std::to_string(data[ons[i]]) + ") > 0.5";
  }
  // The line's on state as grey bands behind the data (paper 1 Figs. 5-7
  // mark the line's state): filled from 0 to 1 on the second y axis.
  const auto on_shading = [&]() -> std::string {
    if (any_on.empty()) return {};
    return signals_data + " using 1:((" + any_on +
           ") ? 1 : 0) axes x1y2 with filledcurves y=0 fillcolor rgb '#e4e4e4' "
           "fillstyle solid 1.0 noborder title 'line on'";
  };
  // The grid in front: the bands would hide it.
  const std::string shading_axes =
      any_on.empty() ? "" : "set y2range [0:1]\nunset y2tics\nset grid front\n";

  if (ierr > 0) {
    s += "\n" + SetOutput(spec.file_prefix + "error", spec.format, outputs) + "set title " +
         GnuplotQuote(title_prefix + spec.error_label) + "\n" + time_plot + shading_axes +
         "set ylabel " + GnuplotQuote(spec.error_label) + "\nset yrange [0:*]\n";
    items.clear();
    if (const std::string shading = on_shading(); !shading.empty()) items.push_back(shading);
    items.push_back(signals_data + " using 1:" + std::to_string(data[ierr]) +
                    " with lines lw 2 lc rgb '#1f77b4' title " +
                    GnuplotQuote(spec.error_name.empty() ? spec.error_label : spec.error_name));
    if (spec.error_bound_m > 0.0) {
      // The bound as a line across the whole time axis; the y range takes
      // it in, so a run far below it still shows where it is.
      s += "set yrange [0:*] noextend\nset offsets 0, 0, graph 0.05, 0\n";
      items.push_back(Num(spec.error_bound_m) + " with lines dt 2 lw 2 lc rgb '#d62728' title " +
                      GnuplotQuote(spec.error_bound_label.empty()
                                       ? "bound " + Num(spec.error_bound_m) + " m"
                                       : spec.error_bound_label));
    }
    s += "plot ";
    for (std::size_t i = 0; i < items.size(); ++i) s += (i ? ", \\\n     " : "") + items[i];
    s += "\nset yrange [*:*]\nset y2range [*:*]\nset grid back\nset bmargin -1\n";
  }

  if (!speeds.empty() || !ons.empty()) {
    s += "\n" + SetOutput(spec.file_prefix + "belt", spec.format, outputs) + "set title " +
         GnuplotQuote(title_prefix + "belts") + "\n" + time_plot +
         "set ylabel 'belt speed (m/s)'\n"
         "set y2label 'scheduled on (1) / off (0)'\n"
         "set yrange [0:*]\nset offsets 0, 0, graph 0.08, 0\n"
         "set y2range [-0.05:1.05]\nset y2tics 0, 1, 1\nset ytics nomirror\nplot ";
    items.clear();
    for (std::size_t i = 0; i < speeds.size(); ++i) {
      items.push_back(signals_data + " using 1:" + std::to_string(data[speeds[i]]) +
                      " with lines lw 2 title " +
                      GnuplotQuote("speed of belt " + std::to_string(i)));
    }
    for (std::size_t i = 0; i < ons.size(); ++i) {
      items.push_back(signals_data + " using 1:" + std::to_string(data[ons[i]]) +
                      " axes x1y2 with steps dt 2 lw 1.5 title " +
                      GnuplotQuote("belt " + std::to_string(i) + " scheduled on"));
    }
    for (std::size_t i = 0; i < items.size(); ++i) s += (i ? ", \\\n     " : "") + items[i];
    s += "\nset yrange [*:*]\nset y2range [*:*]\nset bmargin -1\n";
  }
  if (!flows.empty() && iref > 0) {
    // Each PX4Flow is drawn as what it measures: the surface relative to
    // it (pale), against the same from ground truth (dashed); the filter's
    // estimate is a surface speed (Eq. 2 with the robot's own motion),
    // drawn against the belt's encoder wheel (black).
    // Two title lines: gnuplot joins single-quoted text and a "\n".
    s += "\n" + SetOutput(spec.file_prefix + "optic_flow", spec.format, outputs) + "set title " +
         GnuplotQuote(title_prefix +
                      (filtered.empty() ? "optic flow" : "raw and filtered optic flow") +
                      " against the belt's ground truth (paper 1, Fig. 4)") +
         " . \"\\n\" . " +
         GnuplotQuote(filtered.empty()
                          ? "raw: what each PX4Flow reads (the surface relative to it), dashed: "
                            "the same from ground truth"
                          : "raw: what each PX4Flow reads (the surface relative to it), dashed: "
                            "the same from ground truth; filtered: the surface speed (Eq. 2)") +
         "\n" + time_plot + shading_axes +
         "set ylabel 'speed along the belt (m/s)'\n"
         "set offsets 0, 0, graph 0.05, graph 0.05\nset key maxcols 3\nplot ";
    items.clear();
    if (const std::string shading = on_shading(); !shading.empty()) items.push_back(shading);
    // Raw thin and pale (visibly noisy), filtered bold in the same hue,
    // ground truth black on top.
    static const char* kColours[] = {"#9ecae1", "#fdbf6f", "#a1d99b", "#cbc9e2"};
    for (std::size_t i = 0; i < flows.size(); ++i) {
      const std::string label = i < spec.flow_labels.size() ? spec.flow_labels[i] : "sensor";
      items.push_back(signals_data + " using 1:" + std::to_string(data[flows[i]]) +
                      " with lines lw 1 lc rgb '" + kColours[i % 4] + "' title " +
                      GnuplotQuote("raw, " + label));
    }
    static const char* kMid[] = {"#3182bd", "#e6550d", "#31a354", "#756bb1"};
    for (std::size_t i = 0; i < flow_truths.size(); ++i) {
      const std::string label = i < spec.flow_labels.size() ? spec.flow_labels[i] : "sensor";
      items.push_back(signals_data + " using 1:" + std::to_string(data[flow_truths[i]]) +
                      " with lines lw 1 dt 2 lc rgb '" + kMid[i % 4] + "' title " +
                      GnuplotQuote("true reading, " + label));
    }
    // Paper 1 Fig. 4: the steady-state Kalman filter's output beside the raw.
    static const char* kDark[] = {"#08519c", "#d95f02", "#238b45", "#6a51a3"};
    for (std::size_t i = 0; i < filtered.size(); ++i) {
      const std::string label = i < spec.flow_labels.size() ? spec.flow_labels[i] : "sensor";
      items.push_back(signals_data + " using 1:" + std::to_string(data[filtered[i]]) +
                      " with lines lw 2 lc rgb '" + kDark[i % 4] + "' title " +
                      GnuplotQuote("filtered, " + label));
    }
    items.push_back(signals_data + " using 1:" + std::to_string(data[iref]) +
                    " with lines lw 2.5 lc rgb 'black' title 'ground truth (encoder wheel)'");
    for (std::size_t i = 0; i < items.size(); ++i) s += (i ? ", \\\n     " : "") + items[i];
    s += "\nset y2range [*:*]\nset grid back\nset bmargin -1\n";
  }
  if (!spec.scan.range_columns.empty()) {
    s += ScanPlot(spec, signals, row_starts, ix, iy, iyaw, travels, title_prefix, outputs);
  }
  if (iz > 0) s += SideView(spec, signals, row_starts, ix, iy, iz, title_prefix, outputs);
  if (has_safety) {
    // Speeds and the distance on the left axis; the fields' states as steps
    // on the right (1 clear, 0 infringed), offset so that both show.
    s += "\n" + SetOutput(spec.file_prefix + "safety", spec.format, outputs) + "set title " +
         GnuplotQuote(title_prefix +
                      "S300 safety fields: speed, speed cap, distance to the person") +
         "\n" + time_plot +
         "set ylabel 'speed (m/s), distance (m)'\nset yrange [0:*]\n"
         "set y2label 'field clear (1) / infringed (0)'\nset y2range [-0.1:1.3]\n"
         "set y2tics 0, 1, 1\nset ytics nomirror\nset offsets 0, 0, graph 0.05, 0\nplot ";
    items.clear();
    items.push_back(signals_data + " using 1:(sqrt(column(" + std::to_string(data[ivx]) +
                    ")**2 + column(" + std::to_string(data[ivy]) +
                    ")**2)) with lines lw 2 lc rgb '#1f77b4' title 'robot speed'");
    items.push_back(signals_data + " using 1:(column(" + std::to_string(data[icap]) +
                    ") < 0 ? NaN : column(" + std::to_string(data[icap]) +
                    ")) with lines dt 2 lw 2 lc rgb '#ff7f0e' title 'speed cap'");
    if (idist > 0) {
      items.push_back(signals_data + " using 1:(column(" + std::to_string(data[idist]) +
                      ") > 1.5 ? NaN : column(" + std::to_string(data[idist]) +
                      ")) with lines lw 1.5 lc rgb '#9467bd' "
                      "title 'distance to the person (below 1.5 m)'");
    }
    items.push_back(signals_data + " using 1:" + std::to_string(data[iprot]) +
                    " axes x1y2 with steps lw 2 lc rgb '#d62728' title 'protective field clear'");
    items.push_back(signals_data + " using 1:(column(" + std::to_string(data[iwarn]) +
                    ") * 1.1) axes x1y2 with steps lw 1.5 dt 3 lc rgb '#2ca02c' "
                    "title 'warning field clear (x 1.1)'");
    for (std::size_t i = 0; i < items.size(); ++i) s += (i ? ", \\\n     " : "") + items[i];
    s += "\nset yrange [*:*]\nset y2range [*:*]\nset bmargin -1\n";
  }
  s += "unset output\n";
  return s;
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
  const fs::path csv = folder / kSignals;
  Signals signals = OpenSignals(csv);
  std::vector<std::string> names;
  const std::string script = Script(spec, signals, &names);
  return DrawWithGnuplot(dir, spec.file_prefix + kScript, script, names);
}

}  // namespace linesim::plots
