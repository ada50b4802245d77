#include "units/sensors/px4flow_image.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>

namespace linesim::sensors {

Exposure AutoExposure(const Px4FlowCamera& cam, double lux) {
  Exposure e{};
  const double per_s = cam.responsivity_dn * std::max(lux, 0.0);  // DN/s at gain 1
  // Exposure first (no shorter than one 10 us row), then gain.
  e.exposure_s = per_s > 0.0
                     ? std::clamp(cam.target_brightness_dn / per_s, 1e-5, cam.max_exposure_s)
                     : cam.max_exposure_s;
  const double level = per_s * e.exposure_s;
  e.gain =
      level > 0.0 ? std::clamp(cam.target_brightness_dn / level, 1.0, cam.max_gain) : cam.max_gain;
  e.mean_dn = std::min(level * e.gain, 255.0);
  e.noise_dn = std::sqrt(e.mean_dn * e.gain * cam.full_well_dn +
                         cam.read_noise_dn * cam.read_noise_dn * e.gain * e.gain);
  return e;
}

int ComputeDiff(const Image& img, int x, int y) {
  const int off = (y + 2) * kImageSize + (x + 2);
  int acc = 0;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) {
      const int a = off + r * kImageSize + c;
      acc += std::abs(img[a] - img[a + kImageSize]);  // rows
    }
  }
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 3; ++c) {
      const int a = off + r * kImageSize + c;
      acc += std::abs(img[a] - img[a + 1]);  // columns
    }
  }
  return acc;
}

namespace {

inline int Sad8x8(const Image& a, int ax, int ay, const Image& b, int bx, int by) {
  int acc = 0;
  for (int r = 0; r < 8; ++r) {
    const std::uint8_t* pa = &a[(ay + r) * kImageSize + ax];
    const std::uint8_t* pb = &b[(by + r) * kImageSize + bx];
    for (int c = 0; c < 8; ++c) acc += std::abs(pa[c] - pb[c]);
  }
  return acc;
}

// __UHADD8 on one byte lane: the truncated mean.
inline int H(int a, int b) { return (a + b) >> 1; }

// compute_subpixel: SADs of the 8x8 block of image1 at (x1, y1) against the
// 8 half-pixel shifts around (x2, y2) in image2, in the firmware's order
// 0:+x 1:+x+y 2:+y 3:-x+y 4:-x 5:-x-y 6:-y 7:+x-y.
void Subpixel(const Image& im1, int x1, int y1, const Image& im2, int x2, int y2, int acc[8]) {
  for (int k = 0; k < 8; ++k) acc[k] = 0;
  auto p = [&](int x, int y) { return static_cast<int>(im2[y * kImageSize + x]); };
  for (int i = 0; i < 8; ++i) {
    for (int x = 0; x < 8; ++x) {
      const int X = x2 + x, Y = y2 + i;
      const int s0 = H(p(X, Y), p(X + 1, Y));
      const int s1 = H(p(X, Y + 1), p(X + 1, Y + 1));
      const int s2 = H(p(X, Y), p(X, Y + 1));
      const int s3 = H(p(X, Y + 1), p(X - 1, Y + 1));
      const int s4 = H(p(X, Y), p(X - 1, Y));
      const int s5 = H(p(X, Y - 1), p(X - 1, Y - 1));
      const int s6 = H(p(X, Y), p(X, Y - 1));
      const int s7 = H(p(X, Y - 1), p(X + 1, Y - 1));
      const int cand[8] = {s0, H(s0, s1), s2, H(s3, s4), s4, H(s4, s5), s6, H(s7, s0)};
      const int v = im1[(y1 + i) * kImageSize + x1 + x];
      for (int k = 0; k < 8; ++k) acc[k] += std::abs(v - cand[k]);
    }
  }
}

}  // namespace

