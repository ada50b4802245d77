// Perfect Match (units/estimation/perfect_match.h) and its distance map
// (distance_map.h) on synthetic rooms with exact and noisy LMS151 scans.
#include "units/estimation/perfect_match.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "tests/spread.h"
#include "tests/units/estimation/perfect_match_test_scene.h"
#include "units/estimation/distance_map.h"
#include "units/estimation/scan_matcher.h"

namespace linesim::estimation {
namespace {

using namespace pmtest;  // NOLINT

// Seeds of the statistical tests: each must pass; the spreads quoted are
// min / median / max over them.
constexpr std::uint64_t kSeeds = 8;

class RecoversOffset : public ::testing::TestWithParam<double> {};

// Guards against PM not recovering a known offset (0.1 m, 0.05 m,
// 0.05 rad) from an exact scan, on the default 20 mm grid and Tribots'
// 50 mm one, within the bound above (+ 1e-5 for the Gauss-Newton end).
TEST_P(RecoversOffset, WithinTheLookupGridsBound) {
  const double h = GetParam();
  const models::Scene scene = Room();
  const auto solids = SolidsAt(scene, 0.35);
  const DistanceMap map(scene, 0.35, std::nullopt, {h, 1.0, 4.0, {}});
  const PerfectMatch::Pose truth{1.3, -0.7, 0.4};
  const Points p = ToPoints(Ranges(solids, truth.x, truth.y, truth.yaw));
  ASSERT_GT(p.x.size(), 500u);
  const PerfectMatch pm({});
  const auto r = pm.Match(map, p.x, p.y, {truth.x + 0.1, truth.y + 0.05, truth.yaw + 0.05});
  ASSERT_TRUE(r.ok);
  const auto b = PoseErrorBound(RoomFeatures(solids), p, truth, r.hessian, h, 0.25);
  RecordProperty("bound_x_mm", std::to_string(b[0] * 1e3));
  // Tighter, with the map's actual error delta_i = D(q_i) - d(q_i) at the
  // true points (each within its grid bound) in the same propagation.
  const auto t = PoseErrorBound(RoomFeatures(solids), p, truth, r.hessian, h, 0.25, &map);
  std::printf("h %.3f: tight bound %.4f %.4f mm %.4f mrad\n", h, t[0] * 1e3, t[1] * 1e3,
              t[2] * 1e3);
  EXPECT_NEAR(r.pose.x, truth.x, t[0] + 1e-5);
  EXPECT_NEAR(r.pose.y, truth.y, t[1] + 1e-5);
  EXPECT_NEAR(r.pose.yaw, truth.yaw, t[2] + 1e-5);
  EXPECT_NEAR(r.pose.x, truth.x, b[0] + 1e-5);
  EXPECT_NEAR(r.pose.y, truth.y, b[1] + 1e-5);
  EXPECT_NEAR(r.pose.yaw, truth.yaw, b[2] + 1e-5);
  EXPECT_EQ(r.points, static_cast<int>(p.x.size()));
  EXPECT_EQ(r.points_on_map, r.points);
  // Every point on an outline: E ~ 0, each weight ~ 1.
  EXPECT_LT(r.mean_error, 1e-3);
  EXPECT_GT(r.inlier_weight, 0.99 * r.points);
  std::printf("h %.3f: error %.4f %.4f mm %.4f mrad, bound %.4f %.4f mm %.4f mrad\n", h,
              (r.pose.x - truth.x) * 1e3, (r.pose.y - truth.y) * 1e3,
              (r.pose.yaw - truth.yaw) * 1e3, b[0] * 1e3, b[1] * 1e3, b[2] * 1e3);
}

INSTANTIATE_TEST_SUITE_P(Grids, RecoversOffset, ::testing::Values(0.02, 0.05));

// Guards rprop_stride: RPROP on every second point, the refinement on all,
// ends at the same optimum as RPROP on all (within the tight bound of the
// 20 mm grid above, 0.5 mm / 0.15 mrad), from the same offset start and from
// a noisy LMS151-like scan (12 mm statistical error, 8012471).
TEST(PerfectMatch, RpropOnEverySecondPointEndsWhereAllPointsDo) {
  const models::Scene scene = Room();
  const auto solids = SolidsAt(scene, 0.35);
  const DistanceMap map(scene, 0.35, std::nullopt, {0.02, 1.0, 4.0, {}});
  const PerfectMatch::Pose truth{1.3, -0.7, 0.4};
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.012);
  auto ranges = Ranges(solids, truth.x, truth.y, truth.yaw);
  for (double& r : ranges) r += noise(rng);
  const Points p = ToPoints(ranges);
  PerfectMatch::Options strided;
  strided.rprop_stride = 2;
  const PerfectMatch::Pose start{truth.x + 0.1, truth.y + 0.05, truth.yaw + 0.05};
  const auto all = PerfectMatch({}).Match(map, p.x, p.y, start);
  const auto half = PerfectMatch(strided).Match(map, p.x, p.y, start);
  ASSERT_TRUE(all.ok && half.ok);
  EXPECT_NEAR(half.pose.x, all.pose.x, 5e-4);
  EXPECT_NEAR(half.pose.y, all.pose.y, 5e-4);
  EXPECT_NEAR(half.pose.yaw, all.pose.yaw, 1.5e-4);
  std::printf("stride 2 vs 1: %.4f %.4f mm %.4f mrad\n", (half.pose.x - all.pose.x) * 1e3,
              (half.pose.y - all.pose.y) * 1e3, (half.pose.yaw - all.pose.yaw) * 1e3);
}

// Tribots' RPROP alone (refine_iterations 0) ends within about its last
// steps of the optimum, not at it: the reason for the refinement. Guards
// against the RPROP of Tribots (40 mm, 0.1 rad, x 1.2 / x 0.5, 10
// iterations) being broken: from the same start it must end nearer than
// it started, within 40 mm of the optimum (its first step), and the
// refinement must not end farther than RPROP alone.
TEST(PerfectMatch, RpropAloneEndsNearTheOptimumAndTheRefinementAtIt) {
  const models::Scene scene = Room();
  const auto solids = SolidsAt(scene, 0.35);
  const DistanceMap map(scene, 0.35, std::nullopt, {0.02, 1.0, 4.0, {}});
  const PerfectMatch::Pose truth{1.3, -0.7, 0.4};
  const Points p = ToPoints(Ranges(solids, truth.x, truth.y, truth.yaw));
  PerfectMatch::Options o;
  o.refine_iterations = 0;
  const auto r0 = PerfectMatch(o).Match(map, p.x, p.y, {truth.x + 0.1, truth.y + 0.05, 0.45});
  const auto r2 = PerfectMatch({}).Match(map, p.x, p.y, {truth.x + 0.1, truth.y + 0.05, 0.45});
  EXPECT_EQ(r0.iterations, 10);  // Tribots: 10 with more than 20 points
  const double e0 = std::hypot(r0.pose.x - truth.x, r0.pose.y - truth.y);
  const double e2 = std::hypot(r2.pose.x - truth.x, r2.pose.y - truth.y);
  std::printf(
      "RPROP alone: %.3f mm %.3f mrad (last steps %.3f %.3f mm %.3f mrad); refined %.4f mm\n",
      e0 * 1e3, (r0.pose.yaw - truth.yaw) * 1e3, r0.final_steps[0] * 1e3, r0.final_steps[1] * 1e3,
      r0.final_steps[2] * 1e3, e2 * 1e3);
  EXPECT_LT(e0, 0.04);
  EXPECT_LE(e2, e0);
  // 20 iterations with 20 points or fewer (Tribots).
  const Points few{{p.x.begin(), p.x.begin() + 20}, {p.y.begin(), p.y.begin() + 20}};
  EXPECT_EQ(PerfectMatch(o).Match(map, few.x, few.y, truth).iterations, 20);
}

// The error and its gradient: E = sum 1 - c^2 / (c^2 + d^2) (Lauer et al.
// 2005) against the map's d at each point; the gradient against central
// differences of E (a straight-face pose, E smooth there).
TEST(PerfectMatch, ErrorAndGradientAreLauersFunction) {
  const models::Scene scene = Room();
  const DistanceMap map(scene, 0.35, std::nullopt, {0.02, 1.0, 4.0, {}});
  const std::vector<double> px = {2.0, 1.0, -0.5}, py = {0.3, -1.2, 0.9};
  const PerfectMatch pm({});
  const PerfectMatch::Pose at{0.5, 0.2, 0.3};
  std::array<double, 3> g{};
  const double e = pm.Error(map, px, py, at, g);
  double expect = 0.0;
  for (std::size_t i = 0; i < 3; ++i) {
    const double x = at.x + std::cos(at.yaw) * px[i] - std::sin(at.yaw) * py[i];
    const double y = at.y + std::sin(at.yaw) * px[i] + std::cos(at.yaw) * py[i];
    double gx, gy;
    const double d = map.Lookup(x, y, gx, gy);
    expect += 1.0 - 0.0625 / (0.0625 + d * d);
  }
  EXPECT_NEAR(e, expect, 1e-12);
  const double step[3] = {1e-5, 1e-5, 1e-6};
  for (int j = 0; j < 3; ++j) {
    PerfectMatch::Pose lo = at, hi = at;
    double* l = j == 0 ? &lo.x : j == 1 ? &lo.y : &lo.yaw;
    double* u = j == 0 ? &hi.x : j == 1 ? &hi.y : &hi.yaw;
    *l -= step[j];
    *u += step[j];
    std::array<double, 3> dummy{};
    const double num =
        (pm.Error(map, px, py, hi, dummy) - pm.Error(map, px, py, lo, dummy)) / (2.0 * step[j]);
    // The gradient table is the nodes' central differences, interpolated:
    // equal to the interpolant's derivative where d is linear.
    EXPECT_NEAR(g[static_cast<std::size_t>(j)], num, 1e-3 * (1.0 + std::abs(num))) << j;
  }
}

// The distance map's nodes: within the band (4 cells) exactly the signed
// distance to the outlines (float); beyond it the EDT of the occupied cell
// centres minus h / 2. Bound for the latter: the centres lie inside the
// solids, so EDT >= d; and every outline point of a convex solid at least
// two cells thick has an occupied centre within sqrt(2) h (plus the sag
// h^2 / R of a cylinder's outline of radius R over a cell), so
// EDT <= d + sqrt(2) h + h^2 / R: EDT - h / 2 - d in
// [-h / 2, (sqrt(2) - 1 / 2) h + h^2 / R], R = 0.25 m the pillar.
// What is in it: the shelf above the plane and the carried body are not.
TEST(DistanceMap, HoldsTheSignedDistanceToTheSlice) {
  const models::Scene scene = Room();
  const double h = 0.05;
  const DistanceMap map(scene, 0.35, std::nullopt, {h, 1.0, 4.0, {}});
  EXPECT_EQ(map.solids().size(), 8u);  // 4 walls, pillar, 3 carts: no shelf, no body
  double worst_band = 0.0, worst_far = 0.0;
  for (int iy = 0; iy < map.ny(); ++iy) {
    for (int ix = 0; ix < map.nx(); ++ix) {
      const double x = map.origin_x() + (ix + 0.5) * h, y = map.origin_y() + (iy + 0.5) * h;
      const double exact = map.ExactDistance(x, y);
      const double d = map.NodeDistance(ix, iy);
      if (std::abs(exact) < 4.0 * h - 1e-9) {
        worst_band = std::max(worst_band, std::abs(d - exact));
      } else if (exact > 0.0) {
        worst_far = std::max(worst_far, std::abs(d - exact));
      }
    }
  }
  EXPECT_LT(worst_band, 1e-6);
  std::printf("h %.3f: band nodes worst %.2e m, far nodes worst %.4f m\n", h, worst_band,
              worst_far);
  EXPECT_LE(worst_far, (std::sqrt(2.0) - 0.5) * h + h * h / 0.25);
  // The carried body's place (-1, 1) is free: the map reads a distance to
  // another solid there, not 0.
  EXPECT_GT(map.ExactDistance(-1.0, 1.0), 0.5);
  double gx, gy;
  EXPECT_GT(map.Lookup(-1.0, 1.0, gx, gy), 0.5);
  // Off the grid: far, no gradient.
  EXPECT_EQ(map.Lookup(50.0, 0.0, gx, gy), DistanceMap::kFar);
  EXPECT_EQ(gx, 0.0);
}

// A ramp (terrain piece tilted 15 deg about its width axis) sliced at
// z: by geometry the box's points satisfy |u| <= L/2, |w| <= T/2 with
// u = (x - cx) cos p + (z - cz) sin p, w = -(x - cx) sin p + (z - cz) cos p
// (+ pitch raises the far end: models::TerrainPiece), |y - cy| <= W/2; at
// fixed z each is an interval of x, the slice their intersection.
TEST(DistanceMap, SliceOfATiltedTerrainBoxIsWhereGeometrySaysIt) {
  models::TerrainPiece t;
  t.name = "ramp";
  t.center_x_m = 3.0;
  t.center_y_m = 0.2;
  t.center_z_m = 0.25;
  t.length_m = 2.07;
  t.width_m = 1.2;
  t.thickness_m = 0.1;
  t.pitch_rad = 15.0 * kDeg;
  const double z = 0.35;
  const double cp = std::cos(t.pitch_rad), sp = std::sin(t.pitch_rad), dz = z - t.center_z_m;
  // u in [-L/2, L/2]: x - cx in [(-L/2 - dz sp) / cp, (L/2 - dz sp) / cp]
  // w in [-T/2, T/2]: x - cx in [(dz cp - T/2) / sp, (dz cp + T/2) / sp]
  const double lo =
      std::max((-0.5 * t.length_m - dz * sp) / cp, (dz * cp - 0.5 * t.thickness_m) / sp);
  const double hi =
      std::min((0.5 * t.length_m - dz * sp) / cp, (dz * cp + 0.5 * t.thickness_m) / sp);
  const auto poly = DistanceMap::TerrainSlice(t, z);
  ASSERT_GE(poly.size(), 4u);
  double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
  for (const auto& q : poly) {
    x0 = std::min(x0, q[0]);
    x1 = std::max(x1, q[0]);
    y0 = std::min(y0, q[1]);
    y1 = std::max(y1, q[1]);
  }
  EXPECT_NEAR(x0, t.center_x_m + lo, 1e-12);
  EXPECT_NEAR(x1, t.center_x_m + hi, 1e-12);
  EXPECT_NEAR(y0, t.center_y_m - 0.6, 1e-12);
  EXPECT_NEAR(y1, t.center_y_m + 0.6, 1e-12);
  // Above the ramp's top: no slice.
  EXPECT_TRUE(DistanceMap::TerrainSlice(t, 1.0).empty());
  // In a map: the slice's faces are where d = 0, d in free space is the
  // distance to them (in the exact band, interpolated: linear, exact).
  models::Scene s;
  s.floor = {0.0, 6.0, -2.0, 2.0, 0};
  s.terrain.push_back(t);
  const DistanceMap map(s, z, std::nullopt, {0.02, 0.5, 4.0, {}});
  EXPECT_EQ(map.terrain_count(), 1u);
  double gx, gy;
  EXPECT_NEAR(map.Lookup(t.center_x_m + hi + 0.03, 0.2, gx, gy), 0.03, 1e-6);
  EXPECT_NEAR(gx, 1.0, 1e-5);
  EXPECT_NEAR(map.Lookup(t.center_x_m + lo - 0.02, 0.2, gx, gy), 0.02, 1e-6);
  EXPECT_NEAR(map.Lookup(0.5 * (2 * t.center_x_m + lo + hi), 0.2 + 0.6 + 0.04, gx, gy), 0.04, 1e-6);
  EXPECT_LT(map.Lookup(t.center_x_m + 0.5 * (lo + hi), 0.2, gx, gy), 0.0);  // inside
  // A region that does not hold the slice leaves it out.
  const DistanceMap none(s, z, DistanceMap::Region{0.0, 2.0, -2.0, 2.0}, {0.02, 0.5, 4.0, {}});
  EXPECT_EQ(none.terrain_count(), 0u);
}

// Guards Options::seen_from (a van's 5 cm wall seen from inside only): a
// closed box room of 5 cm walls, x 0..2, y -1..1. Without it the wall's
// inside is minus the distance to the NEARER face, so d rises again towards
// the outer face (a second minimum 5 cm out); seen from inside, d keeps
// falling through the wall (minus the distance to the inner face: 0.04 m at
// 4 cm in, within the 1 cm EDT of cell centres) and stays negative beyond.
TEST(DistanceMap, SeenFromInsideAThinWallHasOneFace) {
  models::Scene s;
  s.floor = {-1.0, 3.0, -2.0, 2.0, 0};
  const auto wall = [&](double x, double y, double yaw, double length) {
    s.obstacles.push_back({"w", "wall", models::BoxSolid(x, y, yaw, length, 0.05, 2.0)});
  };
  wall(1.0, 1.025, 0.0, 2.1);
  wall(1.0, -1.025, 0.0, 2.1);
  wall(2.025, 0.0, 0.5 * std::numbers::pi, 2.0);
  wall(-0.025, 0.0, 0.5 * std::numbers::pi, 2.0);
  const DistanceMap both(s, 0.35, std::nullopt, {0.01, 0.5, 4.0, {}});
  const DistanceMap seen(s, 0.35, DistanceMap::Region{-0.2, 2.2, -1.2, 1.2},
                         {0.01, 0.5, 4.0, std::array<double, 2>{1.0, 0.0}});
  double gx, gy;
  // Inside the room both read the distance to the wall's inner face.
  EXPECT_NEAR(both.Lookup(1.97, 0.0, gx, gy), 0.03, 1e-6);
  EXPECT_NEAR(seen.Lookup(1.97, 0.0, gx, gy), 0.03, 1e-6);
  // 4 cm into the 5 cm wall: 1 cm from its outer face.
  EXPECT_NEAR(both.Lookup(2.04, 0.0, gx, gy), -0.01, 2e-3);
  EXPECT_NEAR(seen.Lookup(2.04, 0.0, gx, gy), -0.04, 6e-3);
  EXPECT_LT(gx, 0.0);  // pulled back in, towards the seen face
  // Beyond the wall: free space for one, never-seen (inside) for the other.
  EXPECT_GT(both.Lookup(2.1, 0.0, gx, gy), 0.0);
  EXPECT_LT(seen.Lookup(2.1, 0.0, gx, gy), -0.05);
}

// Noise: with the LMS151's 12 mm statistical error the matches scatter as
// the covariance says. Over 200 scans from the truth (start 0.1 m, 0.05
// m, 0.05 rad off), the mean of e^T C^-1 e is chi-square(3 x 200) / 200:
// 99.99 % two-sided [2.372, 3.722] (Wilson-Hilferty; the 95 % interval
// [2.670, 3.349] would fail one seed in 20). A covariance off by 25 % in
// variance lands outside. Seeds 1..8: 2.698 / 2.874 / 3.079.
TEST(PerfectMatch, CovarianceMatchesTheScatterOfNoisyMatches) {
  const models::Scene scene = Room();
  const auto solids = SolidsAt(scene, 0.35);
  const DistanceMap map(scene, 0.35, std::nullopt, {0.02, 1.0, 4.0, {}});
  const PerfectMatch pm({});
  const int n = 200;
  std::vector<double> means;
  for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
    std::mt19937_64 rng(seed);
    double sum = 0.0;
    for (int k = 0; k < n; ++k) {
      // Poses along the room, away from the solids.
      const PerfectMatch::Pose truth{-2.0 + 0.02 * k, -0.5 + 0.3 * std::sin(0.1 * k), 0.1 * k};
      const Points p = ToPoints(Ranges(solids, truth.x, truth.y, truth.yaw, kNoise, &rng));
      const auto r = pm.Match(map, p.x, p.y, {truth.x + 0.1, truth.y + 0.05, truth.yaw + 0.05});
      ASSERT_TRUE(r.ok);
      const std::array<double, 6> c = {r.covariance[0], r.covariance[1], r.covariance[2],
                                       r.covariance[4], r.covariance[5], r.covariance[8]};
      std::array<double, 3> e = {r.pose.x - truth.x, r.pose.y - truth.y,
                                 std::remainder(r.pose.yaw - truth.yaw, 2 * std::numbers::pi)};
      std::array<double, 3> sol{};
      ASSERT_TRUE(SolveSymmetric3(c, e, sol));
      sum += e[0] * sol[0] + e[1] * sol[1] + e[2] * sol[2];
    }
    means.push_back(sum / n);
  }
  const auto nees = test_spread::Print("per-match NEES mean over 200 scans", means);
  EXPECT_GT(nees.min(), 2.372);
  EXPECT_LT(nees.max(), 3.722);
}

