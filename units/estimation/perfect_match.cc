#include "units/estimation/perfect_match.h"

#include <algorithm>
#include <cmath>

#include "units/estimation/scan_matcher.h"  // SolveSymmetric3, InverseSymmetric3

namespace linesim::estimation {

double PerfectMatch::Error(const DistanceMap& map, std::span<const double> px,
                           std::span<const double> py, const Pose& pose,
                           std::array<double, 3>& gradient) const {
  const double c2 = options_.c * options_.c;
  const double cs = std::cos(pose.yaw), sn = std::sin(pose.yaw);
  double e = 0.0, g0 = 0.0, g1 = 0.0, g2 = 0.0;
  const std::size_t n = std::min(px.size(), py.size());
  for (std::size_t i = 0; i < n; ++i) {
    const double rx = cs * px[i] - sn * py[i], ry = sn * px[i] + cs * py[i];
    double gx, gy;
    const double d = options_.gradient_tables
                         ? map.Lookup(pose.x + rx, pose.y + ry, gx, gy)
                         : map.LookupInterpolant(pose.x + rx, pose.y + ry, gx, gy);
    const double ef = c2 + d * d;
    e += 1.0 - c2 / ef;
    // d/dd of 1 - c^2 / (c^2 + d^2) = 2 c^2 d / (c^2 + d^2)^2; the point
    // moves with theta by (-ry, rx).
    const double de = 2.0 * c2 * d / (ef * ef);
    g0 += de * gx;
    g1 += de * gy;
    g2 += de * (-gx * ry + gy * rx);
  }
  gradient = {g0, g1, g2};
  return e;
}

void PerfectMatch::Gradient(const DistanceMap& map, std::span<const double> px,
                            std::span<const double> py, const Pose& pose,
                            std::array<double, 3>& gradient, std::size_t stride) const {
  // As Error without E: one division per point (RPROP needs the signs).
  const double c2 = options_.c * options_.c;
  const double cs = std::cos(pose.yaw), sn = std::sin(pose.yaw);
  double g0 = 0.0, g1 = 0.0, g2 = 0.0;
  const std::size_t n = std::min(px.size(), py.size());
  for (std::size_t i = 0; i < n; i += stride) {
    const double rx = cs * px[i] - sn * py[i], ry = sn * px[i] + cs * py[i];
    double gx, gy;
    const double d = options_.gradient_tables
                         ? map.Lookup(pose.x + rx, pose.y + ry, gx, gy)
                         : map.LookupInterpolant(pose.x + rx, pose.y + ry, gx, gy);
    const double inv = 1.0 / (c2 + d * d);
    const double de = 2.0 * c2 * d * inv * inv;
    g0 += de * gx;
    g1 += de * gy;
    g2 += de * (-gx * ry + gy * rx);
  }
  gradient = {g0, g1, g2};
}

PerfectMatch::Normal PerfectMatch::Accumulate(const DistanceMap& map, std::span<const double> px,
                                              std::span<const double> py, const Pose& pose,
                                              double ox, double oy, bool bias) const {
  const double c2 = options_.c * options_.c, c4 = c2 * c2;
  const double cs = std::cos(pose.yaw), sn = std::sin(pose.yaw);
  double a00 = 0, a01 = 0, a02 = 0, a11 = 0, a12 = 0, a22 = 0, b0 = 0, b1 = 0, b2 = 0;
  double k0 = 0, k1 = 0, k2 = 0;
  Normal r;
  const std::size_t n = std::min(px.size(), py.size());
  for (std::size_t i = 0; i < n; ++i) {
    const double rx = cs * px[i] - sn * py[i], ry = sn * px[i] + cs * py[i];
    double gx, gy;
    const double d = options_.gradient_tables
                         ? map.Lookup(pose.x + rx, pose.y + ry, gx, gy)
                         : map.LookupInterpolant(pose.x + rx, pose.y + ry, gx, gy);
    if (d >= DistanceMap::kFar) {
      r.error += 1.0 - c2 / (c2 + d * d);
      continue;
    }
    ++r.on_map;
    const double ef = c2 + d * d;
    r.error += 1.0 - c2 / ef;
    const double u = c4 / (ef * ef);
    const double j2 = -gx * ry + gy * rx;
    a00 += u * gx * gx;
    a01 += u * gx * gy;
    a02 += u * gx * j2;
    a11 += u * gy * gy;
    a12 += u * gy * j2;
    a22 += u * j2 * j2;
    b0 += u * d * gx;
    b1 += u * d * gy;
    b2 += u * d * j2;
    r.udd += u * d * d;
    r.u += u;
    if (!bias) continue;
    // The beam's direction in map: R (p - o) / |p - o|.
    const double bx = px[i] - ox, by = py[i] - oy;
    const double len = std::sqrt(bx * bx + by * by);
    if (len > 0.0) {
      const double kappa = (gx * (cs * bx - sn * by) + gy * (sn * bx + cs * by)) / len;
      const double kd = u * kappa;
      k0 += kd * gx;
      k1 += kd * gy;
      k2 += kd * j2;
      r.ukk += kd * kappa;
      r.ukd += kd * d;
    }
  }
  r.a = {a00, a01, a02, a11, a12, a22};
  r.b = {b0, b1, b2};
  r.k = {k0, k1, k2};
  r.bias = bias;
  return r;
}

PerfectMatch::Result PerfectMatch::Match(const DistanceMap& map, std::span<const double> px,
                                         std::span<const double> py, Pose start, double origin_x,
                                         double origin_y) const {
  Result res;
  res.points = static_cast<int>(std::min(px.size(), py.size()));
  double param[3] = {start.x, start.y, start.yaw};
  double step[3] = {options_.step_x, options_.step_y, options_.step_yaw};
  double last[3] = {0.0, 0.0, 0.0};
  const int iterations =
      res.points > options_.few_points ? options_.iterations : options_.few_iterations;
  std::array<double, 3> g{};
  // RPROP as Tribots' VisualPositionOptimiser::optimise.
  for (int it = 0; it < iterations; ++it) {
    Gradient(map, px, py, {param[0], param[1], param[2]}, g,
             static_cast<std::size_t>(std::max(1, options_.rprop_stride)));
    for (int j = 0; j < 3; ++j) {
      const double gj = g[static_cast<std::size_t>(j)];
      if (gj == 0.0) {
        last[j] = 0.0;
        continue;
      }
      if (gj * last[j] > 0.0) {
        step[j] *= options_.grow;
      } else if (gj * last[j] < 0.0) {
        step[j] *= options_.shrink;
      }
      last[j] = gj;
      param[j] += gj > 0.0 ? -step[j] : step[j];
    }
    ++res.iterations;
  }
  res.final_steps = {step[0], step[1], step[2]};
  Pose pose{param[0], param[1], param[2]};
  // Reweighted Gauss-Newton refinement, then the curvature at the end.
  const int refine = options_.refine_iterations;
  Normal nm = Accumulate(map, px, py, pose, origin_x, origin_y, refine == 0);
  for (int it = 0; it < refine; ++it) {
    std::array<double, 3> dx{};
    if (!SolveSymmetric3(nm.a, nm.b, dx)) break;
    // A step beyond RPROP's first steps leaves the quadratic model: refused.
    if (!(std::abs(dx[0]) <= options_.step_x && std::abs(dx[1]) <= options_.step_y &&
          std::abs(dx[2]) <= options_.step_yaw)) {
      break;
    }
    pose = {pose.x - dx[0], pose.y - dx[1], pose.yaw - dx[2]};
    nm = Accumulate(map, px, py, pose, origin_x, origin_y, it + 1 == refine);
    ++res.iterations;
  }
  // (A refinement refused before its last step: the bias sums once more.)
  if (!nm.bias) nm = Accumulate(map, px, py, pose, origin_x, origin_y, true);
  res.pose = pose;
  res.error = nm.error;
  res.mean_error = res.points > 0 ? nm.error / res.points : 0.0;
  res.points_on_map = nm.on_map;
  res.inlier_weight = nm.u;
  const double scale = 2.0 / (options_.c * options_.c);
  const std::array<int, 9> full = {0, 1, 2, 1, 3, 4, 2, 4, 5};
  for (std::size_t k = 0; k < 9; ++k)
    res.hessian[k] = scale * nm.a[static_cast<std::size_t>(full[k])];
  std::array<double, 9> inv{};
  res.ok = nm.u > 4.0 && InverseSymmetric3(nm.a, inv);
  if (res.ok) {
    // The residuals with a common range bias fitted too (see the header).
    double ktak = 0.0;
    for (std::size_t r = 0; r < 3; ++r) {
      for (std::size_t c = 0; c < 3; ++c) ktak += nm.k[r] * inv[3 * r + c] * nm.k[c];
    }
    const double perp = nm.ukk - ktak;
    double rss = nm.udd;
    if (perp > 1e-12 * nm.ukk) rss = std::max(0.0, rss - nm.ukd * nm.ukd / perp);
    res.residual_variance = rss / (nm.u - 4.0);
    for (std::size_t k = 0; k < 9; ++k) res.covariance[k] = res.residual_variance * inv[k];
    for (std::size_t r = 0; r < 3; ++r) {
      res.bias_sensitivity[r] =
          -(inv[3 * r] * nm.k[0] + inv[3 * r + 1] * nm.k[1] + inv[3 * r + 2] * nm.k[2]);
    }
  }
  return res;
}

}  // namespace linesim::estimation
