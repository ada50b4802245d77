#pragma once

#include <array>
#include <span>

#include "units/estimation/occupancy_grid.h"

namespace linesim::estimation {

/// hector_mapping's scan matcher (Kohlbrecher et al., "A flexible and
/// scalable SLAM system with full 3D motion estimation", SSRR 2011, Sec.
/// IV-B; ScanMatcher.h): Gauss-Newton on
///   sum_i (1 - M(S_i(xi)))^2,  S_i(xi) = R(yaw) p_i + (x, y),
/// p_i the scan points in base_link, M the bilinear map value
/// (OccupancyGrid::ValueAndGradient), coarse to fine over the map's levels.
/// Per iteration: H = sum J_i^T J_i, b = sum J_i^T (1 - M_i) with
/// J_i = grad M (S_i) dS_i/dxi, dxi = H^-1 b, the yaw step clamped to
/// +-max_angle_step (hector's 0.2 rad), xi += dxi. Everything is in SI (the
/// gradient in 1/m), so H comes out in 1/m^2, 1/(m rad), 1/rad^2 directly.
///
/// Early exit (our addition, not hector's): a level's iterations stop once an
/// update moves less than min_step_position and min_step_yaw (defaults 0.1 mm
/// and 0.1 mrad: a hundredth of the finest cell; what is left is below the
/// accuracy the map allows, see the tests).
///
/// Allocation-free: the points come in as spans, nothing is stored per match.
class ScanMatcher {
 public:
  struct Options {
    int coarse_iterations = 3;        // hector: 3 on each coarser level
    int fine_iterations = 5;          // hector: 5 on the finest
    double max_angle_step = 0.2;      // rad, hector's clamp
    double min_step_position = 1e-4;  // m
    double min_step_yaw = 1e-4;       // rad
  };
  struct Pose {
    double x = 0.0, y = 0.0, yaw = 0.0;
  };
  struct Result {
    Pose pose;
    /// sum J^T J at the final pose on the finest level, row-major (x, y, yaw),
    /// SI: 1/m^2, 1/(m rad), 1/rad^2.
    std::array<double, 9> hessian{};
    /// Mean of (1 - M)^2 over the points at the final pose, finest level.
    double cost = 0.0;
    /// Points matched (those given).
    int points = 0;
    /// Points whose 2 x 2 nodes touch the map (non-zero gradient) at the end.
    int points_on_map = 0;
    /// False when a Gauss-Newton system was singular (the pose is then the
    /// last one reached).
    bool solved = true;
    /// Gauss-Newton iterations run over all levels (early exits included).
    int iterations = 0;
  };

  ScanMatcher(const OccupancyGrid& grid, Options options) : grid_(grid), options_(options) {}

  /// Matches the points (base_link, m; px and py of the same size) from the
  /// start pose.
  Result Match(std::span<const double> px, std::span<const double> py, Pose start) const;

  const Options& options() const { return options_; }

 private:
  /// H, b and the summed squared residual at `pose` on level `level`.
  void Accumulate(int level, std::span<const double> px, std::span<const double> py,
                  const Pose& pose, std::array<double, 6>& h, std::array<double, 3>& b,
                  double& cost, int& on_map) const;

  const OccupancyGrid& grid_;
  Options options_;
};

/// Solves the symmetric 3 x 3 system H x = b given as its upper triangle
/// (h00, h01, h02, h11, h12, h22); false when it is singular or not positive
/// definite (Cholesky).
bool SolveSymmetric3(const std::array<double, 6>& h, const std::array<double, 3>& b,
                     std::array<double, 3>& x);
/// The inverse of a symmetric positive definite 3 x 3 (upper triangle in,
/// full row-major out); false when not positive definite.
bool InverseSymmetric3(const std::array<double, 6>& h, std::array<double, 9>& inv);

}  // namespace linesim::estimation
