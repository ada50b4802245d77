// Issue 35 (item 4, bodies where they are): in fleet_line every laser sees
// every other robot whose body crosses its scan plane whenever that body is
// in range and nothing nearer is in the way, and every worker; a body that
// does not cross a scan plane is not seen by it; no laser sees its own
// robot's body.
//
// The expectation is the geometry's, not the lasers': each beam's ray in
// map (the scanner's mount on its robot's recorded pose at the beam's
// time), the other robots' bodies as boxes of the robot files' bottom_m and
// height_m on their recorded poses, the workers' legs and torsos, and the
// scene's static and carried solids (RayScene with nothing moving in it,
// the part of the laser model other tests check). A beam must read a
// target when it is aimed at the target's core (the target shrunk by a
// margin, not its edge), in range, at most 60 deg off the surface's
// normal, with nothing nearer along it (the others widened by a margin),
// and each neighbour is so too on the same solid or meets nothing within
// the laser's echo separation behind the target (an edge, where the laser
// samples across its spot and the far samples make a later echo). It must
// read the target's distance within the device's error: 6 sigma +
// bias_max + resolution (the model files' datasheet figures), 1 cm for
// the motion within a master step, and at an edge the spread of the
// target's samples across the spot. The margins stand for what the laser's
// view may differ from the recording's (Gauss-Seidel: it may take another
// unit's outputs of the step's end): a robot moves 3 mm in a 5 ms step, a
// walking leg up to 15 mm.
#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "cosim/master.h"
#include "cosim/system.h"
#include "cosim/time.h"
#include "loader/scenario.h"
#include "models/models_dir.h"
#include "models/moving_solids.h"
#include "tests/scenarios/run_scenario.h"
#include "units/sensors/laser_scanner_unit.h"
#include "units/sensors/ray_scene.h"

namespace linesim {
namespace {

using cosim::TimeNs;
using models::MovingBox;
using models::MovingCylinder;
using test_scenarios::Shipped;
using Vec = Eigen::Vector3d;

constexpr double kInf = std::numeric_limits<double>::infinity();
// Beams more than this off a surface's normal are left out: near grazing
// a spot's samples spread over more than the echo separation (the S300's
// 0.5 deg steps at 20 m and 60 deg give 0.3 m of 0.5 m).
const double kMaxIncidence = 60.0 * std::numbers::pi / 180.0;
// How much wider the other robots and the workers are taken as occluders,
// and how much narrower as targets (see the file's comment).
constexpr double kRobotMargin = 0.01;
constexpr double kWorkerMargin = 0.02;

// What a ray meets first: distance (inf: nothing), |cos| of the incidence,
// and which part of a target (a worker's leg or torso).
struct Hit {
  double t = kInf;
  double cos_incidence = 0.0;
  int part = 0;
  double radius = 0.0;  // a cylinder's
};

// A ray against a box yawed about the vertical: centre (cx, cy), half sizes
// hx, hy, heights z0..z1. From outside: the entry; from inside: the exit
// when `exit` (else nothing).
Hit RayBox(const Vec& o, const Vec& d, double cx, double cy, double yaw, double hx, double hy,
           double z0, double z1, bool exit = false) {
  const double c = std::cos(yaw), s = std::sin(yaw);
  const double oo[3] = {c * (o.x() - cx) + s * (o.y() - cy), -s * (o.x() - cx) + c * (o.y() - cy),
                        o.z()};
  const double dd[3] = {c * d.x() + s * d.y(), -s * d.x() + c * d.y(), d.z()};
  const double lo[3] = {-hx, -hy, z0}, hi[3] = {hx, hy, z1};
  double t_in = -kInf, t_out = kInf;
  int in_axis = -1, out_axis = -1;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(dd[a]) < 1e-15) {
      if (oo[a] < lo[a] || oo[a] > hi[a]) return {};
      continue;
    }
    double t1 = (lo[a] - oo[a]) / dd[a], t2 = (hi[a] - oo[a]) / dd[a];
    if (t1 > t2) std::swap(t1, t2);
    if (t1 > t_in) t_in = t1, in_axis = a;
    if (t2 < t_out) t_out = t2, out_axis = a;
  }
  if (t_out < std::max(t_in, 0.0)) return {};
  if (t_in >= 0.0) return {t_in, std::abs(dd[in_axis]), 0};
  if (exit && out_axis >= 0) return {t_out, std::abs(dd[out_axis]), 0};
  return {};
}

