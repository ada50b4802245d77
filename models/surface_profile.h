#pragma once

// A surface's height profile that wheels ride on: a deterministic random
// field with the displacement spectrum of ISO 8608 (road and floor profiles).

#include <cstdint>
#include <vector>

namespace linesim::models {

/// What a scene says of a surface's unevenness (Surface::unevenness). ISO
/// 8608:2016 gives a profile's displacement power spectral density as
///   G_d(n) = G_d(n0) (n / n0)^-w,   n0 = 0.1 cycles/m,
/// its classes by G_d(n0): A 16e-6 m^3 (the smoothest; up to 32e-6), B 64e-6,
/// C 256e-6, each class four times the one before, w = 2.
struct Unevenness {
  double psd_n0_m3 = 0.0;  // G_d(n0); 0: flat
  double waviness = 2.0;   // w
  // The band of wavelengths the profile holds: below the shortest a tyre's
  // patch averages the profile out, beyond the longest it is a slope the
  // robot follows without tilting within its own length.
  double min_wavelength_m = 0.05;
  double max_wavelength_m = 10.0;
  int components = 32;  // sinusoids, log-spaced over the band
  std::uint64_t seed = 1;
  bool Flat() const { return psd_n0_m3 <= 0.0; }
};

/// G_d(n0) of an ISO 8608 class letter 'A'..'H' (the class's geometric mean).
double Iso8608ClassPsd(char letter);

/// The profile h(u, v) of an Unevenness over a surface's own plane (u, v in
/// metres): a sum of `components` sinusoids with frequencies log-spaced
/// over the band, each with the amplitude sqrt(2 G_d(n_k) dn_k) of its
/// share of the spectrum, a direction and a phase drawn from the seed:
///   h = sum_k A_k cos(2 pi n_k (u cos t_k + v sin t_k) + p_k).
/// Its variance is sum_k A_k^2 / 2 = the integral of G_d over the band
/// (the log-spaced sum's), and |h| <= sum_k A_k. Isotropic: along any line
/// a component's frequency is n_k |cos(t_k - line)|, so a cut through the
/// field has the band's variance but its spectrum spread to lower
/// frequencies (idealisation: the field is not built from a 2D spectrum).
class SurfaceProfile {
 public:
  SurfaceProfile() = default;
  explicit SurfaceProfile(const Unevenness& u);

  bool Flat() const { return amplitude_.empty(); }
  /// Height at (u, v) and its gradient.
  double Height(double u, double v, double* dh_du, double* dh_dv) const;
  /// sum_k A_k: no height exceeds it.
  double bound_m() const { return bound_m_; }
  /// Standard deviation of the height over the plane, sqrt(sum A_k^2 / 2).
  double rms_m() const { return rms_m_; }
  /// Standard deviation of each gradient component over the plane.
  double slope_rms() const { return slope_rms_; }

 private:
  std::vector<double> amplitude_, ku_, kv_, phase_;  // k* = 2 pi n_k (cos, sin)
  double bound_m_ = 0.0, rms_m_ = 0.0, slope_rms_ = 0.0;
};

}  // namespace linesim::models
