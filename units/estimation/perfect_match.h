#pragma once

#include <array>
#include <span>

#include "units/estimation/distance_map.h"

namespace linesim::estimation {

/// Perfect Match (Lauer, Lange, Riedmiller 2005, "Calculating the perfect
/// match: an efficient and accurate approach for robot self-localization",
/// RoboCup 2005; the localization of paper 2, Sobreira et al. 2019, Sec. 4):
/// the pose xi = (x, y, theta) of base_link minimising
///   E(xi) = sum_i 1 - c^2 / (c^2 + d_i^2),   d_i = D(R(theta) p_i + (x, y)),
/// p_i the scan points in base_link, D the distance map (DistanceMap), c the
/// error's scale (0.25 m in the authors' Tribots code). The error saturates
/// at 1 for far points: outliers (things not in the map) pull little.
///
/// Minimisation as the authors' Tribots code (VisualPositionOptimiser::
/// optimise): RPROP on the gradient of E over (x, y, theta), initial steps
/// 40 mm, 40 mm, 0.1 rad, a step x 1.2 when its gradient's sign is
/// unchanged, x 0.5 when it flipped, the parameter moved against the
/// gradient's sign; 10 iterations, 20 with 20 points or fewer. Left out:
/// Tribots' heading prior (a camera robot's compass term) and its per-point
/// distance weights (for camera line points; a laser's beams are uniform).
///
/// Refinement (ours; `refine_iterations`, 0 = Tribots' RPROP alone): RPROP
/// ends within about its last step of the optimum (9 mm and 4 mrad after 10
/// iterations in the tests, its last steps 6 mm and 6 mrad), more than the
/// matches' own scatter for a 541-beam LMS151 scan (about 1.7 mm), which a
/// fusion filter would take as unmodelled error. Default 1 step (it ends
/// within 0.02 mm of the optimum of an exact scan; a second changed the
/// bench's match by 0.1 mm). Each refinement is one iteratively reweighted
/// Gauss-Newton step on the same E: dE/dxi = sum rho'(d_i) J_i = 0 with
/// rho'(d) = (2 / c^2) u(d) d, u(d) = c^4 / (c^2 + d^2)^2, so the step
///   dxi = -(sum u_i J_i J_i^T)^-1 sum u_i d_i J_i,  J_i = dd_i/dxi,
/// whose fixed point is E's stationary point.
///
/// Covariance (SI, row-major x, y, theta): the curvature of E at the
/// optimum, Gauss-Newton part (the map's own second derivatives left out,
/// as Tribots' analyse does), H = (2 / c^2) sum u_i J_i J_i^T (for
/// |d| << c the Hessian of E: rho''(0) = 2 / c^2), scaled by the residual
/// variance of the distances:
///   C = s^2 (2 / c^2) H^-1 = s^2 (sum u_i J_i J_i^T)^-1,
///   s^2 = RSS / (sum u_i - 4),
/// RSS the weighted residual sum of squares of the distances after fitting
/// the pose AND a range bias common to the beams (weighted least squares in
/// d: the weights u, near 1 for inliers, take outliers out of both). Why
/// the bias in the fit: a range bias (the LMS151's systematic error) that
/// the pose cannot absorb is left in the residuals and would inflate s^2,
/// though it is not independent per beam; it enters the covariance through
/// bias_sensitivity instead. With kappa_i = d d_i / d b = grad d_i . R
/// rhat_i and the pose's normal equations A, K = sum u J kappa:
///   RSS = sum u d^2 - (sum u kappa d)^2 / (sum u kappa^2 - K^T A^-1 K)
/// (d orthogonal to J at the optimum). It treats the beams as independent and the map as
/// exact: correlated errors (a range bias, the map's own error) are not in
/// it; the unit adds floors for them.
///
/// Allocation-free: points come in as spans.
class PerfectMatch {
 public:
  struct Options {
    double c = 0.25;          // m, Tribots
    double step_x = 0.04;     // m, RPROP's initial steps (Tribots: 40 mm, 40 mm, 0.1 rad)
    double step_y = 0.04;     // m
    double step_yaw = 0.1;    // rad
    double grow = 1.2;        // RPROP eta+ (Tribots)
    double shrink = 0.5;      // RPROP eta- (Tribots)
    int iterations = 10;      // Tribots: 10 with more than `few_points` points,
    int few_iterations = 20;  // 20 with fewer
    int few_points = 20;
    int refine_iterations = 1;  // Gauss-Newton steps after RPROP (ours)
    /// RPROP's gradient over every `rprop_stride`-th point only (the
    /// refinement and the covariance always take every point): RPROP only
    /// needs the gradient's signs to close in on the optimum, which the
    /// refinement then reaches with all points (ours; see
    /// bench/perfect_match_bench.cc for the cost and the tests for the
    /// accuracy).
    int rprop_stride = 1;
    /// true: d's gradient from the gradient tables (Tribots); false: the
    /// bilinear interpolant's own derivative (measured: the same accuracy,
    /// about 5 % cheaper; see bench/perfect_match_bench.cc).
    bool gradient_tables = true;
  };
  struct Pose {
    double x = 0.0, y = 0.0, yaw = 0.0;
  };
  struct Result {
    Pose pose;
    /// E at the final pose (sum over the points of 1 - c^2 / (c^2 + d^2)).
    double error = 0.0;
    /// E / points, in [0, 1]: the match's quality (0 perfect).
    double mean_error = 0.0;
    /// H (SI: 1/m^2, 1/(m rad), 1/rad^2), row-major.
    std::array<double, 9> hessian{};
    /// C = s^2 (2 / c^2) H^-1 (m^2, m rad, rad^2), row-major.
    std::array<double, 9> covariance{};
    /// s^2 (m^2), the weighted residual variance of the distances (pose and
    /// bias fitted).
    double residual_variance = 0.0;
    /// sum u_i: the points that count (inliers, each near 1).
    double inlier_weight = 0.0;
    int points = 0;
    /// Points on the map's grid at the end.
    int points_on_map = 0;
    /// False when H is not positive definite (too few or degenerate points).
    bool ok = false;
    int iterations = 0;
    /// RPROP's step widths at its end (m, m, rad).
    std::array<double, 3> final_steps{};
    /// g = d pose / d b for a range bias b common to all beams (every point
    /// moved by b along its beam from the laser origin): to first order
    /// g = -A^-1 sum u_i J_i (grad d_i . R rhat_i), A = sum u J J^T
    /// (m/m, m/m, rad/m). A bias of sigma_b adds sigma_b^2 g g^T to the
    /// covariance: an error common to the beams, which s^2 A^-1 misses.
    std::array<double, 3> bias_sensitivity{};
  };

