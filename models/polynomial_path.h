#pragma once

#include <cstddef>
#include <vector>

#include "models/polyline.h"

/// Parametric polynomial paths (paper 2, Sobreira et al. 2019, "Autonomous
/// Robot Navigation for Automotive Assembly Task: An Industry Use-Case",
/// Sec. 5, Eqs. 2-4, 7-9, 15-17): a segment is
///   Fx(t) = sum_i A_i t^i,  Fy(t) = sum_i B_i t^i,  t in [0, 1],
/// in the map frame (m). Pure functions, no allocation except where said.
namespace linesim::models {

/// Most coefficients per coordinate (degree 15): beyond it the monomial
/// basis on [0, 1] loses digits, and the closest-point search is sized for it.
inline constexpr std::size_t kMaxPolynomialCoefficients = 16;

struct PolynomialSegment {
  std::vector<double> x;  // A_0 .. A_{n-1} (m)
  std::vector<double> y;  // B_0 .. B_{n-1} (m)
  int map = 0;            // index of the localization map this segment is driven on
};

/// F, F' and F'' of a segment at one t (Eqs. 3-4, 8-9 and their derivatives).
struct SegmentPoint {
  double x = 0, y = 0;      // m
  double dx = 0, dy = 0;    // m per unit t
  double ddx = 0, ddy = 0;  // m per unit t^2
};

/// The polynomial sum c_i t^i and its first two derivatives (Horner).
void EvaluatePolynomial(const std::vector<double>& c, double t, double& value, double& first,
                        double& second);
SegmentPoint EvaluateSegment(const PolynomialSegment& s, double t);
/// Fx(t), Fy(t) only.
Point2 SegmentPosition(const PolynomialSegment& s, double t);
/// max(len x, len y) - 1 (0 for a point).
std::size_t SegmentDegree(const PolynomialSegment& s);

/// Eq. 7, F_theta: the heading of the tangent in the map frame, measured
/// from +x counter-clockwise, std::atan2(Fy', Fx'). The paper writes
/// Atan2(dFx, dFy): its Atan2 takes (x, y) (as a spreadsheet's ATAN2
/// does); in C's atan2(y, x) order the tangent's heading is atan2(dFy, dFx).
/// Eq. 16 (dF_theta/dt = (Fy'' Fx' - Fx'' Fy') / |F'|^2) is the derivative of
/// exactly this angle, and Eq. 12's branch (T_theta > 0: the path is to the
/// robot's left, steer left) holds only with it. Where F' vanishes (a cusp)
/// the limit direction F'' is used.
double SegmentHeading(const SegmentPoint& p);
/// The signed curvature (1/m, + turning left): (Fy'' Fx' - Fx'' Fy') /
/// |F'|^3, 0 where F' vanishes.
double SegmentCurvature(const SegmentPoint& p);
/// Eq. 17: the feed-forward yaw rate V (Fy'' Fx' - Fx'' Fy') / |F'|^3 =
/// V times the curvature (rad/s for V in m/s).
double FeedForward(double speed_mps, const SegmentPoint& p);

/// The parameter t_n in [0, 1] of the segment point nearest to (x_m, y_m)
/// (paper 2: "the parameter t which minimizes the distance"): the global
/// minimum of |F(t) - p|^2, which for a polynomial of degree d can have up
/// to d local minima on [0, 1]. The search: both ends are candidates
/// (exactly 0 and 1); the squared distance is sampled at 16 (d + 1) + 1
/// evenly spaced t; each sample not above its neighbours brackets a
/// candidate, refined by golden section on the bracket (two sample
/// intervals) and polished by Newton steps on the stationarity condition
/// (F - p) . F' = 0 kept inside the bracket. The nearest candidate wins
/// (the first of equals). A minimum is missed only when two minima lie
/// within one sample interval of each other, where their distances differ
/// by a fraction of a sample's chord. No allocation.
double ClosestParameter(const PolynomialSegment& s, double x_m, double y_m);

/// Arc length of the segment between t0 and t1 (m): 16-point Gauss-Legendre
/// quadrature of |F'| on each of 4 equal sub-intervals (|F'| is smooth: for
/// the cubics of the graph files the error is below 1e-9 of the length).
double SegmentArcLength(const PolynomialSegment& s, double t0, double t1);

/// The cubic Hermite segment from pose 0 to pose 1 (positions in m, headings
/// in rad, map frame): F(0) = p0, F(1) = p1, F'(0) = L (cos yaw0, sin yaw0),
/// F'(1) = L (cos yaw1, sin yaw1), L = tangent_m, or the chord |p1 - p0|
/// when tangent_m <= 0. Coefficients:
///   A0 = x0, A1 = T0x, A2 = 3 (x1 - x0) - 2 T0x - T1x, A3 = 2 (x0 - x1) + T0x + T1x
/// (likewise B with y).
PolynomialSegment HermiteSegment(double x0, double y0, double yaw0, double x1, double y1,
                                 double yaw1, double tangent_m = 0.0, int map = 0);

/// The segments sampled as one polyline for drawing and for the deviation
/// from the path: each segment at n + 1 evenly spaced t, n = clamp(ceil(
/// length / spacing_m), 4, max_per_segment); the joint of two segments once.
/// A chord of length h on a curve of curvature k is off it by k h^2 / 8.
std::vector<Point2> SamplePolynomialPath(const std::vector<PolynomialSegment>& segments,
                                         double spacing_m, std::size_t max_per_segment = 2000);

}  // namespace linesim::models
