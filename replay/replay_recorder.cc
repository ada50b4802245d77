#include "replay/replay_recorder.h"

#include <charconv>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "cosim/files.h"
#include "json_text/json_string.h"
#include "loader/scenario.h"
#include "units/sensors/laser_scanner_unit.h"

namespace linesim::replay {

namespace {

void AppendInt(std::string& out, std::int64_t v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, static_cast<std::size_t>(r.ptr - buf));
}

// Numbers in fixed notation with a set number of decimals, trailing zeros
// dropped: the value scaled by 10^decimals and rounded to an integer
// (llround: exact, the same on every CPU), written as digits; the same
// double gives the same text everywhere, whatever the locale. Not finite:
// null. Beyond 9e15 after scaling (nothing a replay draws): std::to_chars.
void AppendFixed(std::string& out, double v, int decimals) {
  static constexpr double kScale[] = {1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9};
  static constexpr std::int64_t kPower[] = {1,       10,       100,       1000,       10000,
                                            100000,  1000000,  10000000,  100000000,  1000000000};
  if (!std::isfinite(v)) {
    out += "null";
    return;
  }
  const double scaled = v * kScale[decimals];
  if (!(std::abs(scaled) < 9e15)) {
    char buf[400];
    const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, 0);
    out.append(buf, r.ptr);
    return;
  }
  std::int64_t n = std::llround(scaled);
  if (n < 0) {
    out += '-';
    n = -n;
  }
  AppendInt(out, n / kPower[decimals]);
  std::int64_t fraction = n % kPower[decimals];
  if (fraction == 0) return;
  int digits = decimals;
  while (fraction % 10 == 0) {
    fraction /= 10;
    --digits;
  }
  out += '.';
  char buf[16];
  for (int i = digits - 1; i >= 0; --i) {
    buf[i] = static_cast<char>('0' + fraction % 10);
    fraction /= 10;
  }
  out.append(buf, static_cast<std::size_t>(digits));
}

// A JSON string inside the page's <script> element.
void AppendString(std::string& out, const std::string& s) {
  json_text::AppendString(out, s, /*inside_html_script=*/true);
}

void AppendArray(std::string& out, const std::vector<double>& values, int decimals) {
  out += '[';
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i > 0) out += ',';
    AppendFixed(out, values[i], decimals);
  }
  out += ']';
}

// Decimals per quantity: 0.1 mm for positions and travels, 1e-5 rad
// (10 um at a metre) for angles, 1e-5 of the plotted signals' units (m,
// m/s, A), whole seconds to the nanosecond's 1e-6 for times (every sample
// time is a whole number of base steps, at least a microsecond).
constexpr int kMetres = 4;
constexpr int kRadians = 5;
constexpr int kSignal = 5;
constexpr int kSeconds = 6;

// A key and its value: `"key":` then the caller appends the value.
void Key(std::string& out, const char* key) {
  out += '"';
  out += key;
  out += "\":";
}

void Member(std::string& out, const char* key, double v, int decimals) {
  Key(out, key);
  AppendFixed(out, v, decimals);
  out += ',';
}

void AppendSolid(std::string& out, const models::Solid& s) {
  Key(out, "shape");
  out += s.kind == models::Solid::Kind::kBox ? "\"box\"," : "\"cylinder\",";
  Member(out, "x", s.x_m, kMetres);
  Member(out, "y", s.y_m, kMetres);
  Member(out, "yaw", s.yaw_rad, kRadians);
  Member(out, "length", s.length_m, kMetres);
  Member(out, "width", s.width_m, kMetres);
  Key(out, "radius");
  AppendFixed(out, s.radius_m, kMetres);
}

}  // namespace

