#include "models/polyline.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace linesim::models {
namespace {

PolylinePoint Nearest(const std::vector<Point2>& path, double x, double y, PolylineEnds ends) {
  return NearestOnPolyline(path, CumulativeLengths(path), x, y, ends);
}

// Guards the arc lengths the search takes its segment lengths from.
TEST(Polyline, CumulativeLengthsSumTheSegments) {
  EXPECT_EQ(CumulativeLengths({{0, 0}, {3, 4}, {3, 10}}), (std::vector<double>{0, 5, 11}));
  EXPECT_EQ(CumulativeLengths({{1, 1}}), (std::vector<double>{0}));
  EXPECT_TRUE(CumulativeLengths({}).empty());
}

// Guards the ends: clamped, a point before the start is nearest to the
// start (distance to it, progress 0); extended, it is nearest to the line
// through the first segment (progress below 0), and likewise after the end.
TEST(Polyline, EndsClampedOrExtended) {
  const std::vector<Point2> path = {{0, 0}, {2, 0}};
  const PolylinePoint before_clamped = Nearest(path, -1, 1, PolylineEnds::kClamp);
  EXPECT_TRUE(before_clamped.found);
  EXPECT_DOUBLE_EQ(before_clamped.distance_m, std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(before_clamped.progress_m, 0.0);
  EXPECT_DOUBLE_EQ(before_clamped.cross_track_m, 1.0);  // + left of the path
  const PolylinePoint before = Nearest(path, -1, 1, PolylineEnds::kExtend);
  EXPECT_DOUBLE_EQ(before.distance_m, 1.0);
  EXPECT_DOUBLE_EQ(before.progress_m, -1.0);
  const PolylinePoint after_clamped = Nearest(path, 3, -0.5, PolylineEnds::kClamp);
  EXPECT_DOUBLE_EQ(after_clamped.distance_m, std::hypot(1.0, 0.5));
  EXPECT_DOUBLE_EQ(after_clamped.progress_m, 2.0);
  const PolylinePoint after = Nearest(path, 3, -0.5, PolylineEnds::kExtend);
  EXPECT_DOUBLE_EQ(after.distance_m, 0.5);
  EXPECT_DOUBLE_EQ(after.cross_track_m, -0.5);  // right of the path
  EXPECT_DOUBLE_EQ(after.progress_m, 3.0);
  EXPECT_EQ(after.tangent_x, 1.0);
  EXPECT_EQ(after.tangent_y, 0.0);
}

// Guards the corner of a polyline: the nearest segment wins, progress is
// the arc length up to it plus the way along it; only the end segments are
// extended, so a point beyond the inner corner is nearest to the corner,
// and of two equally near segments the first wins.
TEST(Polyline, NearestSegmentAndCorner) {
  const std::vector<Point2> path = {{0, 0}, {1, 0}, {1, 1}};
  for (const PolylineEnds ends : {PolylineEnds::kClamp, PolylineEnds::kExtend}) {
    const PolylinePoint p = Nearest(path, 1.2, 0.5, ends);
    EXPECT_EQ(p.segment, 1u);
    EXPECT_NEAR(p.distance_m, 0.2, 1e-15);
    EXPECT_NEAR(p.cross_track_m, -0.2, 1e-15);  // right of the segment going up
    EXPECT_NEAR(p.progress_m, 1.5, 1e-15);
    EXPECT_EQ(p.tangent_x, 0.0);
    EXPECT_EQ(p.tangent_y, 1.0);
    const PolylinePoint corner = Nearest(path, 2, -1, ends);
    EXPECT_EQ(corner.segment, 0u);
    EXPECT_DOUBLE_EQ(corner.distance_m, std::sqrt(2.0));
    EXPECT_DOUBLE_EQ(corner.progress_m, 1.0);
  }
}

// Guards a segment of no length (a repeated point): it counts as its
// vertex, with no tangent, instead of dividing by zero.
TEST(Polyline, ZeroLengthSegmentIsItsVertex) {
  const PolylinePoint p = Nearest({{1, 1}, {1, 1}}, 4, 5, PolylineEnds::kExtend);
  ASSERT_TRUE(p.found);
  EXPECT_DOUBLE_EQ(p.distance_m, 5.0);
  EXPECT_EQ(p.progress_m, 0.0);
  EXPECT_EQ(p.tangent_x, 0.0);
  EXPECT_EQ(p.tangent_y, 0.0);
  EXPECT_EQ(p.cross_track_m, 0.0);
}

// Guards against a made-up answer: no segment, or a point that compares
// with nothing, is not found.
TEST(Polyline, NothingFoundWithoutSegmentsOrForANaNPoint) {
  EXPECT_FALSE(Nearest({{1, 1}}, 0, 0, PolylineEnds::kClamp).found);
  EXPECT_FALSE(Nearest({}, 0, 0, PolylineEnds::kClamp).found);
  EXPECT_FALSE(Nearest({{0, 0}, {1, 0}}, NAN, 0, PolylineEnds::kExtend).found);
}

}  // namespace
}  // namespace linesim::models
