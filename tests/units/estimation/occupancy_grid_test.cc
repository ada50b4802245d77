// The scan matcher's map (units/estimation/occupancy_grid.h): its levels,
// which solids it holds, its value profile and the bilinear lookup.
#include "units/estimation/occupancy_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

namespace linesim::estimation {
namespace {

models::Floor Floor(double half_x, double half_y) { return {-half_x, half_x, -half_y, half_y, 0}; }

// Guards against level cell sizes other than resolution * 2^i (hector's
// MapRepMultiMap) and a grid not covering the floor plus its margin.
TEST(OccupancyGrid, LevelCellSizesAndExtent) {
  const OccupancyGrid g({}, Floor(5.0, 4.0), {});
  ASSERT_EQ(g.levels(), 3);
  EXPECT_DOUBLE_EQ(g.cell_size(0), 0.025);
  EXPECT_DOUBLE_EQ(g.cell_size(1), 0.05);
  EXPECT_DOUBLE_EQ(g.cell_size(2), 0.1);
  for (int i = 0; i < 3; ++i) {
    const auto& l = g.level(i);
    EXPECT_LE(l.origin_x, -5.5 + 1e-12);
    EXPECT_LE(l.origin_y, -4.5 + 1e-12);
    EXPECT_GE(l.origin_x + l.nx * l.cell, 5.5 - 1e-12);
    EXPECT_GE(l.origin_y + l.ny * l.cell, 4.5 - 1e-12);
    EXPECT_DOUBLE_EQ(l.w, 2.0 * l.cell);
  }
  OccupancyGrid::Options o;
  o.resolution = 0.05;
  o.levels = 4;
  const OccupancyGrid h({}, Floor(5.0, 4.0), o);
  ASSERT_EQ(h.levels(), 4);
  EXPECT_DOUBLE_EQ(h.cell_size(3), 0.4);
}

// Guards against carried objects or solids outside the scan plane in the
// map: a cart 1 m high is in it for a plane at 0.178 m, a shelf from 0.5 m
// up is not, a car body (carried) never.
TEST(OccupancyGrid, HoldsTheStaticSolidsAtTheScanPlane) {
  models::Scene scene;
  scene.floor = Floor(5.0, 5.0);
  scene.obstacles.push_back({"cart", "cart", models::BoxSolid(1.0, 1.0, 0.0, 1.2, 0.8, 1.0)});
  scene.obstacles.push_back(
      {"shelf", "rack", models::BoxSolid(-2.0, 1.0, 0.0, 1.0, 1.0, 0.3, 0.5)});
  scene.obstacles.push_back({"pillar", "pillar", models::CylinderSolid(2.0, -2.0, 0.25, 4.0)});
  scene.carried.push_back({"body", 0, models::BoxSolid(0.0, -3.0, 0.0, 4.6, 1.8, 1.2, 0.3)});
  const std::vector<double> planes{0.178};
  const OccupancyGrid g(scene, planes, {});
  EXPECT_EQ(g.solid_count(), 2u);
  EXPECT_NEAR(g.Value(0, 1.6, 1.0), 1.0, 1e-6);  // the cart's face at x = 1.6
  EXPECT_EQ(g.Value(0, -2.5, 1.0), 0.0);         // the shelf's face: not in the map
  EXPECT_EQ(g.Value(0, 0.0, -3.9), 0.0);         // the car body's side: not in the map
  const std::vector<double> high{0.6};
  EXPECT_EQ(OccupancyGrid(scene, high, {}).solid_count(), 3u);
}

// Guards against a profile other than M = clamp(1 + d / w, 0, 2) at the
// nodes (d the signed distance to the outline, positive inside; the
// header's formula), for a rotated box and a cylinder.
TEST(OccupancyGrid, NodeValuesFollowTheProfile) {
  const std::vector<models::Solid> solids{models::BoxSolid(0.3, -0.2, 0.4, 1.5, 0.6, 1.0),
                                          models::CylinderSolid(-1.5, 1.0, 0.25, 1.0)};
  const OccupancyGrid g(solids, Floor(3.0, 3.0), {});
  for (int i = 0; i < g.levels(); ++i) {
    const auto& l = g.level(i);
    int checked = 0, peak = 0;
    for (int iy = 0; iy < l.ny; iy += 3) {
      for (int ix = 0; ix < l.nx; ix += 3) {
        const double x = l.origin_x + (ix + 0.5) * l.cell, y = l.origin_y + (iy + 0.5) * l.cell;
        const double d = g.SignedDistance(x, y);
        const double expected = std::clamp(1.0 + d / l.w, 0.0, 2.0);
        // Stored as float: relative rounding 2^-24 of a value <= 2.
        ASSERT_NEAR(l.value[static_cast<std::size_t>(iy) * l.nx + ix], expected, 2.4e-7)
            << "level " << i << " node " << ix << ", " << iy;
        ++checked;
        peak += (expected > 0.0 && expected < 2.0) ? 1 : 0;
      }
    }
    EXPECT_GT(peak, 10) << "level " << i;  // the band around the outlines is sampled
    EXPECT_GT(checked, 100);
  }
}

// Guards against the half-cell bias: a point ON a straight face (axis
// aligned at an arbitrary offset, or rotated) reads M = 1 on every level,
// and the gradient is the face's outward normal over -w. The profile is
// linear in the distance to the face, which the bilinear interpolant
// reproduces exactly (see the header), so the only error is the float
// storage: |M - 1| <= 4 * 2^-24 * 2 (four nodes <= 2), i.e. a face
// offset of at most 5e-7 w (2.4e-8 m at 0.025 m).
TEST(OccupancyGrid, APointOnAFaceMatchesAtTheFace) {
  const double yaw = 0.37;
  const std::vector<models::Solid> solids{
      models::BoxSolid(1.2345 + 0.1, 0.0, 0.0, 0.2, 4.0, 2.0),  // -x face at x = 1.2345
      models::BoxSolid(-1.0, -1.0, yaw, 2.0, 0.4, 2.0)};
  const OccupancyGrid g(solids, Floor(4.0, 4.0), {});
  const double nx = -std::sin(yaw), ny = std::cos(yaw);  // the rotated box's +y face normal
  for (int i = 0; i < g.levels(); ++i) {
    const double w = g.level(i).w;
    for (double y = -1.0; y <= 1.0; y += 0.0173) {
      double gx, gy;
      const double m = g.ValueAndGradient(i, 1.2345, y, gx, gy);
      ASSERT_NEAR(m, 1.0, 1e-6) << "level " << i << " y " << y;
      // Outside the wall (x < 1.2345) the value falls: the gradient points
      // into the solid, +x, of size 1 / w.
      ASSERT_NEAR(gx, 1.0 / w, 1e-4 / w);
      ASSERT_NEAR(gy, 0.0, 1e-4 / w);
    }
    for (double s = -0.5; s <= 0.5; s += 0.031) {
      // On the rotated box's +y face (half width 0.2), along its length.
      const double x = -1.0 + std::cos(yaw) * s + 0.2 * nx, y = -1.0 + std::sin(yaw) * s + 0.2 * ny;
      double gx, gy;
      const double m = g.ValueAndGradient(i, x, y, gx, gy);
      ASSERT_NEAR(m, 1.0, 1e-6) << "level " << i << " s " << s;
      ASSERT_NEAR(gx, -nx / w, 1e-4 / w);
      ASSERT_NEAR(gy, -ny / w, 1e-4 / w);
    }
  }
}

// Guards against a cylinder's face offset beyond the bound of the header:
// at most cell^2 / (4 R) (+ float), here R = 0.25 m.
TEST(OccupancyGrid, ACylinderFaceIsWithinTheCurvatureBound) {
  const double r = 0.25;
  const std::vector<models::Solid> solids{models::CylinderSolid(0.013, -0.021, r, 2.0)};
  const OccupancyGrid g(solids, Floor(2.0, 2.0), {});
  for (int i = 0; i < g.levels(); ++i) {
    const auto& l = g.level(i);
    const double bound = l.cell * l.cell / (4.0 * r) + 1e-6 * l.w;
    for (double a = 0.0; a < 2.0 * std::numbers::pi; a += 0.05) {
      const double x = 0.013 + r * std::cos(a), y = -0.021 + r * std::sin(a);
      // The value's error as a distance: (M - 1) * w.
      EXPECT_LE(std::abs(g.Value(i, x, y) - 1.0) * l.w, bound) << "level " << i << " a " << a;
    }
  }
}

// Guards against reading outside the grid (or a NaN point) indexing memory.
TEST(OccupancyGrid, OutsideTheGridReadsZero) {
  const std::vector<models::Solid> solids{models::BoxSolid(0.0, 0.0, 0.0, 20.0, 20.0, 2.0)};
  const OccupancyGrid g(solids, Floor(2.0, 2.0), {});
  double gx = 1, gy = 1;
  EXPECT_EQ(g.ValueAndGradient(0, 100.0, 0.0, gx, gy), 0.0);
  EXPECT_EQ(gx, 0.0);
  EXPECT_EQ(g.ValueAndGradient(2, std::nan(""), 0.0, gx, gy), 0.0);
  EXPECT_EQ(g.ValueAndGradient(1, 0.0, -1e30, gx, gy), 0.0);
  EXPECT_NEAR(g.Value(0, 0.0, 0.0), 2.0, 1e-6);  // deep inside the box
}

// The learned map (map: mapping). Grid over Floor(2, 1) + 0.5 m: 5 x 3 m,
// 200 x 120 cells of 0.025 m, origin (-2.5, -1.5); the cell of x is
// floor((x + 2.5) / 0.025), of y floor((y + 1.5) / 0.025). The robot at the
// origin, heading +x, the laser at (0.01, 0.01) in its frame: cell (100, 60).
struct Learned {
  OccupancyGrid g{Floor(2.0, 1.0), {}, {}};
  double P(int i, double x, double y) const {
    int ix = 0, iy = 0;
    EXPECT_TRUE(g.CellOf(i, x, y, ix, iy));
    return g.level(i).value[static_cast<std::size_t>(iy) * static_cast<std::size_t>(g.level(i).nx) +
                            static_cast<std::size_t>(ix)];
  }
  float L(int i, double x, double y) const {
    int ix = 0, iy = 0;
    EXPECT_TRUE(g.CellOf(i, x, y, ix, iy));
    return g.level(i)
        .log_odds[static_cast<std::size_t>(iy) * static_cast<std::size_t>(g.level(i).nx) +
                  static_cast<std::size_t>(ix)];
  }
  void Scan(const std::vector<double>& px, const std::vector<double>& py) {
    g.UpdateByScan(px, py, 0.01, 0.01, 0.0, 0.0, 0.0);
  }
};

// Guards against a learned map that does not start unknown or whose cells
// are not where CellOf says.
TEST(OccupancyGridLearned, StartsUnknown) {
  const Learned m;
  ASSERT_TRUE(m.g.learned());
  EXPECT_EQ(m.g.level(0).nx, 200);
  EXPECT_EQ(m.g.level(0).ny, 120);
  for (int i = 0; i < 3; ++i) {
    for (const float v : m.g.level(i).value) ASSERT_EQ(v, 0.5f);
    for (const float v : m.g.level(i).log_odds) ASSERT_EQ(v, 0.0f);
  }
  int ix = 0, iy = 0;
  ASSERT_TRUE(m.g.CellOf(0, 0.01, 0.01, ix, iy));
  EXPECT_EQ(ix, 100);
  EXPECT_EQ(iy, 60);
  EXPECT_FALSE(m.g.CellOf(0, 2.6, 0.0, ix, iy));
  // hector's probToLogOdds of its launch file's 0.9 and 0.4.
  EXPECT_NEAR(m.g.log_odds_occupied(), 2.1972246, 1e-6);
  EXPECT_NEAR(m.g.log_odds_free(), -0.4054651, 1e-6);
  // A map built from the scene is not learned.
  EXPECT_FALSE(OccupancyGrid({}, Floor(2.0, 1.0), {}).learned());
}

// Guards against the log-odds update of one beam against a wall at
// x = 1.01 (cell 140): one hit gives the end cell p = 0.9 (log-odds
// log 9), not decremented by its own beam; the 40 cells from the laser's
// (100) to the one before the wall (139) read 0.4 (log-odds log(2/3));
// the cell behind the wall and the cells beside the beam stay 0.5. The
// same on level 1 (cells 0.05 m: laser cell 50, wall cell 70).
TEST(OccupancyGridLearned, OneBeamAgainstAWall) {
  Learned m;
  m.Scan({1.01}, {0.01});
  EXPECT_NEAR(m.P(0, 1.01, 0.01), 0.9, 1e-6);
  for (int ix = 100; ix < 140; ++ix) {
    ASSERT_NEAR(m.P(0, -2.5 + (ix + 0.5) * 0.025, 0.01), 0.4, 1e-6) << ix;
  }
  EXPECT_EQ(m.P(0, 1.04, 0.01), 0.5);   // behind the wall
  EXPECT_EQ(m.P(0, 0.5, 0.04), 0.5);    // beside the beam
  EXPECT_EQ(m.P(0, -0.02, 0.01), 0.5);  // behind the laser
  EXPECT_NEAR(m.P(1, 1.01, 0.01), 0.9, 1e-6);
  for (int ix = 50; ix < 70; ++ix) {
    ASSERT_NEAR(m.P(1, -2.5 + (ix + 0.5) * 0.05, 0.01), 0.4, 1e-6) << ix;
  }
  // The level's value is the probability of its log-odds.
  EXPECT_EQ(m.P(0, 1.01, 0.01), OccupancyGrid::Probability(m.L(0, 1.01, 0.01)));
  // A second scan: odds multiply, 9^2 = 81 -> 81 / 82; (2/3)^2 = 4/9 -> 4 / 13.
  m.Scan({1.01}, {0.01});
  EXPECT_NEAR(m.P(0, 1.01, 0.01), 81.0 / 82.0, 1e-6);
  EXPECT_NEAR(m.P(0, 0.5, 0.01), 4.0 / 13.0, 1e-6);
}

// Guards against a cell counted more than once in one scan (hector's update
// index): 41 beams fanning from the laser to a wall at x = 1.01 share the
// cells near the laser, which still read 0.4 after the scan; a beam whose
// end cell another beam of the same scan passes reads 0.9 whichever comes
// first (hector's updateUnsetFree).
TEST(OccupancyGridLearned, EachCellOncePerScan) {
  Learned m;
  std::vector<double> px, py;
  for (int j = -20; j <= 20; ++j) {
    px.push_back(1.01);
    py.push_back(0.01 + j * 0.0125);
  }
  m.Scan(px, py);
  EXPECT_NEAR(m.P(0, 0.01, 0.01), 0.4, 1e-6);  // the laser's cell, on every beam
  EXPECT_NEAR(m.P(0, 0.04, 0.01), 0.4, 1e-6);
  for (int j = -20; j <= 20; ++j) ASSERT_NEAR(m.P(0, 1.01, 0.01 + j * 0.0125), 0.9, 1e-6) << j;
  for (const bool short_first : {true, false}) {
    Learned o;
    if (short_first) {
      o.Scan({0.51, 1.01}, {0.01, 0.01});
    } else {
      o.Scan({1.01, 0.51}, {0.01, 0.01});
    }
    EXPECT_NEAR(o.P(0, 0.51, 0.01), 0.9, 1e-6) << short_first;
    EXPECT_NEAR(o.P(0, 0.26, 0.01), 0.4, 1e-6) << short_first;
    EXPECT_NEAR(o.P(0, 0.76, 0.01), 0.4, 1e-6) << short_first;
  }
}

// Guards against beams leaving the grid updating anything (hector skips a
// beam whose end cell is off the map), against an unbounded log-odds (a hit
// only while L < 50: at most 50 + log 9) and against Clear and SetLogOdds
// not restoring what they promise.
TEST(OccupancyGridLearned, OffMapBeamsBoundsClearAndRestore) {
  Learned m;
  m.Scan({3.0, 0.01}, {0.01, 5.0});
  for (int i = 0; i < 3; ++i) {
    for (const float v : m.g.level(i).value) ASSERT_EQ(v, 0.5f);
  }
  for (int s = 0; s < 40; ++s) m.Scan({1.01}, {0.01});
  // 23 hits: 22 log 9 = 48.3 < 50, 23 log 9 = 50.5, then no more.
  EXPECT_NEAR(m.L(0, 1.01, 0.01), 23 * std::log(9.0), 1e-3);
  EXPECT_LT(m.L(0, 0.5, 0.01), -15.0);  // 40 misses: -16.2
  EXPECT_EQ(m.P(0, 1.01, 0.01), 1.0f);
  // Restore level 0's log-odds into a fresh map: the same values.
  Learned r;
  for (int i = 0; i < 3; ++i) r.g.SetLogOdds(i, m.g.level(i).log_odds);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(r.g.level(i).value, m.g.level(i).value) << i;
  // A further scan gives the same map in both.
  m.Scan({0.51}, {0.3});
  r.Scan({0.51}, {0.3});
  for (int i = 0; i < 3; ++i) EXPECT_EQ(r.g.level(i).log_odds, m.g.level(i).log_odds) << i;
  EXPECT_THROW(r.g.SetLogOdds(0, std::vector<float>(5, 0.0f)), std::invalid_argument);
  m.g.Clear();
  for (const float v : m.g.level(0).value) ASSERT_EQ(v, 0.5f);
  EXPECT_THROW(OccupancyGrid(Floor(2.0, 1.0), {}, {1.0, 0.4}), std::invalid_argument);
}

}  // namespace
}  // namespace linesim::estimation
