#include "models/surface_profile.h"

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

namespace linesim::models {

double Iso8608ClassPsd(char letter) {
  if (letter < 'A' || letter > 'H') {
    throw std::invalid_argument(std::string("ISO 8608 classes are A to H, not '") + letter + "'");
  }
  return 16e-6 * std::pow(4.0, letter - 'A');
}

SurfaceProfile::SurfaceProfile(const Unevenness& u) {
  if (u.Flat()) return;
  if (!(u.min_wavelength_m > 0.0 && u.max_wavelength_m > u.min_wavelength_m && u.components >= 1)) {
    throw std::invalid_argument(
        "unevenness: the band needs 0 < min_wavelength_m < "
        "max_wavelength_m and at least one component");
  }
  constexpr double kN0 = 0.1;  // ISO 8608's reference spatial frequency, cycles/m
  const double n_lo = 1.0 / u.max_wavelength_m, n_hi = 1.0 / u.min_wavelength_m;
  const auto k_count = static_cast<std::size_t>(u.components);
  // Log-spaced bins: component k stands for [n_lo r^k, n_lo r^(k+1)],
  // at the bin's geometric centre.
  const double ratio = std::pow(n_hi / n_lo, 1.0 / static_cast<double>(k_count));
  std::mt19937_64 rng(u.seed);
  // 53 random bits as a double in [0, 1): the same on every machine.
  const auto uniform = [&rng] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
  double variance = 0.0, slope_variance = 0.0;
  for (std::size_t k = 0; k < k_count; ++k) {
    const double lo = n_lo * std::pow(ratio, static_cast<double>(k));
    const double hi = lo * ratio;
    const double n = std::sqrt(lo * hi);
    const double psd = u.psd_n0_m3 * std::pow(n / kN0, -u.waviness);
    const double a = std::sqrt(2.0 * psd * (hi - lo));
    const double direction = 2.0 * std::numbers::pi * uniform();
    const double wavenumber = 2.0 * std::numbers::pi * n;
    amplitude_.push_back(a);
    ku_.push_back(wavenumber * std::cos(direction));
    kv_.push_back(wavenumber * std::sin(direction));
    phase_.push_back(2.0 * std::numbers::pi * uniform());
    bound_m_ += a;
    variance += 0.5 * a * a;
    // Each gradient component's variance, averaged over directions
    // (cos^2 averages 1/2).
    slope_variance += 0.25 * a * a * wavenumber * wavenumber;
  }
  rms_m_ = std::sqrt(variance);
  slope_rms_ = std::sqrt(slope_variance);
}

double SurfaceProfile::Height(double u, double v, double* dh_du, double* dh_dv) const {
  double h = 0.0, gu = 0.0, gv = 0.0;
  for (std::size_t k = 0; k < amplitude_.size(); ++k) {
    const double arg = ku_[k] * u + kv_[k] * v + phase_[k];
    const double s = std::sin(arg), c = std::cos(arg);
    h += amplitude_[k] * c;
    gu -= amplitude_[k] * ku_[k] * s;
    gv -= amplitude_[k] * kv_[k] * s;
  }
  if (dh_du != nullptr) *dh_du = gu;
  if (dh_dv != nullptr) *dh_dv = gv;
  return h;
}

}  // namespace linesim::models
