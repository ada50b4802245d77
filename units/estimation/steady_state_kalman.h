#pragma once

#include <cmath>

namespace linesim::estimation {

/// A scalar steady-state Kalman filter for a random-walk state (paper 1,
/// Sec. IV-A: the surface velocity, "a discrete-time, steady-state Kalman
/// filter", equivalent to a first-order low-pass filter):
///   x_k = x_{k-1} + w_k,  w_k ~ N(0, q)   (q: process variance per sample)
///   z_k = x_k + v_k,      v_k ~ N(0, r)   (r: measurement variance)
///
/// The gain is the fixed point of the scalar discrete Riccati recursion
///   P-_{k+1} = P_k + q,   P_k = P-_k r / (P-_k + r),
/// i.e. (P- - q)(P- + r) = P- r, or P-^2 - q P- - q r = 0, whose positive
/// root is
///   P- = (q + sqrt(q^2 + 4 q r)) / 2,   K = P- / (P- + r),
///   P = (1 - K) P- = K r  (a posteriori variance).
/// Paper 1's figures (3 sigma = 1 cm/s per sample, sigma_z = 3 cm/s):
/// q = (0.01 / 3)^2, r = 0.03^2 give K = 0.1051.
///
/// On a constant input with white measurement noise of variance r the
/// output x_k = (1 - K) x_{k-1} + K z_k has the variance
///   K^2 r / (1 - (1 - K)^2) = K r / (2 - K).
class SteadyStateKalman {
 public:
  /// The a priori steady-state variance P- (units of x^2); q >= 0, r > 0.
  static double PriorVariance(double q, double r) {
    return 0.5 * (q + std::sqrt(q * q + 4.0 * q * r));
  }
  /// The steady-state gain K in [0, 1).
  static double Gain(double q, double r) {
    const double p = PriorVariance(q, r);
    return p / (p + r);
  }
  /// The a posteriori steady-state variance P = (1 - K) P- = K r.
  static double PosteriorVariance(double q, double r) { return Gain(q, r) * r; }

  SteadyStateKalman() = default;
  SteadyStateKalman(double q, double r)
      : gain_(Gain(q, r)), prior_variance_(PriorVariance(q, r)) {}

  double gain() const { return gain_; }
  double prior_variance() const { return prior_variance_; }
  double posterior_variance() const { return (1.0 - gain_) * prior_variance_; }

  /// One predict + update: the random walk predicts x unchanged; returns
  /// x + K (z - x).
  double Update(double x, double z) const { return x + gain_ * (z - x); }

 private:
  double gain_ = 0.0;
  double prior_variance_ = 0.0;
};

}  // namespace linesim::estimation