// A ray against a vertical cylinder (its side; a scan's rays are near
// horizontal).
Hit RayCylinder(const Vec& o, const Vec& d, const double* m) {
  const double px = o.x() - m[MovingCylinder::kX], py = o.y() - m[MovingCylinder::kY];
  const double r = m[MovingCylinder::kRadius];
  const double a = d.x() * d.x() + d.y() * d.y();
  const double b = 2.0 * (px * d.x() + py * d.y());
  const double c = px * px + py * py - r * r;
  const double disc = b * b - 4.0 * a * c;
  if (a <= 0.0 || disc < 0.0 || c < 0.0) return {};
  const double t = (-b - std::sqrt(disc)) / (2.0 * a);
  const double z = o.z() + t * d.z();
  if (t < 0.0 || z < m[MovingCylinder::kZBottom] || z > m[MovingCylinder::kZTop]) return {};
  const double nx = (px + t * d.x()) / r, ny = (py + t * d.y()) / r;
  return {t, std::abs(nx * d.x() + ny * d.y()), 0, r};
}

// Everything a run leaves for the analysis, at every base step.
struct Recording {
  struct Robot {
    std::string name;
    std::size_t chassis = 0;
    double bottom_m = 0.0, height_m = 0.0;  // the robot file's, through the chassis
  };
  struct Laser {
    std::string name;
    std::size_t robot = 0;
    const sensors::LaserScannerUnit* unit = nullptr;
    double mount[6] = {0, 0, 0, 0, 0, 0};  // x, y, z, roll, pitch, yaw
    double range_min = 0, range_max = 0, no_return = 0, tolerance = 0;
    double spot_divergence = 0, spot_offset = 0;
    double last_count = 0.0;
    std::vector<TimeNs> scan_start;
    std::vector<std::vector<double>> ranges;
  };
  struct Step {
    // Per robot: body_box, then position_3d, orientation, velocity_3d,
    // angular_velocity.
    std::vector<double> robots;
    std::vector<double> workers;  // per worker: its 3 cylinders
    std::vector<double> belt_travel, belt_speed;
  };
  static constexpr std::size_t kRobotValues = MovingBox::kValues + 13;

  // The run, kept: the lasers' units answer the analysis (beam times,
  // angles, parameters).
  std::unique_ptr<loader::Scenario> scenario;
  std::vector<Robot> robots;
  std::vector<Laser> lasers;
  std::vector<std::string> workers;
  std::vector<std::size_t> worker_units;
  std::optional<std::size_t> belt;
  TimeNs start = 0, base = 0;
  std::vector<Step> steps;
};

double Param(const cosim::Unit& u, const char* name) {
  return u.variables().GetReal(*u.variables().Find(name));
}

std::span<const double> Array(const cosim::Unit& u, const char* name) {
  return u.variables().GetRealArray(*u.variables().Find(name));
}

// Samples the robots, workers and belts at every base step and keeps every
// scan of every laser.
class Recorder : public cosim::Observer {
 public:
  explicit Recorder(Recording& out) : out_(out) {}
  void OnStart(const cosim::Master& master) override {
    out_.start = master.options().start;
    out_.base = master.options().base_step;
  }
  void OnSample(TimeNs t, const cosim::System& system) override {
    EXPECT_EQ(t, out_.start + static_cast<TimeNs>(out_.steps.size()) * out_.base);
    Recording::Step& step = out_.steps.emplace_back();
    for (const auto& r : out_.robots) {
      const cosim::Unit& c = system.unit(r.chassis);
      for (const char* name :
           {"body_box", "position_3d", "orientation", "velocity_3d", "angular_velocity"}) {
        const auto v = Array(c, name);
        step.robots.insert(step.robots.end(), v.begin(), v.end());
      }
    }
    for (const std::size_t w : out_.worker_units) {
      const auto v = Array(system.unit(w), "cylinders");
      step.workers.insert(step.workers.end(), v.begin(), v.end());
    }
    if (out_.belt) {
      const cosim::Unit& b = system.unit(*out_.belt);
      const auto travel = Array(b, "travel"), speed = Array(b, "speed");
      step.belt_travel.assign(travel.begin(), travel.end());
      step.belt_speed.assign(speed.begin(), speed.end());
    }
    for (auto& laser : out_.lasers) {
      const double count = laser.unit->scan_count();
      if (count == laser.last_count) continue;
      laser.last_count = count;
      laser.scan_start.push_back(cosim::SecondsToNs(laser.unit->scan_time_s()));
      laser.ranges.push_back(laser.unit->ranges());
    }
  }