ReplaySpec ReplaySpecFor(const loader::Scenario& s, double bound_m,
                         const std::string& bound_label) {
  const loader::RobotInfo& r = *s.robot;
  const cosim::System& system = *s.system;
  const auto one = [&](const std::string& column) {
    return cosim::ResolveProbes(system, {column}).front();
  };
  ReplaySpec spec;
  spec.title = s.name;
  spec.task = r.task;
  spec.scene = s.scene;
  spec.path = r.path;
  spec.body_length_m = r.body_length_m.value_or(0.0);
  spec.body_width_m = r.body_width_m.value_or(0.0);
  spec.x = one(r.x_column);
  spec.y = one(r.y_column);
  spec.yaw = one(r.yaw_column);
  for (const auto& [wx, wy] : r.wheel_columns) spec.wheels.push_back({one(wx), one(wy)});
  if (!r.wheel_surface_column.empty()) {
    spec.wheel_surface = cosim::ResolveProbes(system, {r.wheel_surface_column});
  }
  for (const auto& c : r.belt_travel_columns) spec.belt_travel.push_back(one(c));
  for (const auto& c : r.belt_on_columns) spec.belt_on.push_back(one(c));

  if (!r.error_column.empty()) {
    ReplaySpec::Plot p;
    p.title = r.task != "hold" ? "deviation from the desired path"
                               : "drift from the held position";
    p.unit = "m";
    p.bound = bound_m;
    p.bound_label = bound_label;
    p.curves.push_back({r.task != "hold" ? "deviation" : "drift", one(r.error_column)});
    spec.plots.push_back(std::move(p));
  }
  // Surface velocity along the belt: each optic-flow sensor's reading (the
  // surface relative to it) beside its true reading, and the filtered
  // surface speed, against the belt's ground truth (paper 1 Fig. 4); with
  // no flow sensors, the belts' own speed (the truth alone).
  {
    ReplaySpec::Plot p;
    p.title = "surface velocity along the belt";
    p.unit = "m/s";
    for (std::size_t k = 0; k < r.flow_columns.size(); ++k) {
      const std::string name = k < r.flow_sensor_names.size() ? r.flow_sensor_names[k]
                                                              : "sensor " + std::to_string(k);
      p.curves.push_back({name + " reading", one(r.flow_columns[k])});
      if (k < r.flow_truth_columns.size()) {
        p.curves.push_back({name + " true reading", one(r.flow_truth_columns[k])});
      }
      if (k < r.flow_filtered_columns.size()) {
        p.curves.push_back({name + " filtered", one(r.flow_filtered_columns[k])});
      }
    }
    if (!r.flow_reference_column.empty()) {
      p.curves.push_back({"truth (belt encoder)", one(r.flow_reference_column)});
    } else {
      for (std::size_t k = 0; k < r.belt_speed_columns.size(); ++k) {
        p.curves.push_back({"belt " + std::to_string(k) + " truth", one(r.belt_speed_columns[k])});
      }
    }
    if (!p.curves.empty()) spec.plots.push_back(std::move(p));
  }
  if (!r.motor_current_column.empty()) {
    ReplaySpec::Plot p;
    p.title = "motor currents";
    p.unit = "A";
    for (auto& probe : cosim::ResolveProbes(system, {r.motor_current_column})) {
      std::string label = probe.label;
      p.curves.push_back({std::move(label), std::move(probe)});
    }
    spec.plots.push_back(std::move(p));
  }
  // Every laser scanner of the robot, found by its type (in a fleet, of
  // the robot's scope: the others' are drawn from their own poses nowhere).
  const std::string scope = r.name.empty() ? "" : r.name + ".";
  for (std::size_t u = 0; u < system.unit_count(); ++u) {
    if (const auto* laser = dynamic_cast<const sensors::LaserScannerUnit*>(&system.unit(u))) {
      if (laser->name().starts_with(scope)) spec.lasers.push_back({laser->name(), laser});
    }
  }
  for (const loader::RobotInfo& other : r.fleet) {
    ReplaySpec::Mover m;
    m.name = other.name;
    m.robot = true;
    m.x = one(other.x_column);
    m.y = one(other.y_column);
    m.yaw = one(other.yaw_column);
    m.length_m = other.body_length_m.value_or(0.0);
    m.width_m = other.body_width_m.value_or(0.0);
    spec.movers.push_back(std::move(m));
  }
  for (const auto& [wx, wy] : r.worker_columns) {
    ReplaySpec::Mover m;
    m.name = wx.substr(0, wx.find('.'));
    m.x = one(wx);
    m.y = one(wy);
    // Half the shoulder breadth of an adult man (DIN 33402-2: about 0.48 m,
    // as people::WorkerUnit's torso).
    m.radius_m = 0.24;
    spec.movers.push_back(std::move(m));
  }
  return spec;
}

