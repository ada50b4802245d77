#include "models/polyline.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace linesim::models {

std::vector<double> CumulativeLengths(const std::vector<Point2>& vertices) {
  std::vector<double> cumulative;
  if (vertices.empty()) return cumulative;
  cumulative.reserve(vertices.size());
  cumulative.push_back(0.0);
  for (std::size_t k = 1; k < vertices.size(); ++k) {
    cumulative.push_back(cumulative.back() + std::hypot(vertices[k][0] - vertices[k - 1][0],
                                                        vertices[k][1] - vertices[k - 1][1]));
  }
  return cumulative;
}

PolylinePoint NearestOnPolyline(const std::vector<Point2>& vertices,
                                const std::vector<double>& cumulative_m, double x_m, double y_m,
                                PolylineEnds ends) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  PolylinePoint best;
  if (vertices.size() < 2) return best;
  const std::size_t segments = vertices.size() - 1;
  const bool extend = ends == PolylineEnds::kExtend;
  // Squared distances are compared, one square root at the end.
  double best_dist2 = kInf;
  for (std::size_t k = 0; k < segments; ++k) {
    const Point2& a = vertices[k];
    const Point2& b = vertices[k + 1];
    const double px = x_m - a[0], py = y_m - a[1];
    // The length from the cumulative sum, so that progress is consistent
    // with it (and no square root is taken per segment).
    const double len = cumulative_m[k + 1] - cumulative_m[k];
    PolylinePoint p{true, k, 0.0, 0.0, cumulative_m[k], 0.0, 0.0};
    double dist2;
    if (!(len > 0.0)) {
      dist2 = px * px + py * py;
    } else {
      p.tangent_x = (b[0] - a[0]) / len;
      p.tangent_y = (b[1] - a[1]) / len;
      const double along = px * p.tangent_x + py * p.tangent_y;
      const double lo = extend && k == 0 ? -kInf : 0.0;
      const double hi = extend && k + 1 == segments ? kInf : len;
      const double u = std::clamp(along, lo, hi);
      p.cross_track_m = -px * p.tangent_y + py * p.tangent_x;
      p.progress_m += u;
      dist2 = (along - u) * (along - u) + p.cross_track_m * p.cross_track_m;
    }
    if (dist2 < best_dist2) {
      best_dist2 = dist2;
      best = p;
    }
  }
  if (best.found) best.distance_m = std::sqrt(best_dist2);
  return best;
}

}  // namespace linesim::models