  explicit PerfectMatch(Options options) : options_(options) {}

  /// The points px, py in base_link; (origin_x, origin_y) the laser's
  /// origin in base_link (for bias_sensitivity only).
  Result Match(const DistanceMap& map, std::span<const double> px, std::span<const double> py,
               Pose start, double origin_x = 0.0, double origin_y = 0.0) const;

  /// E and its gradient at `pose` (m, m, rad).
  double Error(const DistanceMap& map, std::span<const double> px, std::span<const double> py,
               const Pose& pose, std::array<double, 3>& gradient) const;

  const Options& options() const { return options_; }

 private:
  /// The weighted normal equations at `pose`: a = sum u J J^T (upper
  /// triangle), b = sum u d J, sum u d^2, sum u, E, points on the map.
  struct Normal {
    std::array<double, 6> a{};
    std::array<double, 3> b{};
    std::array<double, 3> k{};    // sum u J kappa, kappa = grad d . R rhat (d d / d bias)
    double ukk = 0.0, ukd = 0.0;  // sum u kappa^2, sum u kappa d
    bool bias = false;            // whether k, ukk, ukd were summed
    double udd = 0.0, u = 0.0, error = 0.0;
    int on_map = 0;
  };
  Normal Accumulate(const DistanceMap& map, std::span<const double> px, std::span<const double> py,
                    const Pose& pose, double ox, double oy, bool bias) const;
  void Gradient(const DistanceMap& map, std::span<const double> px, std::span<const double> py,
                const Pose& pose, std::array<double, 3>& gradient,
                std::size_t stride = 1) const;

  Options options_;
};

}  // namespace linesim::estimation
