#pragma once

#include <array>
#include <cstddef>
#include <vector>

namespace linesim::models {

/// A point in the plane, (x, y) in m.
using Point2 = std::array<double, 2>;

/// Arc length of a polyline at each vertex: 0 at the first, then the sum of
/// the segment lengths (empty for no vertices). A unit computes it once
/// for its path, not on every search.
std::vector<double> CumulativeLengths(const std::vector<Point2>& vertices);

/// Where NearestOnPolyline looks. kClamp: on the polyline only. kExtend: the
/// first and the last segment go on beyond the ends, so that progress runs
/// below 0 before the start and past the length after the end, and the
/// cross-track stays the distance from the line through the end segment.
enum class PolylineEnds { kClamp, kExtend };

/// The point of a polyline nearest to a given point.
struct PolylinePoint {
  /// False for fewer than two vertices, or when no distance compares below
  /// infinity (a NaN in the point or the polyline); the rest is then 0.
  bool found = false;
  std::size_t segment = 0;
  /// Unit tangent of that segment ((0, 0) for a segment of no length).
  double tangent_x = 0.0, tangent_y = 0.0;
  /// Arc length of the nearest point along the polyline.
  double progress_m = 0.0;
  /// Signed distance across the segment's line, + on its left (0 for a
  /// segment of no length).
  double cross_track_m = 0.0;
  /// Distance to the nearest point.
  double distance_m = 0.0;
};

/// The point of the polyline `vertices` nearest to (x_m, y_m); the first of
/// equally near segments wins. `cumulative_m` is CumulativeLengths(vertices).
/// A segment that does not grow cumulative_m counts as its first vertex.
PolylinePoint NearestOnPolyline(const std::vector<Point2>& vertices,
                                const std::vector<double>& cumulative_m, double x_m, double y_m,
                                PolylineEnds ends);

}  // namespace linesim::models
