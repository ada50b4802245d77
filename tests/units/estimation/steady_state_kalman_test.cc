// The scalar steady-state Kalman filter (units/estimation/steady_state_kalman.h).
#include "units/estimation/steady_state_kalman.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "tests/spread.h"

namespace linesim::estimation {
namespace {

// Paper 1, Sec. IV-A: process noise 3 sigma = 1 cm/s per sample,
// measurement sigma = 3 cm/s.
constexpr double kQ = (0.01 / 3.0) * (0.01 / 3.0);
constexpr double kR = 0.03 * 0.03;
// Seeds of the statistical tests: each must pass; the spreads quoted are
// min / median / max over them.
constexpr std::uint64_t kSeeds = 8;

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
// 4 of those (P(|z| > 4) = 6e-5 per seed). Seeds 1..8, errors in standard
// deviations: variance -0.72 / 0.18 / 1.68; mean -0.69 / 0.10 / 0.95.
TEST(SteadyStateKalman, OutputVarianceMatchesTheory) {
  const SteadyStateKalman f(kQ, kR);
  const double k = f.gain();
  const double expected = k * kR / (2.0 - k);
  const double truth = 0.1;  // m/s, a belt at paper 1's representative speed
  constexpr std::int64_t kN = 1'000'000;
  const double a = 1.0 - k;
  const double var_sd = std::sqrt(2.0 * (1.0 + a * a) / ((1.0 - a * a) * kN)) * expected;
  const double mean_sd = std::sqrt(expected * (1.0 + a) / ((1.0 - a) * kN));
  std::vector<double> z_var, z_mean;
  for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> noise(0.0, std::sqrt(kR));
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
    z_var.push_back((var - expected) / var_sd);
    z_mean.push_back(mean / mean_sd);
  }
  const auto zv = test_spread::Print("(variance - K r / (2 - K)) / its sd", z_var);
  const auto zm = test_spread::Print("mean error / its sd", z_mean);
  EXPECT_LT(zv.max_abs(), 4.0);
  // Unbiased: the mean error within 4 standard errors (variance of the mean
  // of an AR(1): var (1 + a) / ((1 - a) n)).
  EXPECT_LT(zm.max_abs(), 4.0);
}

// Guards against a gate in the wrong sigma: the innovation variance is
// S = P- + r of the same Riccati solution, 1.0057e-3 m^2/s^2 at paper 1's
// figures (sqrt(S) = 3.17 cm/s); a detector's threshold is g sqrt(S).
TEST(SteadyStateKalman, InnovationVarianceIsPriorPlusMeasurement) {
  const SteadyStateKalman f(kQ, kR);
  EXPECT_DOUBLE_EQ(f.innovation_variance(), f.prior_variance() + kR);
  EXPECT_DOUBLE_EQ(SteadyStateKalman::InnovationVariance(kQ, kR), f.innovation_variance());
  EXPECT_NEAR(std::sqrt(f.innovation_variance()), 0.03171, 1e-5);
  const SwitchDetector d(2.5, 3, f.innovation_variance());
  EXPECT_NEAR(d.threshold(), 2.5 * 0.031713, 1e-6);
  EXPECT_TRUE(d.enabled());
  EXPECT_FALSE(SwitchDetector(0.0, 3, f.innovation_variance()).enabled());
}

// Guards against a run that counts the wrong thing (both sides together,
// innovations inside the gate, a run not cleared by a sign change) and
// against a gate 0 that still acts.
TEST(SwitchDetector, CountsRunsOnOneSideBeyondTheGate) {
  const SwitchDetector d(2.0, 3, 1.0);  // threshold 2
  std::int64_t run = 0;
  EXPECT_FALSE(d.Observe(2.5, run));
  EXPECT_EQ(run, 1);
  EXPECT_FALSE(d.Observe(-2.5, run));  // the other side: a new run
  EXPECT_EQ(run, -1);
  EXPECT_FALSE(d.Observe(-3.0, run));
  EXPECT_FALSE(d.Observe(1.9, run));  // inside the gate: the run ends
  EXPECT_EQ(run, 0);
  EXPECT_FALSE(d.Observe(-2.1, run));
  EXPECT_FALSE(d.Observe(-2.1, run));
  EXPECT_TRUE(d.Observe(-2.1, run));
  EXPECT_EQ(run, -3);
  EXPECT_FALSE(d.Observe(2.0, run));  // exactly at the gate is inside
  EXPECT_EQ(run, 0);
  const SwitchDetector off(0.0, 3, 1.0);
  run = 7;
  for (double nu : {5.0, 5.0, 5.0, -5.0}) EXPECT_FALSE(off.Observe(nu, run));
  EXPECT_EQ(run, 7);
}

// Guards against a false-alarm rate other than the one the gate was chosen
// from: the filter runs on its own model (a random walk of variance q per
// sample measured with variance r, started at its steady state), so its
// innovations are white N(0, S); a run of N beyond g sqrt(S) on one side
// then ends at a given sample with probability Q(g)^N, both sides 2 Q(g)^N.
// A low gate (g = 1, N = 3: 2 Q(1)^3 = 7.99e-3) gives enough alarms in
// 10^6 samples (7990 expected) to measure the rate; the run is not cleared
// at an alarm here (every sample whose last N innovations qualify counts).
// Tolerance: the counts come in clumps (a run of length L >= N counts
// L - N + 1 times), clump sizes geometric with p = Q(1), so the count's
// variance is about (number of clumps) E[C^2] = m (1 - p) (1 + p) / (1 -
// p)^2 for m expected counts; 5 of its standard deviations. A gate in
// sigmas of r instead of S (sqrt(S / r) = 1.057) would give 23 % fewer
// (-21 sd). Seeds 1..8, in standard deviations: alarms -0.99 / 0.08 / 1.05;
// innovation variance -1.55 / 0.14 / 2.51.
TEST(SwitchDetector, FalseAlarmRateOnWhiteInnovations) {
  const SteadyStateKalman f(kQ, kR);
  const SwitchDetector d(1.0, 3, f.innovation_variance());
  std::vector<double> z_alarms, z_var;
  for (std::uint64_t seed = 1; seed <= kSeeds; ++seed) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> process(0.0, std::sqrt(kQ)), noise(0.0, std::sqrt(kR));
    constexpr std::int64_t kN = 1'000'000;
    double truth = 0.1;
    // The estimate starts with the steady a posteriori error (variance P).
    double x =
        truth + std::normal_distribution<double>(0.0, std::sqrt(f.posterior_variance()))(rng);
    std::int64_t run = 0, alarms = 0;
    double sum2 = 0.0;
    for (std::int64_t k = 0; k < kN; ++k) {
      truth += process(rng);
      const double z = truth + noise(rng);
      const double nu = z - x;
      sum2 += nu * nu;
      alarms += d.Observe(nu, run);
      x = f.Update(x, z);
    }
    const double p = 0.5 * std::erfc(1.0 / std::sqrt(2.0));
    const double expected = 2.0 * std::pow(p, 3) * static_cast<double>(kN - 2);
    const double sd = std::sqrt(expected * (1.0 + p) / (1.0 - p));
    z_alarms.push_back((static_cast<double>(alarms) - expected) / sd);
    // The innovations' variance is S (relative sampling sd sqrt(2 / n)).
    z_var.push_back((sum2 / kN - f.innovation_variance()) /
                    (std::sqrt(2.0 / kN) * f.innovation_variance()));
    std::printf("seed %llu: alarms %lld, expected %.0f +- %.0f\n",
                static_cast<unsigned long long>(seed), static_cast<long long>(alarms), expected,
                sd);
  }
  EXPECT_LT(test_spread::Print("(alarms - expected) / sd", z_alarms).max_abs(), 5.0);
  EXPECT_LT(test_spread::Print("(innovation variance - S) / sd", z_var).max_abs(), 5.0);
}

}  // namespace
}  // namespace linesim::estimation
