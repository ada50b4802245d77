#include <gtest/gtest.h>

#include <cmath>

#include "models/scene.h"

namespace linesim::models {
namespace {

// A ramp whose top face rises from (2, 0, 0) to (4, 0, 0.54) along +x, 1.2 m
// wide, 0.04 m thick: pitch atan(0.54 / 2), its centre half a thickness
// below the top face's middle (3, 0, 0.27) along the face's normal.
TerrainPiece Ramp(double yaw_rad = 0.0) {
  TerrainPiece t;
  t.pitch_rad = std::atan2(0.54, 2.0);
  t.length_m = std::hypot(2.0, 0.54);
  t.width_m = 1.2;
  t.thickness_m = 0.04;
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  // The normal of the top face: (-sin p, 0, cos p) before the yaw.
  const double nx = -std::sin(t.pitch_rad), nz = std::cos(t.pitch_rad);
  t.center_x_m = 3.0 * c - 0.02 * nx * c;
  t.center_y_m = 3.0 * s - 0.02 * nx * s;
  t.center_z_m = 0.27 - 0.02 * nz;
  t.yaw_rad = yaw_rad;
  return t;
}

// Guards the terrain convention (+ pitch raises the far end) and the top
// face's height: linear along the ramp, 0.27 m at its middle, 0.54 m at its
// top (the plane through both ends), nothing beside or beyond it.
TEST(TerrainTopAt, HeightOfARampsTopFace) {
  const TerrainPiece t = Ramp();
  EXPECT_NEAR(*TerrainTopAt(t, 3.0, 0.0), 0.27, 1e-12);
  EXPECT_NEAR(*TerrainTopAt(t, 2.5, 0.5), 0.27 * 0.5, 1e-12);
  EXPECT_NEAR(*TerrainTopAt(t, 3.999, 0.0), 0.54 * 1.999 / 2.0, 1e-12);
  EXPECT_FALSE(TerrainTopAt(t, 3.0, 0.61).has_value());
  EXPECT_FALSE(TerrainTopAt(t, 4.01, 0.0).has_value());
  EXPECT_FALSE(TerrainTopAt(t, 1.99, 0.0).has_value());
  // The top face's normal is the third axis, pointing up and back.
  const auto axes = TerrainAxes(t);
  EXPECT_NEAR(axes[2][0], -std::sin(t.pitch_rad), 1e-15);
  EXPECT_NEAR(axes[2][2], std::cos(t.pitch_rad), 1e-15);
}

// Guards the yaw: the same ramp turned by 90 degrees rises along +y.
TEST(TerrainTopAt, TurnedRampRisesAlongItsHeading) {
  const TerrainPiece t = Ramp(std::acos(0.0));
  EXPECT_NEAR(*TerrainTopAt(t, 0.0, 3.5), 0.27 * 1.5, 1e-12);
  EXPECT_FALSE(TerrainTopAt(t, 3.0, 0.0).has_value());
}

}  // namespace
}  // namespace linesim::models