 private:
  Recording& out_;
};

// Loads `file` with `sets`, finds the fleet's robots (NAME.chassis), their
// lasers (NAME.laser_*), the workers and the belt, runs it and records.
Recording RunAndRecord(const std::string& file, const std::vector<std::string>& sets,
                       models::Scene* scene) {
  Recording rec;
  rec.scenario = std::make_unique<loader::Scenario>(loader::LoadScenario(file, sets));
  loader::Scenario& s = *rec.scenario;
  *scene = s.scene;
  const cosim::System& system = *s.system;
  for (std::size_t u = 0; u < system.unit_count(); ++u) {
    const cosim::Unit& unit = system.unit(u);
    const std::string& name = unit.name();
    if (name.ends_with(".chassis")) {
      rec.robots.push_back({name.substr(0, name.size() - 8), u, Param(unit, "body_bottom"),
                            Param(unit, "body_height")});
    } else if (unit.type_name() == "worker") {
      rec.workers.push_back(name);
      rec.worker_units.push_back(u);
    } else if (name == "belt") {
      rec.belt = u;
    }
  }
  for (std::size_t u = 0; u < system.unit_count(); ++u) {
    const auto* laser = dynamic_cast<const sensors::LaserScannerUnit*>(&system.unit(u));
    if (!laser) continue;
    Recording::Laser l;
    l.name = laser->name();
    const auto robot = std::find_if(rec.robots.begin(), rec.robots.end(), [&](const auto& r) {
      return l.name.starts_with(r.name + ".");
    });
    EXPECT_NE(robot, rec.robots.end()) << l.name;
    if (robot == rec.robots.end()) continue;
    l.robot = static_cast<std::size_t>(robot - rec.robots.begin());
    l.unit = laser;
    const char* mount[] = {"mount_x",    "mount_y",     "mount_z",
                           "mount_roll", "mount_pitch", "mount_yaw"};
    for (int k = 0; k < 6; ++k) l.mount[k] = Param(*laser, mount[k]);
    l.range_min = Param(*laser, "range_min");
    l.range_max = Param(*laser, "range_max");
    l.no_return = Param(*laser, "no_return_value");
    l.spot_divergence = Param(*laser, "spot_divergence");
    l.spot_offset = Param(*laser, "spot_offset");
    l.tolerance = 6.0 * Param(*laser, "noise_sigma") + Param(*laser, "bias_max") +
                  Param(*laser, "range_resolution") + 0.01;
    rec.lasers.push_back(std::move(l));
  }
  Recorder recorder(rec);
  s.master->AddObserver(&recorder);
  const cosim::RunResult result = s.master->Run();
  EXPECT_TRUE(result.ok) << result.ErrorText();
  return rec;  // the master, not run again, keeps a pointer to the recorder
}

// What one laser made of one target over the run.
struct PairStats {
  bool crosses = false;    // the target spans the scan plane (robot files)
  long interior = 0;       // beams the geometry says must see it
  long seen = 0;           // of those, the ones that did
  long scans_in_view = 0;  // scans with an interior beam
  long scans_seen = 0;     // scans in which it was seen
  double first_s = kInf, last_s = -kInf;
  std::string first_miss;
  // A target that does not cross the plane: beams over or under it whose
  // range would be its face's, and those that read it anyway.
  long passing = 0, read_anyway = 0;
};

struct Analysis {
  // laser name -> target name -> stats.
  std::map<std::string, std::map<std::string, PairStats>> pairs;
  long own_checked = 0, own_seen = 0;
  long box_samples = 0;
  double box_height_error = 0.0;
};

// The pose terms of a robot at a step: a rotation and the laser's mount.
struct BeamFrame {
  Vec origin;
  Eigen::Matrix3d to_map;  // scanner frame -> map
};

