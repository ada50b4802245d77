// hector_mapping's Gauss-Newton scan matcher (units/estimation/scan_matcher.h)
// on synthetic scans ray-cast analytically (here, in 2D) against a known map.
#include "units/estimation/scan_matcher.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "tests/spread.h"

namespace linesim::estimation {

// The test scene, shared with laser_localization_test.cc (declared there).
namespace testscene {

constexpr double kHalfX = 4.8, kHalfY = 3.8;  // the walls' inner faces

models::Floor RoomFloor() { return {-5.0, 5.0, -4.0, 4.0, 0}; }

// A 10 x 8 m room: walls 0.2 m thick on its edges.
std::vector<models::Solid> EmptyRoom() {
  return {models::BoxSolid(0.0, 3.9, 0.0, 10.0, 0.2, 3.0),
          models::BoxSolid(0.0, -3.9, 0.0, 10.0, 0.2, 3.0),
          models::BoxSolid(-4.9, 0.0, 0.0, 0.2, 8.0, 3.0),
          models::BoxSolid(4.9, 0.0, 0.0, 0.2, 8.0, 3.0)};
}

// The room with pillars (r 0.25 m) and carts, placed without symmetry.
std::vector<models::Solid> Room() {
  auto s = EmptyRoom();
  s.push_back(models::CylinderSolid(-2.5, -2.0, 0.25, 3.0));
  s.push_back(models::CylinderSolid(2.8, 2.2, 0.25, 3.0));
  s.push_back(models::BoxSolid(3.2, -2.4, 0.3, 1.2, 0.8, 1.0));
  s.push_back(models::BoxSolid(-3.6, 2.6, 0.0, 1.2, 0.8, 1.0));
  return s;
}

// Range from (x, y) along `heading` to the first solid (2D, the scan
// plane), +inf when none.
double Cast(const std::vector<models::Solid>& solids, double x, double y, double heading) {
  const double dx = std::cos(heading), dy = std::sin(heading);
  double best = std::numeric_limits<double>::infinity();
  for (const models::Solid& s : solids) {
    const double ox = x - s.x_m, oy = y - s.y_m;
    if (s.kind == models::Solid::Kind::kCylinder) {
      // |o + t d|^2 = R^2: t^2 + 2 (o.d) t + |o|^2 - R^2 = 0, the nearer root.
      const double b = ox * dx + oy * dy, c = ox * ox + oy * oy - s.radius_m * s.radius_m;
      const double disc = b * b - c;
      if (disc < 0) continue;
      const double t = -b - std::sqrt(disc);
      if (t > 0) best = std::min(best, t);
      continue;
    }
    // Slabs in the box's frame.
    const double c = std::cos(s.yaw_rad), sn = std::sin(s.yaw_rad);
    const double o[2] = {c * ox + sn * oy, -sn * ox + c * oy};
    const double d[2] = {c * dx + sn * dy, -sn * dx + c * dy};
    const double half[2] = {0.5 * s.length_m, 0.5 * s.width_m};
    double t0 = -std::numeric_limits<double>::infinity(),
           t1 = std::numeric_limits<double>::infinity();
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

}  // namespace testscene

namespace {

using testscene::Cast;
using testscene::Room;

constexpr double kDeg = std::numbers::pi / 180.0;

struct Points {
  std::vector<double> x, y;
};

// A 541-beam, 270 deg scan (SICK S300 geometry, operating instructions
// 8010948) from the base pose (x, y, yaw), laser at the base origin, ranges
// exact (noise_sigma 0) or with N(0, noise) added; points in base_link.
Points Scan(const std::vector<models::Solid>& solids, double x, double y, double yaw,
            double noise = 0.0, std::uint64_t seed = 1) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  Points p;
  for (int i = 0; i < 541; ++i) {
    const double a = -135.0 * kDeg + i * 0.5 * kDeg;
    double r = Cast(solids, x, y, yaw + a);
    if (!std::isfinite(r) || r > 29.5) continue;
    if (noise > 0) r += noise * n(rng);
    p.x.push_back(r * std::cos(a));
    p.y.push_back(r * std::sin(a));
  }
  return p;
}

ScanMatcher::Result Match(const OccupancyGrid& g, const Points& p, ScanMatcher::Pose start) {
  const ScanMatcher m(g, {});
  return m.Match(p.x, p.y, start);
}

// Guards against the matcher not recovering a known offset (5 cm, 3 cm,
// 2 deg). Bound: with exact ranges every point on a straight face has zero
// residual at the truth (the profile is reproduced exactly, see
// occupancy_grid.h), the pillars' faces are off by at most cell^2 / (4 R)
// = 0.6 mm, and the early exit leaves an update below 0.1 mm: 1 mm and
// 1 mrad.
TEST(ScanMatcher, RecoversAKnownOffset) {
  const auto solids = Room();
  const OccupancyGrid g(solids, testscene::RoomFloor(), {});
  const double tx = 1.3, ty = -0.7, tyaw = 0.4;
  const Points p = Scan(solids, tx, ty, tyaw);
  ASSERT_GT(p.x.size(), 500u);
  const auto r = Match(g, p, {tx + 0.05, ty + 0.03, tyaw + 2.0 * kDeg});
  EXPECT_TRUE(r.solved);
  EXPECT_NEAR(r.pose.x, tx, 1e-3);
  EXPECT_NEAR(r.pose.y, ty, 1e-3);
  EXPECT_NEAR(r.pose.yaw, tyaw, 1e-3);
  EXPECT_EQ(r.points, static_cast<int>(p.x.size()));
  EXPECT_LT(r.cost, 1e-3);
  // Larger: 15 cm and 8 deg, inside the coarse level's basin (w = 0.2 m).
  const auto r2 = Match(g, p, {tx - 0.15, ty + 0.1, tyaw - 8.0 * kDeg});
  EXPECT_NEAR(r2.pose.x, tx, 1e-3);
  EXPECT_NEAR(r2.pose.y, ty, 1e-3);
  EXPECT_NEAR(r2.pose.yaw, tyaw, 1e-3);
}

// Guards against a biased or unstable match under range noise (15 mm, the
// S300 model's noise_sigma). Bound: the covariance sigma^2 (sum n n^T)^-1
// with over 100 points on faces of each direction gives sigma_pos <= 1.5
// mm; 4 sigma = 6 mm, and the yaw from points 1-5 m away 4 mrad. The cost
// is the mean of (d / w)^2, w = 0.05 m, over the points' distances d to
// their faces: the range noise (15 mm) along the beam puts a point
// d = n cos(i) off a face met at incidence i, so its expectation is
// (0.015 / 0.05)^2 = 0.09 times the mean cos^2 i over the beams, at most
// 0.09 (over 500 points the sampling adds sqrt(2 / 500) = 6 %: 0.09 x
// 1.25 is 4 of those); a profile width off by a factor 2 (a cost 4 times
// smaller) falls below 0.09 / 4. Seeds 1..8: position error (x and y)
// -0.0012 / -0.0003 / 0.0023 m; yaw error -0.00029 / 0.00010 / 0.00024 rad;
// cost 0.0619 / 0.0658 / 0.0734 (a mean cos^2 i of about 0.73).
TEST(ScanMatcher, RecoversTheOffsetUnderRangeNoise) {
  const auto solids = Room();
  const OccupancyGrid g(solids, testscene::RoomFloor(), {});
  const double tx = -2.1, ty = 1.4, tyaw = -2.5;
  std::vector<double> pos, yaw, cost;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    const Points p = Scan(solids, tx, ty, tyaw, 0.015, seed);
    const auto r = Match(g, p, {tx + 0.05, ty + 0.03, tyaw + 2.0 * kDeg});
    pos.push_back(r.pose.x - tx);
    pos.push_back(r.pose.y - ty);
    yaw.push_back(r.pose.yaw - tyaw);
    cost.push_back(r.cost);
  }
  EXPECT_LT(test_spread::Print("position error (m)", pos).max_abs(), 6e-3);
  EXPECT_LT(test_spread::Print("yaw error (rad)", yaw).max_abs(), 4e-3);
  const auto c = test_spread::Print("cost", cost);
  EXPECT_GT(c.min(), 0.09 / 4);
  EXPECT_LT(c.max(), 0.09 * 1.25);
}

// Guards against a car body (a models::CarriedObject box: in the scan, not
// in the map) pulling the match away. Its faces are more than w (0.2 m on
// the coarse level) plus the offset from every map face, so its points
// read M = 0 with zero gradient and do not move the match: the same bound
// as without it (1 mm, 1 mrad). The cost rises by their share of r^2 = 1.
TEST(ScanMatcher, IgnoresACarBodyNotInTheMap) {
  const auto solids = Room();
  const OccupancyGrid g(solids, testscene::RoomFloor(), {});
  auto seen = solids;
  seen.push_back(models::BoxSolid(0.0, 1.6, 0.0, 4.6, 1.8, 1.2, 0.3));  // a sedan body
  const double tx = 0.5, ty = -1.0, tyaw = 1.2;
  const Points p = Scan(seen, tx, ty, tyaw);
  const auto r = Match(g, p, {tx + 0.05, ty + 0.03, tyaw + 2.0 * kDeg});
  EXPECT_NEAR(r.pose.x, tx, 1e-3);
  EXPECT_NEAR(r.pose.y, ty, 1e-3);
  EXPECT_NEAR(r.pose.yaw, tyaw, 1e-3);
  EXPECT_GT(r.cost, 0.1);  // a good share of the beams hits the body
  EXPECT_LT(r.points_on_map, r.points);
}

// Guards against the Hessian not in SI: on a room of axis-aligned walls
// each point on a face normal to x adds grad M = (1 / w, 0) to H_xx, so
// H_xx w^2 counts those points (and H_yy the y ones), up to the points
// within about w of a corner, where the union's profile is not linear
// (under 5 % of the scan). H is symmetric.
TEST(ScanMatcher, HessianIsInSiUnits) {
  const auto solids = testscene::EmptyRoom();
  const OccupancyGrid g(solids, testscene::RoomFloor(), {});
  const double tx = 0.7, ty = 0.4, tyaw = 0.0;
  const Points p = Scan(solids, tx, ty, tyaw);
  int on_x = 0, on_y = 0;
  for (std::size_t i = 0; i < p.x.size(); ++i) {
    const double mx = tx + p.x[i], my = ty + p.y[i];
    (std::abs(std::abs(mx) - testscene::kHalfX) < 1e-6 ? on_x : on_y) += 1;
    (void)my;
  }
  const auto r = Match(g, p, {tx, ty, tyaw});
  const double w = g.level(0).w;
  EXPECT_NEAR(r.hessian[0] * w * w, on_x, 0.05 * p.x.size());
  EXPECT_NEAR(r.hessian[4] * w * w, on_y, 0.05 * p.x.size());
  EXPECT_EQ(r.hessian[1], r.hessian[3]);
  EXPECT_EQ(r.hessian[2], r.hessian[6]);
  EXPECT_EQ(r.hessian[5], r.hessian[7]);
  // H_yaw,yaw = sum ((-ry, rx) . grad M)^2: points metres away, order N m^2 / w^2.
  EXPECT_GT(r.hessian[8] * w * w, 0.5 * p.x.size());
}

// Guards against the 3 x 3 solver: a known system and a singular one.
TEST(ScanMatcher, SolvesSymmetricSystems) {
  // H = [[4, 2, 0], [2, 3, 1], [0, 1, 2]], x = (1, -1, 2): b = H x.
  const std::array<double, 6> h{4, 2, 0, 3, 1, 2};
  std::array<double, 3> x{};
  ASSERT_TRUE(SolveSymmetric3(h, {2, 1, 3}, x));
  EXPECT_NEAR(x[0], 1.0, 1e-12);
  EXPECT_NEAR(x[1], -1.0, 1e-12);
  EXPECT_NEAR(x[2], 2.0, 1e-12);
  EXPECT_FALSE(SolveSymmetric3({1, 1, 0, 1, 0, 1}, {1, 1, 1}, x));  // rank 2
  std::array<double, 9> inv{};
  ASSERT_TRUE(InverseSymmetric3(h, inv));
  // H H^-1 = I, first row.
  EXPECT_NEAR(4 * inv[0] + 2 * inv[3] + 0 * inv[6], 1.0, 1e-12);
  EXPECT_NEAR(4 * inv[1] + 2 * inv[4] + 0 * inv[7], 0.0, 1e-12);
}

}  // namespace
}  // namespace linesim::estimation