ReplayRecorder::ReplayRecorder(ReplaySpec spec) : spec_(std::move(spec)) {
  wheel_xy_.resize(2 * spec_.wheels.size());
  wheel_surface_.resize(spec_.wheel_surface.size());
  belt_travel_.resize(spec_.belt_travel.size());
  belt_on_.resize(spec_.belt_on.size());
  curves_.resize(spec_.plots.size());
  for (std::size_t p = 0; p < spec_.plots.size(); ++p) {
    curves_[p].resize(spec_.plots[p].curves.size());
  }
  last_count_.assign(spec_.lasers.size(), 0.0);
  next_scan_.assign(spec_.lasers.size(), 0);
  scans_.resize(spec_.lasers.size());
  movers_.resize(spec_.movers.size());
}

void ReplayRecorder::OnStart(const cosim::Master& master) {
  next_frame_ = master.options().start;
  for (auto& n : next_scan_) n = master.options().start;
}

void ReplayRecorder::OnSample(cosim::TimeNs t, const cosim::System& system) {
  const double x = cosim::ReadProbe(system, spec_.x);
  const double y = cosim::ReadProbe(system, spec_.y);
  const double yaw = cosim::ReadProbe(system, spec_.yaw);
  history_[history_count_ % history_.size()] = {t, x, y, yaw};
  ++history_count_;

  if (t >= next_frame_) {
    while (next_frame_ <= t) next_frame_ += spec_.rates.frame_interval;
    time_.push_back(cosim::NsToSeconds(t));
    x_.push_back(x);
    y_.push_back(y);
    yaw_.push_back(yaw);
    for (std::size_t w = 0; w < spec_.wheels.size(); ++w) {
      wheel_xy_[2 * w].push_back(cosim::ReadProbe(system, spec_.wheels[w][0]));
      wheel_xy_[2 * w + 1].push_back(cosim::ReadProbe(system, spec_.wheels[w][1]));
    }
    for (std::size_t w = 0; w < spec_.wheel_surface.size(); ++w) {
      wheel_surface_[w].push_back(cosim::ReadProbe(system, spec_.wheel_surface[w]));
    }
    for (std::size_t b = 0; b < spec_.belt_travel.size(); ++b) {
      belt_travel_[b].push_back(cosim::ReadProbe(system, spec_.belt_travel[b]));
    }
    for (std::size_t b = 0; b < spec_.belt_on.size(); ++b) {
      belt_on_[b].push_back(cosim::ReadProbe(system, spec_.belt_on[b]));
    }
    for (std::size_t p = 0; p < spec_.plots.size(); ++p) {
      const auto& curves = spec_.plots[p].curves;
      for (std::size_t c = 0; c < curves.size(); ++c) {
        curves_[p][c].push_back(cosim::ReadProbe(system, curves[c].probe));
      }
    }
    for (std::size_t m = 0; m < spec_.movers.size(); ++m) {
      const ReplaySpec::Mover& mover = spec_.movers[m];
      movers_[m][0].push_back(cosim::ReadProbe(system, mover.x));
      movers_[m][1].push_back(cosim::ReadProbe(system, mover.y));
      if (mover.robot) movers_[m][2].push_back(cosim::ReadProbe(system, mover.yaw));
    }
  }

  for (std::size_t k = 0; k < spec_.lasers.size(); ++k) {
    const sensors::LaserScannerUnit& laser = *spec_.lasers[k].unit;
    const double count = laser.scan_count();
    if (count == last_count_[k]) continue;
    last_count_[k] = count;
    const double scan_s = laser.scan_time_s();
    const cosim::TimeNs scan_t = cosim::SecondsToNs(scan_s);
    if (scan_t < next_scan_[k]) continue;
    while (next_scan_[k] <= scan_t) next_scan_[k] += spec_.rates.scan_interval;
    // The pose at the scan's start: the base step nearest to it in the
    // ring (the scan started at most a scan period ago).
    const Pose* best = nullptr;
    const std::size_t n = std::min(history_count_, history_.size());
    for (std::size_t i = 0; i < n; ++i) {
      const Pose& p = history_[i];
      if (!best || std::llabs(p.t - scan_t) < std::llabs(best->t - scan_t)) best = &p;
    }
    scans_[k].push_back({scan_s, best->x, best->y, best->yaw, laser.ranges()});
  }
}