BeamFrame Frame(const double* r, const double* mount, double s) {
  // r: body_box, then position_3d (3), orientation (4), velocity_3d (3),
  // angular_velocity (3); moved on by s seconds as the laser does.
  const double* p = r + MovingBox::kValues;
  const double* q = p + 3;
  const double* v = q + 4;
  const double* w = v + 3;
  Eigen::Quaterniond rot(q[0], q[1], q[2], q[3]);
  const Vec omega(w[0], w[1], w[2]);
  if (omega.norm() > 0.0) rot = rot * Eigen::AngleAxisd(omega.norm() * s, omega.normalized());
  const Eigen::Matrix3d base = rot.normalized().toRotationMatrix();
  const Eigen::Matrix3d m =
      (Eigen::AngleAxisd(mount[5], Vec::UnitZ()) * Eigen::AngleAxisd(mount[4], Vec::UnitY()) *
       Eigen::AngleAxisd(mount[3], Vec::UnitX()))
          .toRotationMatrix();
  const Vec position(p[0] + v[0] * s, p[1] + v[1] * s, p[2] + v[2] * s);
  return {position + base * Vec(mount[0], mount[1], mount[2]), base * m};
}

// A robot's body box as the geometry has it at s seconds after the step:
// the recorded box moved on by its velocity and yaw rate, its heights the
// robot file's (or unbounded: `prism`).
// `grow` widens it on every side (an occluder where the laser may see it).
Hit HitRobot(const Vec& o, const Vec& d, const double* r, const Recording::Robot& robot, double s,
             bool prism = false, bool exit = false, double grow = 0.0) {
  const double z = r[MovingBox::kValues + 2];  // base_link's height
  const double z0 = prism ? -1e3 : z + robot.bottom_m - grow;
  const double z1 = prism ? 1e3 : z + robot.bottom_m + robot.height_m + grow;
  return RayBox(o, d, r[MovingBox::kX] + r[MovingBox::kVx] * s,
                r[MovingBox::kY] + r[MovingBox::kVy] * s,
                r[MovingBox::kYaw] + r[MovingBox::kYawRate] * s, 0.5 * r[MovingBox::kLength] + grow,
                0.5 * r[MovingBox::kWidth] + grow, z0, z1, exit);
}

// A worker's cylinder k (0, 1: legs; 2: torso) moved on by s seconds.
Hit HitCylinder(const Vec& o, const Vec& d, const double* cylinders, int k, double s,
                double grow = 0.0) {
  double m[MovingCylinder::kValues];
  std::copy_n(cylinders + k * MovingCylinder::kValues, MovingCylinder::kValues, m);
  m[MovingCylinder::kX] += m[MovingCylinder::kVx] * s;
  m[MovingCylinder::kY] += m[MovingCylinder::kVy] * s;
  m[MovingCylinder::kRadius] += grow;
  m[MovingCylinder::kZBottom] -= grow;
  m[MovingCylinder::kZTop] += grow;
  Hit h = RayCylinder(o, d, m);
  h.part = k;
  return h;
}

// The nearest of a worker's cylinders; `skip`: leave that one out (the
// others as occluders of it).
Hit HitWorker(const Vec& o, const Vec& d, const double* cylinders, double s, double grow = 0.0,
              int skip = -1) {
  Hit best;
  for (int k = 0; k < 3; ++k) {
    if (k == skip) continue;
    const Hit h = HitCylinder(o, d, cylinders, k, s, grow);
    if (h.t < best.t) best = h;
  }
  return best;
}

// What the geometry puts along one beam. Per target (the other robots,
// then the workers): `exact` the target as it is (a worker's nearest leg
// or torso), `block` as an occluder (widened by the margins: the laser may
// take a unit's outputs of the step's end, Gauss-Seidel, where a robot has
// moved 3 mm and a walking leg up to 15 mm), `prism` a robot's footprint
// at any height, `core` the target shrunk by the margins (met: not its
// edge), `rest` a worker's other cylinders widened.
struct BeamView {
  Vec origin, direction;
  double static_t = kInf;  // the scene's static and carried solids
  double all = kInf;       // the nearest of everything, widened
  Hit own;                 // the laser's own body, from inside: its exit
  std::vector<Hit> exact, block, prism, core;
  std::vector<double> rest;
};

