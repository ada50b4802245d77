#include "units/estimation/scan_matcher.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace linesim::estimation {

bool SolveSymmetric3(const std::array<double, 6>& h, const std::array<double, 3>& b,
                     std::array<double, 3>& x) {
  // Cholesky H = L L^T.
  const double l00sq = h[0];
  if (!(l00sq > 0.0)) return false;
  const double l00 = std::sqrt(l00sq);
  const double l10 = h[1] / l00, l20 = h[2] / l00;
  const double l11sq = h[3] - l10 * l10;
  // Relative threshold: a pivot that lost all but ~1e-12 of its size is 0.
  if (!(l11sq > 1e-12 * h[3])) return false;
  const double l11 = std::sqrt(l11sq);
  const double l21 = (h[4] - l20 * l10) / l11;
  const double l22sq = h[5] - l20 * l20 - l21 * l21;
  if (!(l22sq > 1e-12 * h[5])) return false;
  const double l22 = std::sqrt(l22sq);
  const double z0 = b[0] / l00;
  const double z1 = (b[1] - l10 * z0) / l11;
  const double z2 = (b[2] - l20 * z0 - l21 * z1) / l22;
  x[2] = z2 / l22;
  x[1] = (z1 - l21 * x[2]) / l11;
  x[0] = (z0 - l10 * x[1] - l20 * x[2]) / l00;
  return true;
}

bool InverseSymmetric3(const std::array<double, 6>& h, std::array<double, 9>& inv) {
  for (int c = 0; c < 3; ++c) {
    std::array<double, 3> e{}, col{};
    e[static_cast<std::size_t>(c)] = 1.0;
    if (!SolveSymmetric3(h, e, col)) return false;
    for (int r = 0; r < 3; ++r)
      inv[static_cast<std::size_t>(3 * r + c)] = col[static_cast<std::size_t>(r)];
  }
  // Exactly symmetric (the column solves round differently).
  for (const auto& [a, b] : {std::pair{1, 3}, std::pair{2, 6}, std::pair{5, 7}}) {
    const double m = 0.5 * (inv[static_cast<std::size_t>(a)] + inv[static_cast<std::size_t>(b)]);
    inv[static_cast<std::size_t>(a)] = inv[static_cast<std::size_t>(b)] = m;
  }
  return true;
}

void ScanMatcher::Accumulate(int level, std::span<const double> px, std::span<const double> py,
                             const Pose& pose, std::array<double, 6>& h, std::array<double, 3>& b,
                             double& cost, int& on_map) const {
  const double c = std::cos(pose.yaw), s = std::sin(pose.yaw);
  double h00 = 0, h01 = 0, h02 = 0, h11 = 0, h12 = 0, h22 = 0, b0 = 0, b1 = 0, b2 = 0, sum = 0;
  int touched = 0;
  const std::size_t n = px.size();
  for (std::size_t i = 0; i < n; ++i) {
    // The point rotated (R p) and in map.
    const double rx = c * px[i] - s * py[i], ry = s * px[i] + c * py[i];
    double gx, gy;
    const double m = grid_.ValueAndGradient(level, pose.x + rx, pose.y + ry, gx, gy);
    const double r = 1.0 - m;
    // d S / d yaw = (-ry, rx).
    const double gt = -gx * ry + gy * rx;
    h00 += gx * gx;
    h01 += gx * gy;
    h02 += gx * gt;
    h11 += gy * gy;
    h12 += gy * gt;
    h22 += gt * gt;
    b0 += gx * r;
    b1 += gy * r;
    b2 += gt * r;
    sum += r * r;
    touched += (gx != 0.0 || gy != 0.0) ? 1 : 0;
  }
  h = {h00, h01, h02, h11, h12, h22};
  b = {b0, b1, b2};
  cost = sum;
  on_map = touched;
}

ScanMatcher::Result ScanMatcher::Match(std::span<const double> px, std::span<const double> py,
                                       Pose start) const {
  Result res;
  res.pose = start;
  res.points = static_cast<int>(std::min(px.size(), py.size()));
  px = px.first(static_cast<std::size_t>(res.points));
  py = py.first(static_cast<std::size_t>(res.points));
  std::array<double, 6> h{};
  std::array<double, 3> b{}, d{};
  double cost = 0.0;
  int on_map = 0;
  if (res.points == 0) {
    res.solved = false;
    return res;
  }
  for (int level = grid_.levels() - 1; level >= 0; --level) {
    const int iterations = level == 0 ? options_.fine_iterations : options_.coarse_iterations;
    // The finest level decides `solved`; a coarse level too sparse to solve
    // only hands its pose on.
    res.solved = true;
    for (int it = 0; it < iterations; ++it) {
      Accumulate(level, px, py, res.pose, h, b, cost, on_map);
      ++res.iterations;
      if (!SolveSymmetric3(h, b, d)) {
        res.solved = false;
        break;
      }
      d[2] = std::clamp(d[2], -options_.max_angle_step, options_.max_angle_step);
      res.pose.x += d[0];
      res.pose.y += d[1];
      res.pose.yaw += d[2];
      if (std::abs(d[0]) < options_.min_step_position &&
          std::abs(d[1]) < options_.min_step_position && std::abs(d[2]) < options_.min_step_yaw) {
        break;
      }
    }
  }
  // The Hessian and cost at the final pose, finest level.
  Accumulate(0, px, py, res.pose, h, b, cost, on_map);
  res.hessian = {h[0], h[1], h[2], h[1], h[3], h[4], h[2], h[4], h[5]};
  res.cost = cost / res.points;
  res.points_on_map = on_map;
  return res;
}

}  // namespace linesim::estimation
