#include "models/polynomial_path.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace linesim::models {

namespace {

// Squared distance from (px, py) to F(t).
double Squared(const PolynomialSegment& s, double t, double px, double py) {
  const Point2 f = SegmentPosition(s, t);
  const double dx = f[0] - px, dy = f[1] - py;
  return dx * dx + dy * dy;
}

// The Gauss-Legendre rule of kGaussPoints nodes on [-1, 1], computed once
// (Newton on the Legendre polynomial from the Chebyshev-like first guess).
constexpr int kGaussPoints = 16;
struct GaussRule {
  std::array<double, kGaussPoints> node{}, weight{};
  GaussRule() {
    const int n = kGaussPoints;
    for (int i = 0; i < n; ++i) {
      double z = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
      double derivative = 1.0;
      for (int iteration = 0; iteration < 100; ++iteration) {
        // P_n(z) by the three-term recurrence, and its derivative.
        double p0 = 1.0, p1 = z;
        for (int k = 2; k <= n; ++k) {
          const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        derivative = n * (z * p1 - p0) / (z * z - 1.0);
        const double step = p1 / derivative;
        z -= step;
        if (std::abs(step) < 1e-16) break;
      }
      node[i] = z;
      weight[i] = 2.0 / ((1.0 - z * z) * derivative * derivative);
    }
  }
};
const GaussRule& Gauss() {
  static const GaussRule rule;
  return rule;
}

}  // namespace

void EvaluatePolynomial(const std::vector<double>& c, double t, double& value, double& first,
                        double& second) {
  value = first = second = 0.0;
  for (std::size_t i = c.size(); i-- > 0;) {
    second = second * t + 2.0 * first;
    first = first * t + value;
    value = value * t + c[i];
  }
}

SegmentPoint EvaluateSegment(const PolynomialSegment& s, double t) {
  SegmentPoint p;
  EvaluatePolynomial(s.x, t, p.x, p.dx, p.ddx);
  EvaluatePolynomial(s.y, t, p.y, p.dy, p.ddy);
  return p;
}

Point2 SegmentPosition(const PolynomialSegment& s, double t) {
  double x = 0.0, y = 0.0;
  for (std::size_t i = s.x.size(); i-- > 0;) x = x * t + s.x[i];
  for (std::size_t i = s.y.size(); i-- > 0;) y = y * t + s.y[i];
  return {x, y};
}

std::size_t SegmentDegree(const PolynomialSegment& s) {
  const std::size_t n = std::max(s.x.size(), s.y.size());
  return n == 0 ? 0 : n - 1;
}

double SegmentHeading(const SegmentPoint& p) {
  if (p.dx == 0.0 && p.dy == 0.0) return std::atan2(p.ddy, p.ddx);
  return std::atan2(p.dy, p.dx);
}

double SegmentCurvature(const SegmentPoint& p) {
  const double speed2 = p.dx * p.dx + p.dy * p.dy;
  if (!(speed2 > 0.0)) return 0.0;
  return (p.ddy * p.dx - p.ddx * p.dy) / (speed2 * std::sqrt(speed2));
}

double FeedForward(double speed_mps, const SegmentPoint& p) {
  return speed_mps * SegmentCurvature(p);
}

double ClosestParameter(const PolynomialSegment& s, double x_m, double y_m) {
  // The ends are candidates in their own right, exactly.
  double best_t = 0.0;
  double best = Squared(s, 0.0, x_m, y_m);
  if (const double end = Squared(s, 1.0, x_m, y_m); end < best) {
    best = end;
    best_t = 1.0;
  }
  const std::size_t degree = std::min(SegmentDegree(s), kMaxPolynomialCoefficients - 1);
  if (degree <= 0) return best_t;
  const std::size_t samples = 16 * (degree + 1);
  const double h = 1.0 / static_cast<double>(samples);
  // Refines the minimum bracketed by [lo, hi] (unimodal there as far as the
  // samples tell) and keeps it if it is the nearest so far.
  const auto refine = [&](double lo, double hi) {
    constexpr double kGolden = 0.6180339887498949;
    double a = lo, b = hi;
    double c = b - kGolden * (b - a), d = a + kGolden * (b - a);
    double fc = Squared(s, c, x_m, y_m), fd = Squared(s, d, x_m, y_m);
    // 30 reductions: the bracket (2 h) shrinks to 2 h 0.618^30 = 1e-6 h.
    for (int i = 0; i < 30; ++i) {
      if (fc <= fd) {
        b = d;
        d = c;
        fd = fc;
        c = b - kGolden * (b - a);
        fc = Squared(s, c, x_m, y_m);
      } else {
        a = c;
        c = d;
        fc = fd;
        d = a + kGolden * (b - a);
        fd = Squared(s, d, x_m, y_m);
      }
    }
    double t = fc <= fd ? c : d;
    double f = std::min(fc, fd);
    // Newton on g(t) = (F - p) . F' (half the derivative of the squared
    // distance), g' = |F'|^2 + (F - p) . F'', inside the bracket, each step
    // kept only if it brings the robot nearer.
    for (int i = 0; i < 4; ++i) {
      const SegmentPoint q = EvaluateSegment(s, t);
      const double ex = q.x - x_m, ey = q.y - y_m;
      const double g = ex * q.dx + ey * q.dy;
      const double dg = q.dx * q.dx + q.dy * q.dy + ex * q.ddx + ey * q.ddy;
      if (!(dg > 0.0)) break;
      const double next = std::clamp(t - g / dg, lo, hi);
      const double fn = Squared(s, next, x_m, y_m);
      if (!(fn < f)) break;
      t = next;
      f = fn;
    }
    if (f < best) {
      best = f;
      best_t = t;
    }
  };
  double previous = Squared(s, 0.0, x_m, y_m);
  double current = Squared(s, h, x_m, y_m);
  if (previous <= current) refine(0.0, h);  // a minimum at or near the start
  for (std::size_t k = 1; k < samples; ++k) {
    const double t_next = static_cast<double>(k + 1) * h;
    const double next = Squared(s, t_next, x_m, y_m);
    if (current <= previous && current <= next) {
      refine(static_cast<double>(k - 1) * h, t_next);
    }
    previous = current;
    current = next;
  }
  if (current <= previous) refine(1.0 - h, 1.0);  // at or near the end
  return best_t;
}

double SegmentArcLength(const PolynomialSegment& s, double t0, double t1) {
  const GaussRule& g = Gauss();
  constexpr int kParts = 4;
  const double part = (t1 - t0) / kParts;
  double length = 0.0;
  for (int j = 0; j < kParts; ++j) {
    const double mid = t0 + (j + 0.5) * part;
    for (int i = 0; i < kGaussPoints; ++i) {
      const SegmentPoint p = EvaluateSegment(s, mid + 0.5 * part * g.node[i]);
      length += g.weight[i] * std::hypot(p.dx, p.dy);
    }
  }
  return 0.5 * part * length;
}

PolynomialSegment HermiteSegment(double x0, double y0, double yaw0, double x1, double y1,
                                 double yaw1, double tangent_m, int map) {
  const double length = tangent_m > 0.0 ? tangent_m : std::hypot(x1 - x0, y1 - y0);
  const double t0x = length * std::cos(yaw0), t0y = length * std::sin(yaw0);
  const double t1x = length * std::cos(yaw1), t1y = length * std::sin(yaw1);
  PolynomialSegment s;
  s.x = {x0, t0x, 3.0 * (x1 - x0) - 2.0 * t0x - t1x, 2.0 * (x0 - x1) + t0x + t1x};
  s.y = {y0, t0y, 3.0 * (y1 - y0) - 2.0 * t0y - t1y, 2.0 * (y0 - y1) + t0y + t1y};
  s.map = map;
  return s;
}

std::vector<Point2> SamplePolynomialPath(const std::vector<PolynomialSegment>& segments,
                                         double spacing_m, std::size_t max_per_segment) {
  std::vector<Point2> points;
  for (std::size_t k = 0; k < segments.size(); ++k) {
    const PolynomialSegment& s = segments[k];
    const double length = SegmentArcLength(s, 0.0, 1.0);
    // (less a rounding margin: 1 m at 0.1 m is 10 intervals, not 11)
    double wanted = spacing_m > 0.0 ? std::ceil(length / spacing_m - 1e-9) : 4.0;
    if (!std::isfinite(wanted)) wanted = static_cast<double>(max_per_segment);
    const std::size_t n = static_cast<std::size_t>(
        std::clamp(wanted, 4.0, static_cast<double>(std::max<std::size_t>(max_per_segment, 4))));
    for (std::size_t i = k == 0 ? 0 : 1; i <= n; ++i) {
      points.push_back(SegmentPosition(s, static_cast<double>(i) / static_cast<double>(n)));
    }
  }
  return points;
}

}  // namespace linesim::models