// Everything a laser's beam i meets at its time, from the recording.
void View(const Recording& rec, const Recording::Laser& laser, TimeNs scan_start, int i,
          sensors::RayScene& statics, BeamView& v) {
  const std::size_t nr = rec.robots.size(), nw = rec.workers.size();
  const TimeNs t = scan_start + laser.unit->BeamOffset(i);
  const auto k = static_cast<std::size_t>(
      std::clamp<TimeNs>((t - rec.start) / rec.base, 0, static_cast<TimeNs>(rec.steps.size()) - 1));
  const double s = cosim::NsToSeconds(t - rec.start - static_cast<TimeNs>(k) * rec.base);
  const Recording::Step& step = rec.steps[k];
  const double* own = step.robots.data() + laser.robot * Recording::kRobotValues;
  const BeamFrame frame = Frame(own, laser.mount, s);
  const auto geometry = laser.unit->beam_geometry();
  const double a = geometry.first_beam_rad + i * geometry.beam_step_rad;
  const Vec d = frame.to_map * Vec(std::cos(a), std::sin(a), 0.0);
  const Vec& o = frame.origin;
  v.origin = o;
  v.direction = d;
  v.exact.assign(nr + nw, Hit{});
  v.block.assign(nr + nw, Hit{});
  v.prism.assign(nr, Hit{});
  v.rest.assign(nr + nw, kInf);
  v.core.assign(nr + nw, Hit{});
  for (std::size_t j = 0; j < nr; ++j) {
    if (j == laser.robot) continue;
    const double* r = step.robots.data() + j * Recording::kRobotValues;
    const auto& robot = rec.robots[j];
    v.exact[j] = HitRobot(o, d, r, robot, s);
    v.block[j] = HitRobot(o, d, r, robot, s, false, false, kRobotMargin);
    v.prism[j] = HitRobot(o, d, r, robot, s, true);
    v.core[j] = HitRobot(o, d, r, robot, s, false, false, -kRobotMargin);
  }
  for (std::size_t w = 0; w < nw; ++w) {
    const double* c = step.workers.data() + w * 3 * MovingCylinder::kValues;
    Hit& e = v.exact[nr + w];
    e = HitWorker(o, d, c, s);
    v.block[nr + w] = HitWorker(o, d, c, s, kWorkerMargin);
    if (e.t < kInf) {
      v.rest[nr + w] = HitWorker(o, d, c, s, kWorkerMargin, e.part).t;
      v.core[nr + w] = HitCylinder(o, d, c, e.part, s, -kWorkerMargin);
    }
  }
  v.own = HitRobot(o, d, own, rec.robots[laser.robot], s, false, /*exit=*/true);
  sensors::Ray ray{{o.x(), o.y(), o.z()}, {d.x(), d.y(), d.z()}, laser.range_max, s};
  sensors::RayHit hit;
  statics.Cast(std::span(&ray, 1), std::span(&hit, 1), step.belt_travel, step.belt_speed);
  v.static_t = hit.range;
  v.all = v.static_t;
  for (const Hit& h : v.block) v.all = std::min(v.all, h.t);
}

// Whether a laser's plane crosses a robot's box (the robot files'
// heights); the plane must stay 1 cm clear of either face (the robots
// roll and pitch by milliradians), or the answer would be the tilt's.
bool Crosses(const Recording::Laser& laser, const Recording::Robot& r) {
  const double z = laser.mount[2], lo = r.bottom_m, hi = r.bottom_m + r.height_m;
  EXPECT_GT(std::min(std::abs(z - lo), std::abs(z - hi)), 0.01)
      << laser.name << "'s plane grazes " << r.name << "'s box";
  return z > lo && z < hi;
}