FlowResult ComputeFlow(const Image& im1, const Image& im2, int search_range,
                       int feature_threshold) {
  constexpr int kTile = 8, kBlocks = 5, kValueThreshold = 5000;
  FlowResult r;
  const int S = search_range;
  const int lo = S + 1;
  const int hi = kImageSize - (S + 1) - kTile;
  const int step = (hi - lo) / kBlocks + 1;
  double sum_x = 0.0, sum_y = 0.0;
  int count = 0, index = 0;
  for (int j = lo; j < hi; j += step) {
    for (int i = lo; i < hi; i += step) {
      const int diff = ComputeDiff(im1, i, j);
      if (index < 25) r.diff[static_cast<std::size_t>(index)] = diff;
      ++index;
      if (diff < feature_threshold) continue;
      int best = 0x7fffffff, bx = 0, by = 0;
      for (int jj = -S; jj <= S; ++jj) {
        for (int ii = -S; ii <= S; ++ii) {
          const int d = Sad8x8(im1, i, j, im2, i + ii, j + jj);
          if (d < best) {
            best = d;
            bx = ii;
            by = jj;
          }
        }
      }
      if (best >= kValueThreshold) continue;
      int acc[8];
      Subpixel(im1, i, j, im2, i + bx, j + by, acc);
      int min_dist = best, dir = 8;
      for (int k = 0; k < 8; ++k) {
        if (acc[k] < min_dist) {
          min_dist = acc[k];
          dir = k;
        }
      }
      double sx = 0.0, sy = 0.0;
      if (dir == 0 || dir == 1 || dir == 7) sx = 0.5;
      if (dir == 3 || dir == 4 || dir == 5) sx = -0.5;
      if (dir == 5 || dir == 6 || dir == 7) sy = -0.5;
      if (dir == 1 || dir == 2 || dir == 3) sy = 0.5;
      sum_x += bx + sx;
      sum_y += by + sy;
      ++count;
    }
  }
  r.blocks = count;
  if (count > 10) {
    r.flow_x_px = sum_x / count;
    r.flow_y_px = sum_y / count;
    r.quality = count * 255 / (kBlocks * kBlocks);
  }
  return r;
}

