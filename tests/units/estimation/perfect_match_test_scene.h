#pragma once
// Synthetic scenes and exact scans for the Perfect Match tests.

#include <gtest/gtest.h>

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
#include "units/estimation/distance_map.h"
#include "units/estimation/perfect_match.h"
#include "units/estimation/scan_matcher.h"

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
  return f;
}
// Room's: its boxes' and cylinders' and its inner corners (where two
// walls' faces meet).
inline Features RoomFeatures(const std::vector<models::Solid>& solids) {
  Features f = FeaturesOf(solids);
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

namespace linesim::estimation::pmtest {

// The van bay of paper 2's use case (Sobreira et al. 2019; dimensions of a
// Renault Master L2H2 class van: load length 3.1 m, width 1.765 m, load
// floor 0.54 m): a factory hall (x -6..10, y -5..5, 0.3 m walls), a few
// carts and a pillar off the corridor, the van (cargo interior x 4.0..7.1,
// |y| < 0.8825, 5 cm side and front walls from z 0.30 to 2.44, wheel arches
// up to 0.82, four beacon cylinders r 0.04 m from the floor 0.54 to 1.34),
// its floor slab (terrain, z 0.30..0.54) and a 2 m ramp (terrain, 15.1 deg).
inline models::Scene VanBay() {
  models::Scene s;
  s.floor = {-6.0, 10.0, -5.0, 5.0, 0};
  const auto box = [](double x, double y, double l, double w, double bottom, double top) {
    return models::BoxSolid(x, y, 0.0, l, w, top - bottom, bottom);
  };
  s.obstacles = {Ob("hall_n", box(2.0, 4.85, 16.0, 0.3, 0.0, 4.0)),
                 Ob("hall_s", box(2.0, -4.85, 16.0, 0.3, 0.0, 4.0)),
                 Ob("hall_w", box(-5.85, 0.0, 0.3, 10.0, 0.0, 4.0)),
                 Ob("hall_e", box(9.85, 0.0, 0.3, 10.0, 0.0, 4.0)),
                 Ob("cart", box(-4.0, 3.0, 1.2, 0.8, 0.0, 1.0)),
                 Ob("rack", box(8.0, 3.5, 2.0, 0.6, 0.0, 2.0)),
                 Ob("pillar", models::CylinderSolid(1.0, -3.5, 0.25, 4.0)),
                 Ob("van_left", box(5.55, 0.9075, 3.1, 0.05, 0.30, 2.44)),
                 Ob("van_right", box(5.55, -0.9075, 3.1, 0.05, 0.30, 2.44)),
                 Ob("van_front", box(7.125, 0.0, 0.05, 1.865, 0.30, 2.44)),
                 Ob("arch_left", box(5.1, 0.78625, 0.7, 0.1925, 0.54, 0.82)),
                 Ob("arch_right", box(5.1, -0.78625, 0.7, 0.1925, 0.54, 0.82)),
                 Ob("beacon1", models::CylinderSolid(6.0, 0.75, 0.04, 0.8, 0.54)),
                 Ob("beacon2", models::CylinderSolid(6.0, -0.75, 0.04, 0.8, 0.54)),
                 Ob("beacon3", models::CylinderSolid(6.95, 0.75, 0.04, 0.8, 0.54)),
                 Ob("beacon4", models::CylinderSolid(6.95, -0.75, 0.04, 0.8, 0.54))};
  for (auto& o : s.obstacles) {
    if (o.name.rfind("van", 0) == 0) o.kind = "vehicle";
    if (o.name.rfind("beacon", 0) == 0) o.kind = "beacon";
  }
  models::TerrainPiece floor;
  floor.name = "van_floor";
  floor.center_x_m = 5.55;
  floor.center_z_m = 0.42;
  floor.length_m = 3.1;
  floor.width_m = 1.765;
  floor.thickness_m = 0.24;
  s.terrain.push_back(floor);
  // The ramp's top face from (2.0, z 0) to (4.0, z 0.54), 5 cm thick.
  models::TerrainPiece ramp;
  ramp.name = "ramp";
  ramp.pitch_rad = std::atan2(0.54, 2.0);
  ramp.length_m = std::hypot(2.0, 0.54);
  ramp.width_m = 1.2;
  ramp.thickness_m = 0.05;
  ramp.center_x_m = 3.0 + 0.025 * std::sin(ramp.pitch_rad);
  ramp.center_z_m = 0.27 - 0.025 * std::cos(ramp.pitch_rad);
  s.terrain.push_back(ramp);
  return s;
}

}  // namespace linesim::estimation::pmtest

namespace linesim::estimation::pmtest {

// The first-order bound on the pose error a map error delta_i at each
// point gives: the weighted least-squares shift e = A^-1 sum u J delta with
// A = sum u J J^T (u <= 1) obeys |e_j| <= sqrt((A^-1)_jj sum delta_i^2)
// (Cauchy-Schwarz in the metric of A). Per point, delta_i is bounded from
// the lookup grid h (distance_map.h): 0 on a straight face (d linear over
// the 2 x 2 nodes, which lie within sqrt(2) h of the point: true when the
// point is more than 2 sqrt(2) h, taken 3 h, from any corner: the medial
// axis leaves a corner at 45 deg); sqrt(2) h within 3 h of a corner (d is
// 1-Lipschitz and the interpolant a convex combination of nodes within
// sqrt(2) h); h^2 / (4 (R - sqrt(2) h)) on a cylinder of radius R (the
// bilinear error (h^2 / 8)(|d_xx| + |d_yy|), |d''| <= 1 / rho); plus 1e-6 m
// for the float tables.
inline std::array<double, 3> PoseErrorBound(const Features& f, const Points& p,
                                            const PerfectMatch::Pose& truth,
                                            const std::array<double, 9>& hessian, double h,
                                            double c, const DistanceMap* measured = nullptr) {
  double sum = 0.0;
  const double cs = std::cos(truth.yaw), sn = std::sin(truth.yaw);
  for (std::size_t i = 0; i < p.x.size(); ++i) {
    const double x = truth.x + cs * p.x[i] - sn * p.y[i];
    const double y = truth.y + sn * p.x[i] + cs * p.y[i];
    double e = 1e-6;
    for (const auto& [cx, cy] : f.corners) {
      if (std::hypot(x - cx, y - cy) < 3.0 * h) e = std::max(e, std::sqrt(2.0) * h);
    }
    for (const auto& cyl : f.cylinders) {
      if (std::abs(std::hypot(x - cyl[0], y - cyl[1]) - cyl[2]) < 1e-6) {
        // (R <= sqrt(2) h: only the Lipschitz bound.)
        const double den = cyl[2] - std::sqrt(2.0) * h;
        e = std::max(
            e, den > 0.0 ? std::min(h * h / (4.0 * den), std::sqrt(2.0) * h) : std::sqrt(2.0) * h);
      }
    }
    if (measured) {
      double gx, gy;
      const double delta = measured->Lookup(x, y, gx, gy) - measured->ExactDistance(x, y);
      if (!(std::abs(delta) <= e)) {
        ADD_FAILURE() << "map error " << delta << " beyond its grid bound " << e << " at " << x
                      << ", " << y;
      }
      e = std::abs(delta) + 1e-6;
    }
    sum += e * e;
  }
  // A = (c^2 / 2) H.
  const std::array<double, 6> a = {hessian[0], hessian[1], hessian[2],
                                   hessian[4], hessian[5], hessian[8]};
  std::array<double, 9> inv{};
  EXPECT_TRUE(InverseSymmetric3(a, inv));
  const double k = 2.0 / (c * c);  // H = (2 / c^2) A: A^-1 = (2 / c^2) H^-1
  return {std::sqrt(sum * inv[0] * k), std::sqrt(sum * inv[4] * k), std::sqrt(sum * inv[8] * k)};
}

}  // namespace linesim::estimation::pmtest