// One scan against target j (which crosses the plane): the beams that must
// read it, and whether they did. A beam must read it when it is aimed at
// the target's core (in range, at most kMaxIncidence off its normal) with
// nothing nearer, and each neighbour either is so too on the same solid
// (no edge between them) or meets nothing within echo_separation behind
// it (an edge the laser samples across its spot, whose far samples make a
// later echo than the target's: the first echo, reported, is the target).
void ScanAgainst(const Recording::Laser& laser, const std::vector<BeamView>& views,
                 const std::vector<double>& ranges, std::size_t j, double echo_separation,
                 double scan_s, PairStats& ps) {
  const double tol = laser.tolerance;
  const int n = static_cast<int>(views.size());
  const auto other = [&](const BeamView& v) {
    double t = std::min(v.static_t, v.rest[j]);
    for (std::size_t m = 0; m < v.block.size(); ++m) {
      if (m != j) t = std::min(t, v.block[m].t);
    }
    return t;
  };
  const auto steep = [](const Hit& h) {
    return std::acos(std::min(1.0, h.cos_incidence)) <= kMaxIncidence;
  };
  // Near a box's corner a ray may enter by the face beside it at grazing
  // incidence (no return there) where the laser has the box a few
  // millimetres off the recording's: the box widened and shrunk by the
  // margins must be met on faces as steep, the shrunk one within a few
  // centimetres of the hit (on the same face).
  const bool box = j < views.front().prism.size();
  const auto clear = [&](int i) {
    const BeamView& v = views[static_cast<std::size_t>(i)];
    const Hit& h = v.exact[j];
    const Hit& core = v.core[j];
    return h.t >= laser.range_min + tol && h.t <= laser.range_max - tol && steep(h) &&
           core.t < h.t + 0.05 && (!box || (steep(v.block[j]) && steep(core))) &&
           other(v) > h.t + tol;
  };
  bool in_view = false, seen = false;
  for (int i = 1; i + 1 < n; ++i) {
    if (!clear(i)) continue;
    const Hit& h = views[static_cast<std::size_t>(i)].exact[j];
    bool clean = true, edge = false;
    for (const int b : {i - 1, i + 1}) {
      const BeamView& v = views[static_cast<std::size_t>(b)];
      const bool same = clear(b) && v.exact[j].part == h.part;
      clean = clean && (same || v.all >= h.t + echo_separation + tol);
      edge = edge || !same;
    }
    if (!clean) continue;
    in_view = true;
    ++ps.interior;
    // At an edge the laser reports the mean of the target's samples across
    // its spot (half angle a = (divergence + offset / d) / 2): on a face at
    // incidence q they spread by d a tan q, on a leg by up to its radius.
    double tol_i = tol;
    if (edge) {
      const double a = 0.5 * (laser.spot_divergence + laser.spot_offset / h.t);
      const double q = std::acos(std::min(1.0, h.cos_incidence));
      tol_i += h.t * a * std::tan(q) + (box ? 0.0 : h.radius);
    }
    const double r = ranges[static_cast<std::size_t>(i)];
    if (r != laser.no_return && std::abs(r - h.t) <= tol_i) {
      ++ps.seen;
      seen = true;
    } else if (ps.first_miss.empty()) {
      ps.first_miss = "scan at " + std::to_string(scan_s) + " s, beam " + std::to_string(i) +
                      ": expected " + std::to_string(h.t) + " m, read " + std::to_string(r) + " m";
    }
  }
  if (in_view) ++ps.scans_in_view;
  if (seen) {
    ++ps.scans_seen;
    ps.first_s = std::min(ps.first_s, scan_s);
    ps.last_s = std::max(ps.last_s, scan_s);
  }
}

// One scan against robot j whose box does not cross the plane: beams
// aimed at its footprint pass over or under it (their height at its face
// clear of the box) and must not read its face's distance, where nothing
// else is near that distance.
void ScanPast(const Recording::Laser& laser, const std::vector<BeamView>& views,
              const std::vector<double>& ranges, std::size_t j, const Recording::Robot& robot,
              PairStats& ps) {
  const double tol = laser.tolerance;
  for (std::size_t i = 0; i < views.size(); ++i) {
    const BeamView& v = views[i];
    const Hit& h = v.prism[j];
    if (h.t < laser.range_min + tol || h.t > laser.range_max - tol ||
        std::acos(std::min(1.0, h.cos_incidence)) > kMaxIncidence) {
      continue;
    }
    // The floor is level in fleet_line: base_link at z 0 within a millimetre.
    const double z = v.origin.z() + h.t * v.direction.z();
    const bool apart = z > robot.bottom_m + robot.height_m + 0.005 || z < robot.bottom_m - 0.005;
    double others = v.static_t;
    for (std::size_t m = 0; m < v.block.size(); ++m) {
      if (m != j) others = std::min(others, v.block[m].t);
    }
    if (!apart || std::abs(others - h.t) <= 2.0 * tol) continue;
    ++ps.passing;
    const double r = ranges[i];
    if (r != laser.no_return && std::abs(r - h.t) <= tol) ++ps.read_anyway;
  }
}

