#include "models/polygon.h"

#include <algorithm>
#include <cmath>

namespace linesim::models {

namespace {

using Point = std::array<double, 2>;

// Twice the signed area of the triangle a, b, c: > 0 counter-clockwise.
double Orientation(const Point& a, const Point& b, const Point& c) {
  return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

int Sign(double x) { return (x > 0.0) - (x < 0.0); }

// Whether p, collinear with segment a-b, lies on it.
bool OnSegment(const Point& a, const Point& b, const Point& p) {
  return std::min(a[0], b[0]) <= p[0] && p[0] <= std::max(a[0], b[0]) &&
         std::min(a[1], b[1]) <= p[1] && p[1] <= std::max(a[1], b[1]);
}

// Whether closed segments a-b and c-d have a point in common.
bool SegmentsMeet(const Point& a, const Point& b, const Point& c, const Point& d) {
  const int o1 = Sign(Orientation(a, b, c)), o2 = Sign(Orientation(a, b, d));
  const int o3 = Sign(Orientation(c, d, a)), o4 = Sign(Orientation(c, d, b));
  if (o1 != o2 && o3 != o4) return true;
  return (o1 == 0 && OnSegment(a, b, c)) || (o2 == 0 && OnSegment(a, b, d)) ||
         (o3 == 0 && OnSegment(c, d, a)) || (o4 == 0 && OnSegment(c, d, b));
}

}  // namespace

std::optional<std::string> PolygonProblem(const std::vector<Point>& p) {
  const std::size_t n = p.size();
  if (n < 3) return "needs at least 3 corners [x, y], got " + std::to_string(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Point& before = p[(i + n - 1) % n];
    if (p[i] == before) {
      return "corner " + std::to_string(i) + " repeats corner " + std::to_string((i + n - 1) % n);
    }
  }
  // All corners on one line (within rounding): the line through corner 0
  // and the corner farthest from it.
  std::size_t far = 1;
  const auto d2 = [&](const Point& q) {
    return (q[0] - p[0][0]) * (q[0] - p[0][0]) + (q[1] - p[0][1]) * (q[1] - p[0][1]);
  };
  for (std::size_t i = 2; i < n; ++i) {
    if (d2(p[i]) > d2(p[far])) far = i;
  }
  bool collinear = true;
  for (std::size_t i = 1; i < n && collinear; ++i) {
    collinear = std::abs(Orientation(p[0], p[far], p[i])) <= 1e-12 * d2(p[far]);
  }
  if (collinear) return "has zero area: its corners lie on one line (no point can be inside it)";
  for (std::size_t i = 0; i < n; ++i) {
    const Point& a = p[i];
    const Point& b = p[(i + 1) % n];
    // The next edge shares corner b: it may only meet this one there, so
    // it must not run back along it.
    const Point& c = p[(i + 2) % n];
    if (Sign(Orientation(a, b, c)) == 0 &&
        (c[0] - b[0]) * (a[0] - b[0]) + (c[1] - b[1]) * (a[1] - b[1]) > 0.0) {
      return "folds back on itself at corner " + std::to_string((i + 1) % n) + " (edges " +
             std::to_string(i) + " and " + std::to_string((i + 1) % n) + " overlap)";
    }
    // Edges that share no corner must not meet at all.
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // the last edge ends at corner 0
      if (SegmentsMeet(a, b, p[j], p[(j + 1) % n])) {
        return "is self-intersecting: edge " + std::to_string(i) + " (corners " +
               std::to_string(i) + "-" + std::to_string((i + 1) % n) + ") meets edge " +
               std::to_string(j) + " (corners " + std::to_string(j) + "-" +
               std::to_string((j + 1) % n) + ")";
      }
    }
  }
  // A simple polygon has an area; this catches what rounding hid above.
  double area2 = 0.0, min_x = p[0][0], max_x = p[0][0], min_y = p[0][1], max_y = p[0][1];
  for (std::size_t i = 0; i < n; ++i) {
    const Point& a = p[i];
    const Point& b = p[(i + 1) % n];
    area2 += a[0] * b[1] - b[0] * a[1];
    min_x = std::min(min_x, a[0]), max_x = std::max(max_x, a[0]);
    min_y = std::min(min_y, a[1]), max_y = std::max(max_y, a[1]);
  }
  const double diagonal2 = (max_x - min_x) * (max_x - min_x) + (max_y - min_y) * (max_y - min_y);
  if (!(std::abs(area2) > 1e-12 * diagonal2)) {
    return "has zero area (no point can be inside it)";
  }
  return std::nullopt;
}

}  // namespace linesim::models