namespace {

constexpr double kPi = std::numbers::pi;
// The golden angle, pi (3 - sqrt 5): successive points of a Vogel spiral.
constexpr double kGoldenAngle = 2.399963229728653;

inline std::uint64_t Mix(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

}  // namespace

Px4FlowImageModel::Px4FlowImageModel(const Px4FlowCamera& cam, std::uint64_t seed)
    : cam_(cam), texture_seed_(Mix(seed ^ 0x5eedULL)), rng_(seed) {}

// Value noise: a uniform value of unit variance at each lattice node,
// bilinearly interpolated. Bilinear interpolation of independent values
// keeps (2/3)^2 of the variance on average over a cell, hence the 1.5.
double Px4FlowImageModel::Field(double x, double y) const {
  const double gx = x / cam_.texture_scale_m, gy = y / cam_.texture_scale_m;
  const double fx = std::floor(gx), fy = std::floor(gy);
  const double u = gx - fx, v = gy - fy;
  const auto ix = static_cast<std::int64_t>(fx), iy = static_cast<std::int64_t>(fy);
  auto node = [&](std::int64_t a, std::int64_t b) {
    const std::uint64_t h = Mix(texture_seed_ ^ Mix(static_cast<std::uint64_t>(a) * 0x1f1f1f1fULL +
                                                    static_cast<std::uint64_t>(b)));
    // Uniform in [-sqrt 3, sqrt 3]: unit variance.
    return (static_cast<double>(h >> 11) * 0x1.0p-53 * 2.0 - 1.0) * 1.7320508075688772;
  };
  const double a = node(ix, iy), b = node(ix + 1, iy), c = node(ix, iy + 1),
               d = node(ix + 1, iy + 1);
  const double aperiodic = 1.5 * ((a * (1 - u) + b * u) * (1 - v) + (c * (1 - u) + d * u) * v);
  if (periodic_share_ <= 0.0) return aperiodic;
  // A sine of unit variance (sqrt 2 amplitude) along the period's direction.
  const double along = x * period_cos_ + y * period_sin_;
  const double periodic = 1.4142135623730951 * std::sin(2.0 * std::numbers::pi * along / period_m_);
  return std::sqrt(1.0 - periodic_share_) * aperiodic + std::sqrt(periodic_share_) * periodic;
}

void Px4FlowImageModel::SetPeriodicTexture(double period_m, double cos_dir, double sin_dir,
                                           double share) {
  period_m_ = period_m;
  period_cos_ = cos_dir;
  period_sin_ = sin_dir;
  periodic_share_ = period_m > 0.0 ? std::clamp(share, 0.0, 1.0) : 0.0;
}

void Px4FlowImageModel::Render(double dx_m, double dy_m, double vx_mps, double vy_mps,
                               double height_m, double contrast, double lux, Image& out,
                               double brightness, double defocus_px) {
  Exposure e = AutoExposure(cam_, lux);
  // The auto exposure follows the mean light; a flickering lamp makes this
  // exposure brighter or darker than that.
  e.mean_dn *= brightness;
  const double pix_m = height_m / cam_.focal_length_px;
  // Motion blur: the exposure [t - T, t] sampled at K instants, K growing
  // with the blur length so that samples are at most 1/2 pixel apart.
  const double blur_px = std::hypot(vx_mps, vy_mps) * e.exposure_s / pix_m;
  const int k_samples = std::clamp(static_cast<int>(std::ceil(2.0 * blur_px)) + 1, 1, 32);
  // Defocus: the lens' blur circle (diameter defocus_px) sampled by a
  // Vogel spiral of points at most about 1/2 pixel apart (pi c^2 points
  // over the disk of area pi c^2 / 4), each also on one corner of the 2x2
  // footprint pattern below.
  const int disk_points =
      defocus_px > 0.0 ? std::max(4, static_cast<int>(std::ceil(kPi * defocus_px * defocus_px)))
                       : 4;
  if (defocus_px > 0.0) {
    disk_.resize(static_cast<std::size_t>(2 * disk_points));
    for (int p = 0; p < disk_points; ++p) {
      const double r = 0.5 * defocus_px * std::sqrt((p + 0.5) / disk_points);
      const double a = kGoldenAngle * p;
      const double u = ((p & 1) ? 0.25 : -0.25) + r * std::cos(a);
      const double v = ((p & 2) ? 0.25 : -0.25) + r * std::sin(a);
      disk_[static_cast<std::size_t>(2 * p)] = u * pix_m;
      disk_[static_cast<std::size_t>(2 * p + 1)] = v * pix_m;
    }
  }
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double half = 0.5 * (kImageSize - 1);
  for (int j = 0; j < kImageSize; ++j) {
    for (int i = 0; i < kImageSize; ++i) {
      double sum = 0.0;
      for (int k = 0; k < k_samples; ++k) {
        const double back = k_samples == 1 ? 0.0 : e.exposure_s * k / (k_samples - 1);
        const double sx = dx_m - vx_mps * back, sy = dy_m - vy_mps * back;
        if (defocus_px > 0.0) {
          // Over the binned pixel's footprint (2x2) and the blur circle.
          const double cx = (i - half) * pix_m - sx, cy = (j - half) * pix_m - sy;
          for (int p = 0; p < disk_points; ++p) {
            sum += Field(cx + disk_[static_cast<std::size_t>(2 * p)],
                         cy + disk_[static_cast<std::size_t>(2 * p + 1)]);
          }
          continue;
        }
        // In focus: 2x2 samples over the binned pixel's footprint.
        for (int q = 0; q < 4; ++q) {
          const double u = (i - half + ((q & 1) ? 0.25 : -0.25)) * pix_m - sx;
          const double v = (j - half + ((q & 2) ? 0.25 : -0.25)) * pix_m - sy;
          sum += Field(u, v);
        }
      }
      const double level = e.mean_dn * (1.0 + contrast * sum / (disk_points * k_samples));
      const double sigma = std::sqrt(std::max(level, 0.0) * e.gain * cam_.full_well_dn +
                                     cam_.read_noise_dn * cam_.read_noise_dn * e.gain * e.gain);
      const double value = std::round(level + sigma * gauss(rng_));
      out[static_cast<std::size_t>(j * kImageSize + i)] =
          static_cast<std::uint8_t>(std::clamp(value, 0.0, 255.0));
    }
  }
}

FlowResult Px4FlowImageModel::Step(double vx_mps, double vy_mps, double height_m, double contrast,
                                   double lux, double brightness, double defocus_px) {
  const double dt = 1.0 / cam_.frame_rate_hz;
  if (!have_previous_) {
    Render(dx_m_, dy_m_, vx_mps, vy_mps, height_m, contrast, lux, current_, brightness, defocus_px);
    have_previous_ = true;
  }
  previous_ = current_;
  dx_m_ += vx_mps * dt;
  dy_m_ += vy_mps * dt;
  Render(dx_m_, dy_m_, vx_mps, vy_mps, height_m, contrast, lux, current_, brightness, defocus_px);
  return ComputeFlow(previous_, current_, cam_.search_range_px, cam_.feature_threshold);
}

}  // namespace linesim::sensors