Analysis Analyse(const Recording& rec, const models::Scene& scene) {
  Analysis out;
  const std::size_t nr = rec.robots.size();
  // The body boxes' heights against the robot files' (level floor).
  for (const auto& step : rec.steps) {
    for (std::size_t k = 0; k < nr; ++k) {
      const double* r = step.robots.data() + k * Recording::kRobotValues;
      const double z = r[MovingBox::kValues + 2];
      const auto& robot = rec.robots[k];
      out.box_height_error =
          std::max({out.box_height_error, std::abs(r[MovingBox::kZBottom] - z - robot.bottom_m),
                    std::abs(r[MovingBox::kZTop] - z - robot.bottom_m - robot.height_m)});
      ++out.box_samples;
    }
  }
  sensors::RayScene statics(scene);
  for (const auto& laser : rec.lasers) {
    const int n = laser.unit->beam_count();
    const double echo_separation = Param(*laser.unit, "echo_separation");
    std::vector<std::string> names;
    for (const auto& r : rec.robots) names.push_back(r.name);
    for (const auto& w : rec.workers) names.push_back(w);
    std::vector<BeamView> views(static_cast<std::size_t>(n));
    for (std::size_t scan = 0; scan < laser.ranges.size(); ++scan) {
      const auto& ranges = laser.ranges[scan];
      for (int i = 0; i < n; ++i) {
        View(rec, laser, laser.scan_start[scan], i, statics, views[static_cast<std::size_t>(i)]);
        // Its own body: never read (where nothing else is near its exit).
        const BeamView& v = views[static_cast<std::size_t>(i)];
        const double r = ranges[static_cast<std::size_t>(i)];
        if (v.own.t < kInf && v.all > v.own.t + 2.0 * laser.tolerance) {
          ++out.own_checked;
          if (r != laser.no_return && r <= v.own.t + laser.tolerance) ++out.own_seen;
        }
      }
      const double scan_s = cosim::NsToSeconds(laser.scan_start[scan]);
      for (std::size_t j = 0; j < names.size(); ++j) {
        if (j == laser.robot) continue;
        PairStats& ps = out.pairs[laser.name][names[j]];
        ps.crosses = j >= nr || Crosses(laser, rec.robots[j]);  // legs from the floor up
        if (ps.crosses) {
          ScanAgainst(laser, views, ranges, j, echo_separation, scan_s, ps);
        } else {
          ScanPast(laser, views, ranges, j, rec.robots[j], ps);
        }
      }
    }
  }
  return out;
}

void Print(const Analysis& a) {
  for (const auto& [laser, targets] : a.pairs) {
    for (const auto& [target, ps] : targets) {
      std::cout << laser << " -> " << target
                << (ps.crosses ? " (crosses its plane)" : " (does not)") << ": interior beams "
                << ps.interior << ", seen " << ps.seen << "; scans in view " << ps.scans_in_view
                << ", seen in " << ps.scans_seen;
      if (ps.scans_seen > 0) std::cout << " (" << ps.first_s << " to " << ps.last_s << " s)";
      if (ps.passing > 0) {
        std::cout << "; beams over or under it " << ps.passing << ", read it " << ps.read_anyway;
      }
      if (!ps.first_miss.empty()) std::cout << "; first miss: " << ps.first_miss;
      std::cout << "\n";
    }
  }
  std::cout << "own body: " << a.own_checked << " beams checked, " << a.own_seen << " read it\n"
            << "body_box heights against the robot files: " << a.box_samples << " samples, worst "
            << a.box_height_error << " m\n";
}