std::string ReplayRecorder::DataJson() const {
  std::string out;
  out.reserve(std::size_t{2} << 20);  // a 20 s cross_line: 1.5 MB
  out += '{';
  Key(out, "format");
  out += "1,";
  Key(out, "title");
  AppendString(out, spec_.title);
  out += ',';
  Key(out, "task");
  AppendString(out, spec_.task);
  out += ',';
  Key(out, "rates");
  out += '{';
  Member(out, "frame_hz", cosim::kNsPerSecond / static_cast<double>(spec_.rates.frame_interval),
         kSignal);
  Key(out, "scan_hz");
  AppendFixed(out, cosim::kNsPerSecond / static_cast<double>(spec_.rates.scan_interval), kSignal);
  out += "},";

  // The scene.
  const models::Scene& scene = spec_.scene;
  Key(out, "surfaces");
  out += '[';
  for (std::size_t i = 0; i < scene.surfaces.size(); ++i) {
    if (i > 0) out += ',';
    AppendString(out, scene.surfaces[i].name);
  }
  out += "],";
  Key(out, "floor");
  out += '{';
  Member(out, "min_x", scene.floor.min_x_m, kMetres);
  Member(out, "max_x", scene.floor.max_x_m, kMetres);
  Member(out, "min_y", scene.floor.min_y_m, kMetres);
  Member(out, "max_y", scene.floor.max_y_m, kMetres);
  Key(out, "surface");
  AppendInt(out, scene.floor.surface);
  out += "},";
  Key(out, "belts");
  out += '[';
  for (std::size_t b = 0; b < scene.belts.size(); ++b) {
    const models::Belt& belt = scene.belts[b];
    if (b > 0) out += ',';
    out += '{';
    Key(out, "name");
    AppendString(out, belt.name);
    out += ',';
    Member(out, "x", belt.area.center_x_m, kMetres);
    Member(out, "y", belt.area.center_y_m, kMetres);
    Member(out, "length", belt.area.length_m, kMetres);
    Member(out, "width", belt.area.width_m, kMetres);
    Member(out, "dir", belt.area.direction_rad, kRadians);
    Key(out, "surface");
    AppendInt(out, belt.surface);
    out += ',';
    Key(out, "travel");
    AppendArray(out, b < belt_travel_.size() ? belt_travel_[b] : std::vector<double>{}, kMetres);
    out += ',';
    Key(out, "on");
    AppendArray(out, b < belt_on_.size() ? belt_on_[b] : std::vector<double>{}, 0);
    out += '}';
  }
  out += "],";
  Key(out, "obstacles");
  out += '[';
  for (std::size_t i = 0; i < scene.obstacles.size(); ++i) {
    if (i > 0) out += ',';
    out += '{';
    Key(out, "name");
    AppendString(out, scene.obstacles[i].name);
    out += ',';
    Key(out, "kind");
    AppendString(out, scene.obstacles[i].kind);
    out += ',';
    AppendSolid(out, scene.obstacles[i].solid);
    out += '}';
  }
  out += "],";
  Key(out, "carried");
  out += '[';
  for (std::size_t i = 0; i < scene.carried.size(); ++i) {
    const models::CarriedObject& c = scene.carried[i];
    if (i > 0) out += ',';
    out += '{';
    Key(out, "name");
    AppendString(out, c.name);
    out += ',';
    Key(out, "belt");
    AppendInt(out, c.belt);
    out += ',';
    // The travel over which it lies on its belt (outside: lifted off).
    const bool has_belt = c.belt >= 0 && static_cast<std::size_t>(c.belt) < scene.belts.size();
    const auto range = has_belt ? models::CarriedTravelRange(
                                      scene.belts[static_cast<std::size_t>(c.belt)].area, c.solid)
                                : std::array<double, 2>{0.0, 0.0};
    Member(out, "travel_min", range[0], kMetres);
    Member(out, "travel_max", range[1], kMetres);
    AppendSolid(out, c.solid);
    out += '}';
  }
  out += "],";
  Key(out, "terrain");
  out += '[';
  for (std::size_t i = 0; i < scene.terrain.size(); ++i) {
    const models::TerrainPiece& p = scene.terrain[i];
    if (i > 0) out += ',';
    out += '{';
    Key(out, "name");
    AppendString(out, p.name);
    out += ',';
    Member(out, "x", p.center_x_m, kMetres);
    Member(out, "y", p.center_y_m, kMetres);
    Member(out, "yaw", p.yaw_rad, kRadians);
    // The footprint of its top face seen from above.
    Member(out, "length", p.length_m * std::cos(p.pitch_rad), kMetres);
    Member(out, "width", p.width_m * std::cos(p.roll_rad), kMetres);
    Key(out, "surface");
    AppendInt(out, p.surface);
    out += '}';
  }
  out += "],";
  Key(out, "path");
  out += '[';
  for (std::size_t i = 0; i < spec_.path.size(); ++i) {
    if (i > 0) out += ',';
    out += '[';
    AppendFixed(out, spec_.path[i][0], kMetres);
    out += ',';
    AppendFixed(out, spec_.path[i][1], kMetres);
    out += ']';
  }
  out += "],";

  // The robot over time.
  Key(out, "body");
  out += '{';
  Member(out, "length", spec_.body_length_m, kMetres);
  Key(out, "width");
  AppendFixed(out, spec_.body_width_m, kMetres);
  out += "},";
  Key(out, "t");
  AppendArray(out, time_, kSeconds);
  out += ',';
  Key(out, "x");
  AppendArray(out, x_, kMetres);
  out += ',';
  Key(out, "y");
  AppendArray(out, y_, kMetres);
  out += ',';
  Key(out, "yaw");
  AppendArray(out, yaw_, kRadians);
  out += ',';
  Key(out, "wheels");
  out += '[';
  for (std::size_t w = 0; w < spec_.wheels.size(); ++w) {
    if (w > 0) out += ',';
    out += '{';
    Key(out, "x");
    AppendArray(out, wheel_xy_[2 * w], kMetres);
    out += ',';
    Key(out, "y");
    AppendArray(out, wheel_xy_[2 * w + 1], kMetres);
    out += ',';
    Key(out, "surface");
    AppendArray(out, w < wheel_surface_.size() ? wheel_surface_[w] : std::vector<double>{}, 0);
    out += '}';
  }
  out += "],";
  Key(out, "plots");
  out += '[';
  for (std::size_t p = 0; p < spec_.plots.size(); ++p) {
    const ReplaySpec::Plot& plot = spec_.plots[p];
    if (p > 0) out += ',';
    out += '{';
    Key(out, "title");
    AppendString(out, plot.title);
    out += ',';
    Key(out, "unit");
    AppendString(out, plot.unit);
    out += ',';
    Member(out, "bound", plot.bound, kSignal);
    Key(out, "bound_label");
    AppendString(out, plot.bound_label);
    out += ',';
    Key(out, "curves");
    out += '[';
    for (std::size_t c = 0; c < plot.curves.size(); ++c) {
      if (c > 0) out += ',';
      out += '{';
      Key(out, "label");
      AppendString(out, plot.curves[c].label);
      out += ',';
      Key(out, "values");
      AppendArray(out, curves_[p][c], kSignal);
      out += '}';
    }
    out += "]}";
  }
  out += "],";
  Key(out, "movers");
  out += '[';
  for (std::size_t m = 0; m < spec_.movers.size(); ++m) {
    const ReplaySpec::Mover& mover = spec_.movers[m];
    if (m > 0) out += ',';
    out += '{';
    Key(out, "name");
    AppendString(out, mover.name);
    out += ',';
    Key(out, "robot");
    out += mover.robot ? "true," : "false,";
    Member(out, "length", mover.length_m, kMetres);
    Member(out, "width", mover.width_m, kMetres);
    Member(out, "radius", mover.radius_m, kMetres);
    Key(out, "x");
    AppendArray(out, movers_[m][0], kMetres);
    out += ',';
    Key(out, "y");
    AppendArray(out, movers_[m][1], kMetres);
    out += ',';
    Key(out, "yaw");
    AppendArray(out, movers_[m][2], kRadians);
    out += '}';
  }
  out += "],";
  // Ranges in whole millimetres (the S300 and LMS151 report in mm), -1 for
  // no echo.
  Key(out, "lasers");
  out += '[';
  for (std::size_t k = 0; k < spec_.lasers.size(); ++k) {
    const auto g = spec_.lasers[k].unit->beam_geometry();
    if (k > 0) out += ',';
    out += '{';
    Key(out, "name");
    AppendString(out, spec_.lasers[k].name);
    out += ',';
    Member(out, "mount_x", g.mount_x_m, kMetres);
    Member(out, "mount_y", g.mount_y_m, kMetres);
    Member(out, "mount_yaw", g.mount_yaw_rad, kRadians);
    Member(out, "first_beam", g.first_beam_rad, 7);
    Member(out, "beam_step", g.beam_step_rad, 9);
    Key(out, "scans");
    out += '[';
    for (std::size_t i = 0; i < scans_[k].size(); ++i) {
      const Scan& scan = scans_[k][i];
      if (i > 0) out += ',';
      out += '{';
      Member(out, "t", scan.time_s, kSeconds);
      Key(out, "pose");
      out += '[';
      AppendFixed(out, scan.x, kMetres);
      out += ',';
      AppendFixed(out, scan.y, kMetres);
      out += ',';
      AppendFixed(out, scan.yaw, kRadians);
      out += "],";
      Key(out, "ranges_mm");
      out += '[';
      for (std::size_t b = 0; b < scan.ranges.size(); ++b) {
        if (b > 0) out += ',';
        const double range = scan.ranges[b];
        if (range == g.no_return_m || !std::isfinite(range)) {
          out += "-1";
        } else {
          AppendInt(out, std::llround(range * 1000.0));
        }
      }
      out += "]}";
    }
    out += "]}";
  }
  out += "]}";
  return out;
}

std::string ReplayRecorder::Html() const {
  const std::string page = PageTemplate();
  const std::size_t at = page.find(kDataMarker);
  if (at == std::string::npos) throw std::logic_error("replay page template without its data marker");
  std::string html = page.substr(0, at);
  html += DataJson();
  html += page.substr(at + std::strlen(kDataMarker));
  return html;
}

void ReplayRecorder::Write(const std::string& path) const {
  cosim::WriteFileAtomically(path, Html());
}

}  // namespace linesim::replay
