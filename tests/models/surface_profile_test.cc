#include "models/surface_profile.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace linesim::models {
namespace {

// ISO 8608:2016's class A (G_d(n0) = 16e-6 m^3 at n0 = 0.1 cycles/m, w =
// 2) over wavelengths 0.05 to 10 m.
Unevenness ClassA(std::uint64_t seed) {
  Unevenness u;
  u.psd_n0_m3 = Iso8608ClassPsd('A');
  u.seed = seed;
  return u;
}

// Guards the class table against ISO 8608's: geometric means 16e-6 m^3
// for A, four times more per class.
TEST(SurfaceProfile, Iso8608Classes) {
  EXPECT_DOUBLE_EQ(Iso8608ClassPsd('A'), 16e-6);
  EXPECT_DOUBLE_EQ(Iso8608ClassPsd('B'), 64e-6);
  EXPECT_DOUBLE_EQ(Iso8608ClassPsd('C'), 256e-6);
  EXPECT_DOUBLE_EQ(Iso8608ClassPsd('H'), 16e-6 * std::pow(4.0, 7));
  EXPECT_THROW(Iso8608ClassPsd('I'), std::invalid_argument);
}

// Guards the amplitudes against the spectrum: the variance is the integral
// of G_d over the band, G_d(n0) n0^2 (1 / n_lo - 1 / n_hi) for w = 2 (1.255
// mm for class A over 0.05-10 m); the log-spaced sum of 32 bins is within
// 1 % of it. Over the plane (a 200 m square, 400 x 400 samples) the field's
// own standard deviation comes within 10 % of it for each of three seeds
// (32 random directions and phases: a sample's variance is not exact).
TEST(SurfaceProfile, VarianceIsTheSpectrumsIntegral) {
  const double analytic = std::sqrt(16e-6 * 0.01 * (10.0 - 0.05));
  for (const std::uint64_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE(seed);
    const SurfaceProfile p(ClassA(seed));
    EXPECT_NEAR(p.rms_m(), analytic, 0.01 * analytic);
    double sum = 0.0, sum2 = 0.0, most = 0.0;
    const int n = 400;
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        const double h = p.Height(0.5 * i - 100.0, 0.5 * j - 100.0, nullptr, nullptr);
        sum += h;
        sum2 += h * h;
        most = std::max(most, std::abs(h));
      }
    }
    const double count = static_cast<double>(n) * n;
    const double mean = sum / count;
    EXPECT_NEAR(std::sqrt(sum2 / count - mean * mean), analytic, 0.1 * analytic);
    EXPECT_LE(most, p.bound_m());
  }
}

// Guards the gradient against the height it belongs to: central
// differences of 1e-6 m agree to 1e-6 of the slope scale.
TEST(SurfaceProfile, GradientIsTheHeightsDerivative) {
  const SurfaceProfile p(ClassA(7));
  for (const auto& [u, v] : {std::pair{0.3, -1.2}, std::pair{5.0, 2.5}, std::pair{-3.3, 0.01}}) {
    double du = 0.0, dv = 0.0;
    p.Height(u, v, &du, &dv);
    const double e = 1e-6;
    const double fu =
        (p.Height(u + e, v, nullptr, nullptr) - p.Height(u - e, v, nullptr, nullptr)) / (2 * e);
    const double fv =
        (p.Height(u, v + e, nullptr, nullptr) - p.Height(u, v - e, nullptr, nullptr)) / (2 * e);
    EXPECT_NEAR(du, fu, 1e-6 * p.slope_rms() + 1e-9);
    EXPECT_NEAR(dv, fv, 1e-6 * p.slope_rms() + 1e-9);
  }
}

// Guards flat defaults and reproducibility: no G_d gives no profile; the
// same seed the same field, another seed another.
TEST(SurfaceProfile, FlatByDefaultAndTheSameForTheSameSeed) {
  EXPECT_TRUE(SurfaceProfile(Unevenness{}).Flat());
  EXPECT_EQ(SurfaceProfile(Unevenness{}).bound_m(), 0.0);
  const SurfaceProfile a(ClassA(1)), b(ClassA(1)), c(ClassA(2));
  EXPECT_EQ(a.Height(1.0, 2.0, nullptr, nullptr), b.Height(1.0, 2.0, nullptr, nullptr));
  EXPECT_NE(a.Height(1.0, 2.0, nullptr, nullptr), c.Height(1.0, 2.0, nullptr, nullptr));
  Unevenness bad = ClassA(1);
  bad.max_wavelength_m = bad.min_wavelength_m;
  EXPECT_THROW(SurfaceProfile{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace linesim::models
