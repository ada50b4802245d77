#pragma once

#include <cmath>
#include <cstdint>

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
///
/// The innovation of a new measurement, nu = z - x (x the previous
/// estimate, the random walk's prediction), has in steady state the
/// variance S = P- + r and, when the model holds, is white (the innovation
/// sequence of an optimal Kalman filter; Bar-Shalom, Li, Kirubarajan,
/// "Estimation with Applications to Tracking and Navigation", 2001, Ch.
/// 5). Paper 1's figures: S = 1.0057e-3 m^2/s^2, sqrt(S) = 3.17 cm/s.
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
  /// The steady-state innovation variance S = P- + r.
  static double InnovationVariance(double q, double r) { return PriorVariance(q, r) + r; }

  SteadyStateKalman() = default;
  SteadyStateKalman(double q, double r)
      : gain_(Gain(q, r)),
        prior_variance_(PriorVariance(q, r)),
        innovation_variance_(InnovationVariance(q, r)) {}

  double gain() const { return gain_; }
  double prior_variance() const { return prior_variance_; }
  double posterior_variance() const { return (1.0 - gain_) * prior_variance_; }
  double innovation_variance() const { return innovation_variance_; }

  /// One predict + update: the random walk predicts x unchanged; returns
  /// x + K (z - x).
  double Update(double x, double z) const { return x + gain_ * (z - x); }

 private:
  double gain_ = 0.0;
  double prior_variance_ = 0.0;
  double innovation_variance_ = 0.0;
};

/// Innovation-based detection of a change of the state that the random
/// walk does not model (a manoeuvre in tracking: Bar-Shalom et al. 2001,
/// Ch. 11; X. R. Li, V. P. Jilkov, "A Survey of Maneuvering Target
/// Tracking, Part IV: Decision-Based Methods", SPIE 4728, 2002). Here a
/// line switching on or off: paper 1 Sec. II, the line runs in only two
/// states, and the process noise models only the variation within one.
/// Each innovation nu is compared with the gate g sqrt(S); a run of N
/// (`samples`) consecutive innovations beyond it ON THE SAME SIDE says the
/// state changed. A change of the mean shows as innovations of one sign,
/// which white noise rarely gives: if the innovations are white Gaussian
/// of variance S, one side holds a run ending at a given sample with
/// probability Q(g)^N (Q the standard normal tail), so a scalar filter
/// raises a false alarm per sample with probability at most
///   2 Q(g)^N   (both sides).
/// On a constant input (no process noise at all) the innovations have the
/// smaller variance 2 r / (2 - K) and the covariance
/// -(1 - K)^(j - 1) K r / (2 - K) at every lag j >= 1; by Slepian's
/// inequality both only lower that probability, so it stays a bound.
///
/// The run is the caller's state (a signed count: > 0 a run above the
/// gate, < 0 below, 0 none), so one detector serves many filters. A gate
/// of 0 disables the detector: Observe never changes the run and never
/// fires.
class SwitchDetector {
 public:
  SwitchDetector() = default;
  /// gate in innovation sigmas (>= 0; 0: off), samples >= 1, S > 0.
  SwitchDetector(double gate_sigmas, std::int64_t samples, double innovation_variance)
      : threshold_(gate_sigmas * std::sqrt(innovation_variance)),
        samples_(samples < 1 ? 1 : samples) {}

  bool enabled() const { return threshold_ > 0.0; }
  /// The gate in the state's units, g sqrt(S).
  double threshold() const { return threshold_; }
  std::int64_t samples() const { return samples_; }

  /// Adds the innovation `nu` to the run; true when the run reached
  /// `samples` (the caller restarts its filter and clears the run).
  bool Observe(double nu, std::int64_t& run) const {
    if (!enabled()) return false;
    if (nu > threshold_) {
      run = run > 0 ? run + 1 : 1;
    } else if (nu < -threshold_) {
      run = run < 0 ? run - 1 : -1;
    } else {
      run = 0;
    }
    return run >= samples_ || -run >= samples_;
  }

 private:
  double threshold_ = 0.0;
  std::int64_t samples_ = 1;
};

}  // namespace linesim::estimation