// A range bias common to a scan's beams (the LMS151's systematic error,
// +-30 mm typical, 8012471) shifts the match by g b to first order
// (PerfectMatch::Result::bias_sensitivity). Exact ranges + 30 mm: the shift
// is g b within the second-order term, b^2 / r over the ~1 m nearest ranges
// (0.9 mm, taken 1 mm), and the map's own error (the tight bound of
// RecoversOffset, 0.5 mm at 20 mm cells).
TEST(PerfectMatch, BiasSensitivityPredictsTheShiftOfARangeBias) {
  const models::Scene scene = Room();
  const auto solids = SolidsAt(scene, 0.35);
  const DistanceMap map(scene, 0.35, std::nullopt, {0.02, 1.0, 4.0, {}});
  const PerfectMatch pm({});
  const PerfectMatch::Pose truth{1.3, -0.7, 0.4};
  const double b = 0.03;
  const Points p0 = ToPoints(Ranges(solids, truth.x, truth.y, truth.yaw));
  const Points pb = ToPoints(Ranges(solids, truth.x, truth.y, truth.yaw, 0.0, nullptr, b));
  const auto r0 = pm.Match(map, p0.x, p0.y, truth);
  const auto rb = pm.Match(map, pb.x, pb.y, truth);
  const auto& g = r0.bias_sensitivity;
  std::printf("bias 30 mm: shift %.3f %.3f mm %.3f mrad, g b %.3f %.3f mm %.3f mrad\n",
              (rb.pose.x - r0.pose.x) * 1e3, (rb.pose.y - r0.pose.y) * 1e3,
              (rb.pose.yaw - r0.pose.yaw) * 1e3, g[0] * b * 1e3, g[1] * b * 1e3, g[2] * b * 1e3);
  EXPECT_NEAR(rb.pose.x - r0.pose.x, g[0] * b, 1.5e-3);
  EXPECT_NEAR(rb.pose.y - r0.pose.y, g[1] * b, 1.5e-3);
  EXPECT_NEAR(rb.pose.yaw - r0.pose.yaw, g[2] * b, 1.5e-3 / 3.0);  // over the ~3 m ranges
  // Not trivially zero: the room is seen off-centre.
  EXPECT_GT(std::hypot(g[0], g[1]), 0.1);
}

