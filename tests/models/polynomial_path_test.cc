#include "models/polynomial_path.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

namespace linesim::models {
namespace {

constexpr double kPi = std::numbers::pi;

// A quarter circle of radius r about the origin, counter-clockwise from
// (r, 0) to (0, r), as the Taylor polynomials of degree 15 of r cos(pi t / 2)
// and r sin(pi t / 2): the remainder at t = 1 is below r (pi/2)^16 / 16! =
// 7e-11 r, and below 1e-8 r in the second derivative.
PolynomialSegment QuarterCircle(double r) {
  PolynomialSegment s;
  s.x.assign(16, 0.0);
  s.y.assign(16, 0.0);
  double term = r;  // r (pi/2)^i / i!
  for (int i = 0; i < 16; ++i) {
    if (i > 0) term *= (kPi / 2) / i;
    const int phase = i % 4;  // cos: + 0 - 0, sin: 0 + 0 -
    s.x[i] = phase == 0 ? term : phase == 2 ? -term : 0.0;
    s.y[i] = phase == 1 ? term : phase == 3 ? -term : 0.0;
  }
  return s;
}

// Guards the Horner evaluation of a polynomial and its two derivatives
// against the closed forms of p(t) = 2 - t + 3 t^2 + 5 t^3.
TEST(PolynomialPath, PolynomialAndDerivatives) {
  double v, d1, d2;
  EvaluatePolynomial({2, -1, 3, 5}, 0.7, v, d1, d2);
  EXPECT_NEAR(v, 2 - 0.7 + 3 * 0.49 + 5 * 0.343, 1e-14);
  EXPECT_NEAR(d1, -1 + 6 * 0.7 + 15 * 0.49, 1e-14);
  EXPECT_NEAR(d2, 6 + 30 * 0.7, 1e-14);
  EvaluatePolynomial({}, 0.5, v, d1, d2);
  EXPECT_EQ(v, 0.0);
}

// Guards Eq. 7's argument order: F_theta is the heading of the tangent in
// the map frame (a line at 30 deg gives 30 deg, not 60 deg), and Eq. 17 is V
// times the curvature: on a circle of radius 2 m at 0.3 m/s, 0.15 rad/s,
// counter-clockwise positive; the heading at t = 0.5 is 135 deg.
TEST(PolynomialPath, HeadingAndFeedForwardOnACircle) {
  PolynomialSegment line{{1.0, std::cos(kPi / 6)}, {2.0, std::sin(kPi / 6)}, 0};
  EXPECT_NEAR(SegmentHeading(EvaluateSegment(line, 0.3)), kPi / 6, 1e-15);
  EXPECT_EQ(FeedForward(0.3, EvaluateSegment(line, 0.3)), 0.0);

  const PolynomialSegment circle = QuarterCircle(2.0);
  for (const double t : {0.0, 0.25, 0.5, 0.9, 1.0}) {
    const SegmentPoint p = EvaluateSegment(circle, t);
    EXPECT_NEAR(std::hypot(p.x, p.y), 2.0, 1e-9) << t;
    EXPECT_NEAR(FeedForward(0.3, p), 0.3 / 2.0, 1e-8) << t;
    EXPECT_NEAR(SegmentCurvature(p), 0.5, 1e-8) << t;
  }
  EXPECT_NEAR(SegmentHeading(EvaluateSegment(circle, 0.5)), 3 * kPi / 4, 1e-9);
  // Clockwise (the mirror image, y -> -y): the curvature changes sign.
  PolynomialSegment mirrored = circle;
  for (double& b : mirrored.y) b = -b;
  EXPECT_NEAR(FeedForward(0.3, EvaluateSegment(mirrored, 0.4)), -0.15, 1e-8);
  // Arc length of the quarter: pi r / 2.
  EXPECT_NEAR(SegmentArcLength(circle, 0.0, 1.0), kPi, 1e-9);
}

// Guards Eq. 17 on a parabola y = a x^2 (Fx = t, Fy = a t^2): curvature
// 2a / (1 + 4 a^2 x^2)^(3/2) (the textbook formula of a graph y(x)).
TEST(PolynomialPath, FeedForwardOnAParabola) {
  const double a = 1.5;
  const PolynomialSegment parabola{{0.0, 1.0}, {0.0, 0.0, a}, 0};
  for (const double t : {0.0, 0.3, 0.8}) {
    const double expected = 2 * a / std::pow(1 + 4 * a * a * t * t, 1.5);
    EXPECT_NEAR(FeedForward(0.4, EvaluateSegment(parabola, t)), 0.4 * expected, 1e-14) << t;
  }
}

// Guards the closest-parameter search against stopping at a local minimum.
// On the S-curve Fx = 3t, Fy = 10 t (t - 0.5)(t - 1) the point (1.2, -0.9)
// has a local minimum of the distance at t = 0 (g(0) = (F - p) . F' = 0.9 > 0:
// a local method from t = 0 stays there, 1.5 m away) and the global one
// inside, near t = 0.57 (0.89 m). The reference is a brute-force scan of
// 2 million samples.
TEST(PolynomialPath, ClosestParameterFindsTheGlobalMinimum) {
  const PolynomialSegment s{{0.0, 3.0}, {0.0, 5.0, -15.0, 10.0}, 0};
  const auto distance = [&](double t) {
    const Point2 f = SegmentPosition(s, t);
    return std::hypot(f[0] - 1.2, f[1] + 0.9);
  };
  // A local descent from t = 0 does not move.
  EXPECT_GT(distance(1e-4), distance(0.0));
  double best_t = 0.0, best = distance(0.0);
  for (int k = 1; k <= 2000000; ++k) {
    const double t = k / 2e6;
    if (distance(t) < best) best = distance(best_t = t);
  }
  EXPECT_GT(best_t, 0.5);
  EXPECT_LT(best, 0.9);
  const double t_n = ClosestParameter(s, 1.2, -0.9);
  EXPECT_NEAR(t_n, best_t, 1e-6);
  EXPECT_LE(distance(t_n), best + 1e-12);

  // A loop-like parabola x = 8 t (1 - t), y = 2 t - 1 seen from (-0.5, 0.5):
  // the distance increases from t = 0 (local minimum 1.58 m); the global one
  // is the end t = 1 (0.71 m), returned exactly.
  const PolynomialSegment loop{{0.0, 8.0, -8.0}, {-1.0, 2.0}, 0};
  EXPECT_EQ(ClosestParameter(loop, -0.5, 0.5), 1.0);
  // Before the start of a straight segment: exactly 0.
  const PolynomialSegment line{{0.0, 2.0}, {0.0}, 0};
  EXPECT_EQ(ClosestParameter(line, -0.3, 0.1), 0.0);
  EXPECT_NEAR(ClosestParameter(line, 1.5, 0.4), 0.75, 1e-12);
}

// Guards the Hermite edge: the end poses and tangents (length = chord by
// default), and a straight edge between aligned poses is the line itself,
// traversed at constant speed (a Hermite cubic with both tangents equal to
// the chord reduces to p0 + t (p1 - p0)).
TEST(PolynomialPath, HermiteSegmentMatchesThePoses) {
  const PolynomialSegment s = HermiteSegment(-1.5, -1.0, 0.0, 1.4, 0.0, 0.0);
  const SegmentPoint a = EvaluateSegment(s, 0.0), b = EvaluateSegment(s, 1.0);
  const double chord = std::hypot(2.9, 1.0);
  EXPECT_NEAR(a.x, -1.5, 1e-15);
  EXPECT_NEAR(a.y, -1.0, 1e-15);
  EXPECT_NEAR(b.x, 1.4, 1e-14);
  EXPECT_NEAR(b.y, 0.0, 1e-14);
  EXPECT_NEAR(a.dx, chord, 1e-14);
  EXPECT_NEAR(a.dy, 0.0, 1e-15);
  EXPECT_NEAR(b.dx, chord, 1e-14);
  EXPECT_NEAR(b.dy, 0.0, 1e-14);
  const PolynomialSegment straight = HermiteSegment(1.4, 0.0, 0.0, 4.4, 0.0, 0.0);
  EXPECT_NEAR(straight.x[2], 0.0, 1e-15);
  EXPECT_NEAR(straight.x[3], 0.0, 1e-15);
  EXPECT_NEAR(SegmentPosition(straight, 0.25)[0], 2.15, 1e-15);
  const PolynomialSegment longer = HermiteSegment(0, 0, kPi / 2, 1, 1, 0, 3.0, 2);
  EXPECT_NEAR(EvaluateSegment(longer, 0.0).dy, 3.0, 1e-15);
  EXPECT_EQ(longer.map, 2);
}

// Guards the sampling for plots: the joint is listed once, the ends are the
// path's, spacing about as asked.
TEST(PolynomialPath, SamplesAPathOnce) {
  const std::vector<PolynomialSegment> path = {HermiteSegment(0, 0, 0, 1, 0, 0),
                                               HermiteSegment(1, 0, 0, 3, 0, 0)};
  const std::vector<Point2> points = SamplePolynomialPath(path, 0.1);
  ASSERT_EQ(points.size(), 1u + 10u + 20u);
  EXPECT_NEAR(points.front()[0], 0.0, 1e-15);
  EXPECT_NEAR(points[10][0], 1.0, 1e-14);
  EXPECT_NEAR(points.back()[0], 3.0, 1e-14);
}

}  // namespace
}  // namespace linesim::models