// Guards issue 35's fault and its kind: in the shipped fleet_line every
// scan plane (the S300s' at 0.178 m, the LMS151's at 0.35 m) crosses every
// other robot's body (Rob@Work 3: 0.07 to 0.40 m; Husky: 0.1323 to
// 0.3798 m), so every laser must see every other robot and every worker
// wherever the geometry puts them in view, with no beam reading through a
// body; and every pair of a laser and another robot does come into view in
// the run (the Husky's LMS151 has raw3_a from 0 to 24 s: the fault was 0
// hits at 13.98 s), each worker into view of every robot.
TEST(FleetVisibility, EveryLaserSeesEveryRobotAndWorkerInView) {
  models::Scene scene;
  const Recording rec = RunAndRecord(Shipped("fleet_line"), {}, &scene);
  ASSERT_TRUE(rec.belt.has_value());
  ASSERT_EQ(rec.robots.size(), 3u);
  ASSERT_EQ(rec.lasers.size(), 5u);
  ASSERT_EQ(rec.workers.size(), 2u);
  const Analysis a = Analyse(rec, scene);
  Print(a);
  EXPECT_LT(a.box_height_error, 1e-3);
  EXPECT_GT(a.own_checked, 0);
  EXPECT_EQ(a.own_seen, 0);
  for (const auto& laser : rec.lasers) {
    const auto& targets = a.pairs.at(laser.name);
    for (const auto& r : rec.robots) {
      if (laser.name.starts_with(r.name + ".")) continue;
      ASSERT_TRUE(targets.contains(r.name)) << laser.name << " " << r.name;
      const PairStats& ps = targets.at(r.name);
      EXPECT_TRUE(ps.crosses) << laser.name << " " << r.name;
      EXPECT_GT(ps.scans_in_view, 0) << laser.name << " never has " << r.name << " in view";
      EXPECT_EQ(ps.seen, ps.interior) << laser.name << " " << r.name << ": " << ps.first_miss;
      EXPECT_EQ(ps.scans_seen, ps.scans_in_view) << laser.name << " " << r.name;
    }
    for (const auto& w : rec.workers) {
      const PairStats& ps = targets.at(w);
      EXPECT_EQ(ps.seen, ps.interior) << laser.name << " " << w << ": " << ps.first_miss;
      EXPECT_EQ(ps.scans_seen, ps.scans_in_view) << laser.name << " " << w;
    }
  }
  // Not vacuous for the workers either: each comes into view of every
  // robot (raw3_b's rear S300, facing back-left, never has worker_2, who
  // walks on its right, in its 270 deg field).
  for (const auto& w : rec.workers) {
    for (const auto& r : rec.robots) {
      long in_view = 0;
      for (const auto& laser : rec.lasers) {
        if (laser.name.starts_with(r.name + "."))
          in_view += a.pairs.at(laser.name).at(w).scans_in_view;
      }
      EXPECT_GT(in_view, 0) << w << " never in view of " << r.name;
    }
  }
}

// The Rob@Work 3 of models/robots/raw3.yaml with its box's top at 0.33 m
// (the height the box had when it was centred on the centre of mass),
// written where a scenario can name it.
std::string LowRaw3() {
  YAML::Node robot = YAML::LoadFile(
      (std::filesystem::path(models::ModelsDir()) / "robots" / "raw3.yaml").string());
  robot["body"]["height_m"] = 0.26;  // 0.07 to 0.33 m
  const auto path = std::filesystem::path(::testing::TempDir()) /
                    ("raw3_top_at_0.33_" + std::to_string(getpid()) + ".yaml");
  std::ofstream(path) << robot;
  return path.string();
}

// Guards the negative: a body whose top is below a scan plane is not seen
// by it. Both Rob@Work 3 with their tops at 0.33 m, under the Husky's
// LMS151 at 0.35 m: the LMS151's beams pass over them (none reads their
// faces' range, though many are aimed at them) while the S300s at 0.178 m
// still see them. 20 s: the Husky passes raw3_a at about 14 s.
TEST(FleetVisibility, ABodyBelowAScanPlaneIsNotSeenByIt) {
  const std::string low = LowRaw3();
  models::Scene scene;
  const Recording rec =
      RunAndRecord(Shipped("fleet_line"),
                   {"robots.0.model=" + low, "robots.1.model=" + low, "duration_s=20"}, &scene);
  const Analysis a = Analyse(rec, scene);
  Print(a);
  for (const char* raw3 : {"raw3_a", "raw3_b"}) {
    const PairStats& over = a.pairs.at("husky.laser_front").at(raw3);
    EXPECT_FALSE(over.crosses) << raw3;
    EXPECT_GT(over.passing, 100) << raw3;
    EXPECT_EQ(over.read_anyway, 0) << raw3;
    EXPECT_EQ(over.interior, 0) << raw3;
  }
  // The S300s still see both (each other's) and the Husky.
  for (const auto& laser : rec.lasers) {
    if (laser.name.starts_with("husky.")) continue;
    for (const auto& [target, ps] : a.pairs.at(laser.name)) {
      if (!ps.crosses) continue;
      EXPECT_EQ(ps.seen, ps.interior) << laser.name << " " << target << ": " << ps.first_miss;
    }
  }
  EXPECT_GT(a.pairs.at("raw3_a.laser_front").at("husky").scans_seen, 0);
}

}  // namespace
}  // namespace linesim