// The same consistency with a bias drawn per scan, N(0, 15 mm) (the
// LMS151 model's bias_sigma), and the covariance C + sigma_b^2 g g^T;
// 200 scans: 99.99 % two-sided [2.372, 3.722] as above. Without the term
// the NEES is far above (the bias's share dominates). Seeds 1..8: with the
// term 2.552 / 2.989 / 3.138; without 146 / 192 / 219.
TEST(PerfectMatch, BiasTermMakesTheCovarianceConsistentWithABias) {
  const models::Scene scene = Room();
  const auto solids = SolidsAt(scene, 0.35);
  const DistanceMap map(scene, 0.35, std::nullopt, {0.02, 1.0, 4.0, {}});
  const PerfectMatch pm({});
  const double sb = 0.015;
  const int count = 200;
  std::vector<double> with, without;
  for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> n(0.0, 1.0);
    double sum = 0.0, sum_without = 0.0;
    for (int k = 0; k < count; ++k) {
      const PerfectMatch::Pose truth{-2.0 + 0.02 * k, -0.5 + 0.3 * std::sin(0.1 * k), 0.1 * k};
      const double bias = sb * n(rng);
      const Points p = ToPoints(Ranges(solids, truth.x, truth.y, truth.yaw, kNoise, &rng, bias));
      const auto r = pm.Match(map, p.x, p.y, {truth.x + 0.02, truth.y - 0.01, truth.yaw + 0.01});
      ASSERT_TRUE(r.ok);
      std::array<double, 9> c = r.covariance;
      std::array<double, 3> e = {r.pose.x - truth.x, r.pose.y - truth.y,
                                 std::remainder(r.pose.yaw - truth.yaw, 2 * std::numbers::pi)};
      std::array<double, 3> sol{};
      ASSERT_TRUE(SolveSymmetric3({c[0], c[1], c[2], c[4], c[5], c[8]}, e, sol));
      sum_without += e[0] * sol[0] + e[1] * sol[1] + e[2] * sol[2];
      for (std::size_t a = 0; a < 3; ++a)
        for (std::size_t b = 0; b < 3; ++b)
          c[3 * a + b] += sb * sb * r.bias_sensitivity[a] * r.bias_sensitivity[b];
      ASSERT_TRUE(SolveSymmetric3({c[0], c[1], c[2], c[4], c[5], c[8]}, e, sol));
      sum += e[0] * sol[0] + e[1] * sol[1] + e[2] * sol[2];
    }
    with.push_back(sum / count);
    without.push_back(sum_without / count);
  }
  const auto w = test_spread::Print("per-match NEES with a 15 mm bias, with the bias term", with);
  const auto wo = test_spread::Print("the same without the term", without);
  EXPECT_GT(w.min(), 2.372);
  EXPECT_LT(w.max(), 3.722);
  EXPECT_GT(wo.min(), 3.722);  // the term is needed
}

}  // namespace
}  // namespace linesim::estimation
