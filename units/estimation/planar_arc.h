#pragma once

#include <cmath>

namespace linesim::estimation {

/// The displacement (dx, dy), in the body frame at the start, of a body
/// moving with the constant body twist (vx, vy, omega) for dt seconds: the
/// exact arc
///   dx = (sin(u) vx - (1 - cos(u)) vy) / omega,
///   dy = ((1 - cos(u)) vx + sin(u) vy) / omega,   u = omega dt,
/// with its Taylor series (error below 1e-16 relative) for |u| < 1e-4.
/// Arcs compose exactly: dt1 then dt2 from the pose reached is dt1 + dt2.
inline void ArcDisplacement(double vx, double vy, double omega, double dt_s, double* dx,
                            double* dy) {
  const double u = omega * dt_s;
  double s, c;  // sin(u) / omega and (1 - cos(u)) / omega
  if (std::abs(u) < 1e-4) {
    const double u2 = u * u;
    s = dt_s * (1.0 - u2 / 6.0);
    c = dt_s * u * (0.5 - u2 / 24.0);
  } else {
    s = std::sin(u) / omega;
    c = (1.0 - std::cos(u)) / omega;
  }
  *dx = s * vx - c * vy;
  *dy = c * vx + s * vy;
}

}  // namespace linesim::estimation
