// The scalar steady-state Kalman filter (units/estimation/steady_state_kalman.h).
#include "units/estimation/steady_state_kalman.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>

namespace linesim::estimation {
namespace {

// Paper 1, Sec. IV-A: process noise 3 sigma = 1 cm/s per sample,
// measurement sigma = 3 cm/s.
constexpr double kQ = (0.01 / 3.0) * (0.01 / 3.0);
constexpr double kR = 0.03 * 0.03;

// Guards against a wrong closed form: the gain must be the fixed point of
// the Riccati recursion P- <- P- r / (P- + r) + q, iterated here from the
// measurement variance until it stops changing.
TEST(SteadyStateKalman, GainIsTheRiccatiFixedPoint) {
  double prior = kR;
  for (int k = 0; k < 100000; ++k) {
    const double next = prior * kR / (prior + kR) + kQ;
    if (next == prior) break;
    prior = next;
  }
  const double k_iterated = prior / (prior + kR);
  const SteadyStateKalman f(kQ, kR);
  EXPECT_NEAR(f.prior_variance(), prior, 1e-12 * prior);
  EXPECT_NEAR(f.gain(), k_iterated, 1e-12);
  EXPECT_NEAR(SteadyStateKalman::Gain(kQ, kR), k_iterated, 1e-12);
  // The number for paper 1's figures: P- = (q + sqrt(q^2 + 4 q r)) / 2 =
  // 1.0571e-4 m^2/s^2, K = P- / (P- + r) = 0.1051.
  EXPECT_NEAR(f.gain(), 0.1051, 1e-4);
  // A posteriori variance: P = (1 - K) P- = K r, and P- = P + q.
  EXPECT_NEAR(f.posterior_variance(), f.gain() * kR, 1e-15);
  EXPECT_NEAR(SteadyStateKalman::PosteriorVariance(kQ, kR) + kQ, f.prior_variance(), 1e-15);
}

// Guards against an update that is not x + K (z - x) (a wrong sign or a
// gain applied to the wrong term changes the variance): the output of a
// constant input with white Gaussian noise of variance r is an AR(1)
// process x_k = (1 - K) x_{k-1} + K z_k with variance K r / (2 - K).
// Tolerance: the sampling error of a variance estimate of an AR(1) process
// with coefficient a = 1 - K from n samples has relative standard deviation
// sqrt(2 (1 + a^2) / ((1 - a^2) n)) (Bartlett), 0.43 % for n = 10^6;
// 4 of those.
TEST(SteadyStateKalman, OutputVarianceMatchesTheory) {
  const SteadyStateKalman f(kQ, kR);
  const double k = f.gain();
  const double expected = k * kR / (2.0 - k);
  const double truth = 0.1;  // m/s, a belt at paper 1's representative speed
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, std::sqrt(kR));
  constexpr std::int64_t kN = 1'000'000;
  double x = truth;
  // Burn-in: start at the truth, so the output is already stationary in
  // mean; 200 samples (a^200 = 2e-10) forget the initial variance 0.
  for (int i = 0; i < 200; ++i) x = f.Update(x, truth + noise(rng));
  double sum = 0.0, sum2 = 0.0;
  for (std::int64_t i = 0; i < kN; ++i) {
    x = f.Update(x, truth + noise(rng));
    sum += x - truth;
    sum2 += (x - truth) * (x - truth);
  }
  const double mean = sum / kN;
  const double var = sum2 / kN - mean * mean;
  const double a = 1.0 - k;
  const double rel_sd = std::sqrt(2.0 * (1.0 + a * a) / ((1.0 - a * a) * kN));
  EXPECT_NEAR(var, expected, 4.0 * rel_sd * expected);
  // Unbiased: the mean error within 4 standard errors (variance of the mean
  // of an AR(1): var (1 + a) / ((1 - a) n)).
  EXPECT_NEAR(mean, 0.0, 4.0 * std::sqrt(expected * (1.0 + a) / ((1.0 - a) * kN)));
}

}  // namespace
}  // namespace linesim::estimation
