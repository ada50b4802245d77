#include "replay/replay_recorder.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "cosim/files.h"
#include "loader/scenario.h"
#include "units/sensors/laser_scanner_unit.h"

namespace linesim::replay {

ReplaySpec ReplaySpecFor(const loader::Scenario& s, double bound_m,
                         const std::string& bound_label) {
  const loader::RobotInfo& r = *s.robot;
  const cosim::System& system = *s.system;
  const auto one = [&](const std::string& column) {
    return cosim::ResolveProbes(system, {column}).front();
  };
  ReplaySpec spec;
  spec.title = s.name;
  spec.description = s.description;
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
      if (!laser->name().starts_with(scope)) continue;
      const cosim::VariableTable& v = laser->variables();
      const auto ranges = v.Find("ranges");
      const auto real = [&](const char* name) {
        const auto ref = v.Find(name);
        return ref ? v.GetReal(*ref) : 0.0;
      };
      // A measured range: at most range_max, plus the device's bias (at
      // most bias_max, or some bias_sigma) and noise (some noise_sigma):
      // ten sigmas and twice range_max are beyond any run.
      const double farthest = 2.0 * real("range_max") + real("bias_max") +
                              10.0 * (real("bias_sigma") + real("noise_sigma"));
      spec.lasers.push_back({laser->name(), laser, ranges ? v.info(*ranges).size : 0, farthest});
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

namespace {

// The longest text of a range no farther than `farthest_m`, in whole
// millimetres, with its comma; "-1" for no echo.
std::uint64_t RangeBytes(double farthest_m) {
  const double mm = std::ceil(1000.0 * std::max(farthest_m, 0.0));
  if (!(mm < 1e15)) return kMaxNumberBytes;
  std::uint64_t digits = 1;
  for (double d = mm; d >= 10.0; d /= 10.0) ++digits;
  return std::max<std::uint64_t>(digits, 2) + 1;
}

// A text's longest escaped form: every byte as \u00XX, the quotes, a comma.
std::uint64_t TextBytes(const std::string& s) { return 6 * s.size() + 3; }

}  // namespace

std::uint64_t ReplayBytesBound(const ReplaySpec& spec, cosim::TimeNs start, cosim::TimeNs stop) {
  const auto count = [&](cosim::TimeNs interval) {
    return static_cast<std::uint64_t>(std::max<cosim::TimeNs>(stop - start, 0) /
                                      std::max<cosim::TimeNs>(interval, 1)) +
           2;
  };
  constexpr std::uint64_t kItem = 256;  // an item's keys and punctuation
  const std::uint64_t n = kMaxNumberBytes;
  std::uint64_t bytes = PageBytesWithoutData() + 4096;  // the fixed keys and rates
  bytes += TextBytes(spec.title) + TextBytes(spec.description) + TextBytes(spec.task);
  const models::Scene& scene = spec.scene;
  for (const auto& s : scene.surfaces) bytes += TextBytes(s.name);
  for (const auto& b : scene.belts) bytes += kItem + TextBytes(b.name) + 8 * n;
  for (const auto& o : scene.obstacles) {
    bytes += kItem + TextBytes(o.name) + TextBytes(o.kind) + 6 * n;
  }
  for (const auto& c : scene.carried) bytes += kItem + TextBytes(c.name) + 9 * n;
  for (const auto& t : scene.terrain) bytes += kItem + TextBytes(t.name) + 6 * n;
  bytes += spec.path.size() * (2 * n + 3);
  // Per frame: time and pose, each wheel's contact point and surface, each
  // belt's travel and on state, every curve, every mover's pose.
  std::uint64_t per_frame =
      4 + 3 * spec.wheels.size() + spec.belt_travel.size() + spec.belt_on.size();
  for (const auto& p : spec.plots) {
    bytes += kItem + TextBytes(p.title) + TextBytes(p.unit) + TextBytes(p.bound_label) + n;
    for (const auto& c : p.curves) bytes += kItem + TextBytes(c.label);
    per_frame += p.curves.size();
  }
  for (const auto& m : spec.movers) {
    bytes += kItem + TextBytes(m.name) + 3 * n;
    per_frame += m.robot ? 3 : 2;
  }
  bytes += count(spec.rates.frame_interval) * per_frame * n;
  for (const auto& l : spec.lasers) {
    bytes += kItem + TextBytes(l.name) + 5 * n;
    bytes += count(spec.rates.scan_interval) *
             (64 + 4 * n + static_cast<std::uint64_t>(l.beams) * RangeBytes(l.farthest_m));
  }
  return bytes;
}

ReplayRecorder::ReplayRecorder(ReplaySpec spec) : spec_(std::move(spec)) {
  ReplayData& d = data_;
  d.title = spec_.title;
  d.description = spec_.description;
  d.task = spec_.task;
  d.frame_hz = cosim::kNsPerSecond / static_cast<double>(spec_.rates.frame_interval);
  d.scan_hz = cosim::kNsPerSecond / static_cast<double>(spec_.rates.scan_interval);
  d.scene = spec_.scene;
  d.path = spec_.path;
  d.body_length_m = spec_.body_length_m;
  d.body_width_m = spec_.body_width_m;
  d.wheels.resize(spec_.wheels.size());
  d.belt_travel.resize(spec_.belt_travel.size());
  d.belt_on.resize(spec_.belt_on.size());
  for (const ReplaySpec::Plot& p : spec_.plots) {
    ReplayData::Plot plot{p.title, p.unit, p.bound, p.bound_label, {}};
    for (const auto& c : p.curves) plot.curves.push_back({c.label, {}});
    d.plots.push_back(std::move(plot));
  }
  for (const ReplaySpec::Mover& m : spec_.movers) {
    d.movers.push_back({m.name, m.robot, m.length_m, m.width_m, m.radius_m, {}, {}, {}});
  }
  for (const ReplaySpec::Laser& l : spec_.lasers) {
    const auto g = l.unit->beam_geometry();
    d.lasers.push_back({l.name,
                        g.mount_x_m,
                        g.mount_y_m,
                        g.mount_yaw_rad,
                        g.first_beam_rad,
                        g.beam_step_rad,
                        g.no_return_m,
                        {}});
  }
  last_count_.assign(spec_.lasers.size(), 0.0);
  next_scan_.assign(spec_.lasers.size(), 0);
}

void ReplayRecorder::OnStart(const cosim::Master& master) {
  next_frame_ = master.options().start;
  for (auto& n : next_scan_) n = master.options().start;
  data_.outcome.stop_s = cosim::NsToSeconds(master.options().stop);
}

void ReplayRecorder::OnSample(cosim::TimeNs t, const cosim::System& system) {
  const double x = cosim::ReadProbe(system, spec_.x);
  const double y = cosim::ReadProbe(system, spec_.y);
  const double yaw = cosim::ReadProbe(system, spec_.yaw);
  history_[history_count_ % history_.size()] = {t, x, y, yaw};
  ++history_count_;
  ReplayData& d = data_;
  d.outcome.end_s = cosim::NsToSeconds(t);

  if (t >= next_frame_) {
    while (next_frame_ <= t) next_frame_ += spec_.rates.frame_interval;
    d.t.push_back(cosim::NsToSeconds(t));
    d.x.push_back(x);
    d.y.push_back(y);
    d.yaw.push_back(yaw);
    for (std::size_t w = 0; w < spec_.wheels.size(); ++w) {
      d.wheels[w].x.push_back(cosim::ReadProbe(system, spec_.wheels[w][0]));
      d.wheels[w].y.push_back(cosim::ReadProbe(system, spec_.wheels[w][1]));
      if (w < spec_.wheel_surface.size()) {
        d.wheels[w].surface.push_back(cosim::ReadProbe(system, spec_.wheel_surface[w]));
      }
    }
    for (std::size_t b = 0; b < spec_.belt_travel.size(); ++b) {
      d.belt_travel[b].push_back(cosim::ReadProbe(system, spec_.belt_travel[b]));
    }
    for (std::size_t b = 0; b < spec_.belt_on.size(); ++b) {
      d.belt_on[b].push_back(cosim::ReadProbe(system, spec_.belt_on[b]));
    }
    for (std::size_t p = 0; p < spec_.plots.size(); ++p) {
      const auto& curves = spec_.plots[p].curves;
      for (std::size_t c = 0; c < curves.size(); ++c) {
        d.plots[p].curves[c].values.push_back(cosim::ReadProbe(system, curves[c].probe));
      }
    }
    for (std::size_t m = 0; m < spec_.movers.size(); ++m) {
      const ReplaySpec::Mover& mover = spec_.movers[m];
      d.movers[m].x.push_back(cosim::ReadProbe(system, mover.x));
      d.movers[m].y.push_back(cosim::ReadProbe(system, mover.y));
      if (mover.robot) d.movers[m].yaw.push_back(cosim::ReadProbe(system, mover.yaw));
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
    d.lasers[k].scans.push_back({scan_s, best->x, best->y, best->yaw, laser.ranges()});
  }
}

void ReplayRecorder::Write(const std::string& path) const {
  cosim::WriteFileAtomically(path, Html());
}

}  // namespace linesim::replay
