#pragma once
// Synthetic scenes and exact scans for the Perfect Match tests.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "models/scene.h"

namespace linesim::estimation::pmtest {

constexpr double kDeg = std::numbers::pi / 180.0;
// SICK LMS151 (operating instructions 8012471): 270 deg at 0.5 deg, 541
// beams from -135 deg, 50 Hz; statistical error 12 mm (1 sigma).
constexpr int kBeams = 541;
constexpr double kFirst = -135.0 * kDeg, kStep = 0.5 * kDeg, kPeriod = 0.02;
constexpr double kRangeMin = 0.5, kRangeMax = 50.0, kNoise = 0.012;

inline models::Obstacle Ob(const std::string& name, models::Solid s) { return {name, "wall", s}; }

// A 9.6 x 7.6 m room (walls' inner faces at x = +-4.8, y = +-3.8, 3 m high,
// 0.5 m thick: a pose error that moves points deeper into a solid than half
// its thickness pulls them out of its far face, see distance_map.h)
// with a pillar and boxes without symmetry, two of them turned; all cover
// the 0.35 m scan plane. Plus what must stay out of its 0.35 m map: a shelf
// above the plane and a carried object.
inline models::Scene Room() {
  models::Scene s;
  s.floor = {-5.3, 5.3, -4.3, 4.3, 0};
  s.obstacles = {Ob("north", models::BoxSolid(0.0, 4.05, 0.0, 10.6, 0.5, 3.0)),
                 Ob("south", models::BoxSolid(0.0, -4.05, 0.0, 10.6, 0.5, 3.0)),
                 Ob("west", models::BoxSolid(-5.05, 0.0, 0.0, 0.5, 8.6, 3.0)),
                 Ob("east", models::BoxSolid(5.05, 0.0, 0.0, 0.5, 8.6, 3.0)),
                 Ob("pillar", models::CylinderSolid(-2.5, -2.0, 0.25, 3.0)),
                 Ob("cart1", models::BoxSolid(3.2, -2.4, 0.3, 1.2, 0.8, 1.0)),
                 Ob("cart2", models::BoxSolid(-3.6, 2.6, 0.0, 1.2, 0.8, 1.0)),
                 Ob("cart3", models::BoxSolid(1.0, 2.5, 0.7, 0.6, 0.4, 1.0)),
                 Ob("shelf", models::BoxSolid(0.0, -1.0, 0.0, 1.0, 0.5, 0.3, 1.2))};
  s.carried.push_back({"body", 0, models::BoxSolid(-1.0, 1.0, 0.0, 1.0, 0.6, 1.0)});
  return s;
}

// The corners where the room's distance field is not linear (the inner
// room corners, the boxes' corners) and the cylinders (x, y, radius) that
// cover the plane z.
struct Features {
  std::vector<std::pair<double, double>> corners;
  std::vector<std::array<double, 3>> cylinders;
};
inline Features FeaturesOf(const std::vector<models::Solid>& solids) {
  Features f;
  for (const models::Solid& s : solids) {
    if (s.kind == models::Solid::Kind::kCylinder) {
      f.cylinders.push_back({s.x_m, s.y_m, s.radius_m});
      continue;
    }
    const double c = std::cos(s.yaw_rad), sn = std::sin(s.yaw_rad);
    for (const double a : {-0.5, 0.5}) {
      for (const double b : {-0.5, 0.5}) {
        const double u = a * s.length_m, v = b * s.width_m;
        f.corners.push_back({s.x_m + c * u - sn * v, s.y_m + sn * u + c * v});
      }
    }
  }
  // The room's inner corners (where two walls' faces meet).
  for (const double x : {-4.8, 4.8})
    for (const double y : {-3.8, 3.8}) f.corners.push_back({x, y});
  return f;
}

// The solids that cut the horizontal plane z.
inline std::vector<models::Solid> SolidsAt(const models::Scene& s, double z) {
  std::vector<models::Solid> out;
  for (const auto& o : s.obstacles) {
    if (z >= o.solid.bottom_m && z <= o.solid.bottom_m + o.solid.height_m) out.push_back(o.solid);
  }
  return out;
}

// Range from (x, y) along `heading` to the first solid (2D), +inf if none.
inline double Cast(const std::vector<models::Solid>& solids, double x, double y, double heading) {
  const double dx = std::cos(heading), dy = std::sin(heading);
  double best = std::numeric_limits<double>::infinity();
  for (const models::Solid& s : solids) {
    const double ox = x - s.x_m, oy = y - s.y_m;
    if (s.kind == models::Solid::Kind::kCylinder) {
      const double b = ox * dx + oy * dy, c = ox * ox + oy * oy - s.radius_m * s.radius_m;
      const double disc = b * b - c;
      if (disc < 0) continue;
      const double t = -b - std::sqrt(disc);
      if (t > 0) best = std::min(best, t);
      continue;
    }
    const double c = std::cos(s.yaw_rad), sn = std::sin(s.yaw_rad);
    const double o[2] = {c * ox + sn * oy, -sn * ox + c * oy};
    const double d[2] = {c * dx + sn * dy, -sn * dx + c * dy};
    const double half[2] = {0.5 * s.length_m, 0.5 * s.width_m};
    double t0 = -std::numeric_limits<double>::infinity();
    double t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 2; ++a) {
      if (d[a] == 0.0) {
        if (std::abs(o[a]) > half[a]) t0 = std::numeric_limits<double>::infinity();
        continue;
      }
      double ta = (-half[a] - o[a]) / d[a], tb = (half[a] - o[a]) / d[a];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    if (t0 <= t1 && t0 > 0) best = std::min(best, t0);
  }
  return best;
}

// An LMS151 scan's ranges from the laser at (x, y, heading of beam 0's
// frame), all beams from one pose; no return (0) beyond kRangeMax; with
// sigma > 0 Gaussian noise of that sigma added (and `bias`).
inline std::vector<double> Ranges(const std::vector<models::Solid>& solids, double x, double y,
                                  double yaw, double sigma = 0.0, std::mt19937_64* rng = nullptr,
                                  double bias = 0.0) {
  std::vector<double> r(kBeams, 0.0);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int i = 0; i < kBeams; ++i) {
    double d = Cast(solids, x, y, yaw + kFirst + i * kStep);
    if (!(d <= kRangeMax)) continue;
    if (sigma > 0.0) d += sigma * n(*rng);
    r[static_cast<std::size_t>(i)] = d + bias;
  }
  return r;
}

// The points (base_link) of a scan from a laser at base_link's origin.
struct Points {
  std::vector<double> x, y;
};
inline Points ToPoints(const std::vector<double>& r) {
  Points p;
  for (int i = 0; i < kBeams; ++i) {
    const double ri = r[static_cast<std::size_t>(i)];
    if (!(ri >= kRangeMin && ri <= kRangeMax)) continue;
    const double a = kFirst + i * kStep;
    p.x.push_back(ri * std::cos(a));
    p.y.push_back(ri * std::sin(a));
  }
  return p;
}

}  // namespace linesim::estimation::pmtest
