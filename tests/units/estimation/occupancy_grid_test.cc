// The scan matcher's map (units/estimation/occupancy_grid.h): its levels,
// which solids it holds, its value profile and the bilinear lookup.
#include "units/estimation/occupancy_grid.h"

#include <gtest/gtest.h>

#include <array>
#include <algorithm>
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
  scene.obstacles.push_back({"shelf", "rack", models::BoxSolid(-2.0, 1.0, 0.0, 1.0, 1.0, 0.3, 0.5)});
  scene.obstacles.push_back({"pillar", "pillar", models::CylinderSolid(2.0, -2.0, 0.25, 4.0)});
  scene.carried.push_back({"body", 0, models::BoxSolid(0.0, -3.0, 0.0, 4.6, 1.8, 1.2, 0.3)});
  const std::vector<double> planes{0.178};
  const OccupancyGrid g(scene, planes, {});
  EXPECT_EQ(g.solid_count(), 2u);
  EXPECT_NEAR(g.Value(0, 1.6, 1.0), 1.0, 1e-6);   // the cart's face at x = 1.6
  EXPECT_EQ(g.Value(0, -2.5, 1.0), 0.0);          // the shelf's face: not in the map
  EXPECT_EQ(g.Value(0, 0.0, -3.9), 0.0);          // the car body's side: not in the map
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

}  // namespace
}  // namespace linesim::estimation
