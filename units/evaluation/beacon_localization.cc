#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <utility>

#include "cosim/seed.h"
#include "models/angle.h"
#include "units/evaluation/beacon_localization.h"

namespace linesim::evaluation {
namespace {

using models::WrapAngle;

// Hypotheses of the geometric association whose RMS differ by less than
// this fit equally well (a symmetric layout); the heading hint decides.
constexpr double kTieRms = 0.005;
// Two hypotheses closer than this are the same pose.
constexpr double kSamePosition = 0.05, kSameYaw = 0.05;

// Inverse of a symmetric 3 x 3 (row-major); false when singular.
bool Inverse3(const std::array<double, 9>& a, std::array<double, 9>& inv) {
  const double c00 = a[4] * a[8] - a[5] * a[7];
  const double c01 = a[5] * a[6] - a[3] * a[8];
  const double c02 = a[3] * a[7] - a[4] * a[6];
  const double det = a[0] * c00 + a[1] * c01 + a[2] * c02;
  const double scale = std::abs(a[0]) + std::abs(a[4]) + std::abs(a[8]);
  if (!(std::abs(det) > 1e-15 * scale * scale * scale) || !std::isfinite(det)) return false;
  const double d = 1.0 / det;
  inv = {c00 * d, (a[2] * a[7] - a[1] * a[8]) * d, (a[1] * a[5] - a[2] * a[4]) * d,
         c01 * d, (a[0] * a[8] - a[2] * a[6]) * d, (a[2] * a[3] - a[0] * a[5]) * d,
         c02 * d, (a[1] * a[6] - a[0] * a[7]) * d, (a[0] * a[4] - a[1] * a[3]) * d};
  return true;
}

// Row-major product of small matrices, each element summed in index order:
// A B (A R x K, B K x C), or A B^T with `b_transposed` (B given C x K).
template <std::size_t R, std::size_t K, std::size_t C, bool b_transposed = false>
std::array<double, R * C> Product(const std::array<double, R * K>& a,
                                  const std::array<double, K * C>& b) {
  std::array<double, R * C> out{};
  for (std::size_t r = 0; r < R; ++r) {
    for (std::size_t c = 0; c < C; ++c) {
      double acc = 0;
      for (std::size_t q = 0; q < K; ++q)
        acc += a[r * K + q] * b[b_transposed ? c * K + q : q * C + c];
      out[r * C + c] = acc;
    }
  }
  return out;
}

}  // namespace

std::vector<const models::Obstacle*> BeaconLocalizationUnit::SceneBeacons(
    const models::Scene& scene) {
  std::vector<const models::Obstacle*> out;
  for (const models::Obstacle& o : scene.obstacles) {
    if (o.kind == "beacon") out.push_back(&o);
  }
  return out;
}

BeaconLocalizationUnit::BeaconLocalizationUnit(std::string name, std::vector<Beacon> beacons,
                                               int beam_count, std::uint64_t seed)
    : cosim::Unit(kTypeName, std::move(name)),
      scene_beacons_(std::move(beacons)),
      beacons_(scene_beacons_),
      beam_count_(beam_count),
      seed_(seed) {
  if (beam_count_ < 1 || beam_count_ > 100000) {
    throw cosim::UnitError(Where() + ": beam_count must be 1..100000, got " +
                           std::to_string(beam_count_));
  }
  const std::size_t nb = beacons_.size();
  if (!beacons_.empty()) radius_ = beacons_[0].radius;
  beacon_distance_.assign(nb * nb, 0.0);  // filled by Derive, from the surveyed beacons
  const auto n = static_cast<std::size_t>(beam_count_);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  mount_x_ = mount_y_ = mount_yaw_ = first_beam_angle_ = angular_step_ = nan;
  ranges_.assign(n, 0.0);
  position_.assign(2, 0.0);
  covariance_.assign(9, 0.0);
  cos_a_.assign(n, 0.0);
  sin_a_.assign(n, 0.0);
  px_.assign(n, 0.0);
  py_.assign(n, 0.0);
  use_.assign(n, 0);
  valid_beam_.assign(n, 0);
  detections_.assign(kMaxDetections, Detection{});
  beacon_taken_.assign(nb, -1);
  beacon_d2_.assign(nb, 0.0);
  beacon_last_scan_.assign(nb, -1);

  using cosim::Rule;
  auto& v = variables();
  // The parameters in the order `inspect` lists them: a real (with its
  // unit) or an integer.
  using Self = BeaconLocalizationUnit;
  struct ParameterRow {
    const char* name;
    const char* unit;
    double Self::*real;
    std::int64_t Self::*integer;
    const char* description;
    Rule rule;
  };
  const ParameterRow parameters[] = {
      {"mount_x", "m", &Self::mount_x_, nullptr, "the laser's origin in base_link, x",
       Rule::Finite().NoDefault()},
      {"mount_y", "m", &Self::mount_y_, nullptr, "the laser's origin in base_link, y",
       Rule::Finite().NoDefault()},
      {"mount_yaw", "rad", &Self::mount_yaw_, nullptr,
       "the laser's yaw in base_link (scan plane taken level: 3-DoF)", Rule::Finite().NoDefault()},
      {"first_beam_angle", "rad", &Self::first_beam_angle_, nullptr, "direction of beam 0",
       Rule::Range(-2 * std::numbers::pi, 2 * std::numbers::pi).NoDefault()},
      {"angular_step", "rad", &Self::angular_step_, nullptr, "angle between neighbouring beams",
       Rule::Range(0, false, std::numbers::pi, true).NoDefault()},
      {"range_min", "m", &Self::range_min_, nullptr,
       "nearer returns are not used (LMS151: 0.5 m, SICK 8012471)", Rule::NonNegative()},
      {"range_max", "m", &Self::range_max_, nullptr,
       "farther returns are not used (LMS151: 18 m at 10 % remission, SICK 8012471)",
       Rule::Positive()},
      {"range_sigma", "m", &Self::range_sigma_, nullptr,
       "the range's statistical error, 1 sigma: the circle fit's point noise (LMS151: 12 "
       "mm typical, SICK 8012471)",
       Rule::Positive()},
      {"systematic_sigma", "m", &Self::systematic_sigma_, nullptr,
       "the range's systematic error per device, 1 sigma (LMS151: +-30 mm typical, taken "
       "as 2 sigma, SICK 8012471): added to the output covariance and the gate",
       Rule::NonNegative()},
      {"flank_margin", "m", &Self::flank_margin_, nullptr,
       "a beacon's silhouette: the beams nearer than its axis plus 2 range_sigma plus "
       "this; it must end on both sides within the beacon's width (0: the van's beacons "
       "stand 9 cm before the wall)",
       Rule::Finite()},
      {"edge_trim", nullptr, nullptr, &Self::edge_trim_,
       "beams dropped at either edge of a beacon's silhouette before the fit (the mixed pixels of "
       "the spot, 15 mrad + 8 mm, SICK 8012471, at the silhouette)",
       Rule::Range(0, 10)},
      {"min_points", nullptr, nullptr, &Self::min_points_,
       "a beacon's fit needs at least this many points", Rule::Range(3, 100000)},
      {"max_fit_rms", "m", &Self::max_fit_rms_, nullptr,
       "a candidate whose circle fit leaves a larger residual RMS is no beacon "
       "(ASSUMPTION 0.03: 2.5 range_sigma)",
       Rule::Positive()},
      {"outlier_sigmas", "1", &Self::outlier_sigmas_, nullptr,
       "points farther than this many range_sigma from the first fit are dropped and the "
       "circle fitted again",
       Rule::Range(1.0, 100.0)},
      {"pair_tolerance", "m", &Self::pair_tolerance_, nullptr,
       "geometric association: a pair of detections matches a pair of beacons when their "
       "distances agree within this (ASSUMPTION 0.06: two centres each off by up to the "
       "LMS151's 40 mm maximum systematic error along different lines of sight, less "
       "the common part)",
       Rule::Positive()},
      {"match_distance", "m", &Self::match_distance_, nullptr,
       "geometric association: a detection joins a hypothesis within this of a beacon "
       "(ASSUMPTION 0.1: below half the 0.95 m between the van's beacons)",
       Rule::Positive()},
      {"gate", "1", &Self::gate_, nullptr,
       "association under the filter: Mahalanobis distance squared below this (13.8: "
       "chi-square 2 dof, 99.9 %)",
       Rule::Positive()},
      {"min_beacons", nullptr, nullptr, &Self::min_beacons_,
       "beacons needed to start the filter and for `valid`", Rule::Range(2, kMaxBeacons)},
      {"valid_scans", nullptr, nullptr, &Self::valid_scans_,
       "`valid` wants min_beacons distinct beacons associated within this many of the "
       "last processed scans (a single scan may miss a beacon to noise; 5: 0.1 s at the "
       "LMS151's 50 Hz)",
       Rule::Range(1, 1000)},
      {"uncover_delay", "s", &Self::uncover_delay_, nullptr,
       "scans starting earlier than this after `active` rose are not used (ASSUMPTION 1 "
       "s: paper 2 uncovered the beacons by hand once the robot stood inside; the filter "
       "assumes a robot that no longer moves)",
       Rule::NonNegative()},
      {"heading_hint", "rad", &Self::heading_hint_, nullptr,
       "decides between hypotheses a symmetric layout fits equally (the van's rectangle: "
       "a pose and its half-turn): the one whose yaw is nearer wins; nothing else",
       Rule::Finite()},
      {"process_noise_position", "m/s^0.5", &Self::process_noise_position_, nullptr,
       "random walk of the standing robot's position per sqrt(s) (ASSUMPTION 0.001: a "
       "robot settling on its tyres and a van on its suspension, about 1 mm over a "
       "second of 50 scans)",
       Rule::NonNegative()},
      {"process_noise_yaw", "rad/s^0.5", &Self::process_noise_yaw_, nullptr,
       "random walk of the standing robot's yaw per sqrt(s) (ASSUMPTION 0.001)",
       Rule::NonNegative()},
      {"initial_sigma_position", "m", &Self::initial_sigma_position_, nullptr,
       "the filter's position sigma at the geometric fix (ASSUMPTION 0.1: wide, the first "
       "scan's update decides)",
       Rule::Positive()},
      {"initial_sigma_yaw", "rad", &Self::initial_sigma_yaw_, nullptr,
       "the filter's yaw sigma at the geometric fix (ASSUMPTION 0.1)", Rule::Positive()},
      {"survey_sigma", "m", &Self::survey_sigma_, nullptr,
       "error of each surveyed beacon coordinate (1 sigma), drawn once per installation: "
       "the filter knows the beacons there, not where they stand (0: exactly)",
       Rule::Range(0.0, true, 0.1, true)},
      {"installation_seed", nullptr, nullptr, &Self::installation_seed_,
       "which installation: >= 0 draws the survey errors from this seed, the same in "
       "every run; -1: from the run's seed (a new installation per run)",
       Rule::Range(-1, 4294967295.0)},
  };
  for (const ParameterRow& p : parameters) {
    if (p.real) {
      v.Parameter(p.name, p.unit, &(this->*p.real), p.description, p.rule);
    } else {
      v.Parameter(p.name, &(this->*p.integer), p.description, p.rule);
    }
  }

  v.Input("ranges", "m", &ranges_, "the laser's last complete scan (0: no return)");
  v.Input("scan_count", "1", &scan_count_, "the laser's complete scans so far");
  v.Input("scan_time", "s", &scan_time_, "start time of the laser's last scan");
  v.Input("active", &active_,
          "the beacons are uncovered (paper 2 covered them while the robot climbed); each "
          "rising edge restarts from geometry");

  v.Output("position", "m", &position_, "base_link x, y in map (the filter's estimate)", {});
  v.Output("yaw", "rad", &yaw_, "base_link yaw in map", {});
  v.Output("covariance", "1", &covariance_,
           "row-major 3 x 3 of x (m), y (m), yaw (rad): the filter's P plus the systematic "
           "range error's part",
           {});
  v.Output("valid", &valid_,
           "active, the filter started, and at least min_beacons distinct beacons associated "
           "within the last valid_scans processed scans",
           {});
  v.Output("beacons_seen", &beacons_seen_, "beacons associated in the last processed scan", {});
  v.Output("scans_used", &scans_used_, "scans that updated the filter since the last activation",
           {});
}

std::vector<cosim::ParameterProblem> BeaconLocalizationUnit::CheckParameters() const {
  auto problems = cosim::Unit::CheckParameters();
  const auto nb = static_cast<std::int64_t>(beacons_.size());
  if (nb < min_beacons_ || nb > kMaxBeacons) {
    problems.push_back({"beacons", std::nullopt,
                        "the scene has " + std::to_string(nb) +
                            " obstacles of kind beacon; the unit needs " +
                            std::to_string(min_beacons_) + " to " + std::to_string(kMaxBeacons)});
  }
  for (std::size_t j = 0; j < beacons_.size(); ++j) {
    const Beacon& b = beacons_[j];
    if (!std::isfinite(b.x) || !std::isfinite(b.y) || !(b.radius > 0.0) ||
        !std::isfinite(b.radius)) {
      problems.push_back({"beacons", j, "must have a finite position and a radius > 0"});
    } else if (std::abs(b.radius - radius_) > 1e-6) {
      problems.push_back({"beacons", j,
                          "radius " + cosim::FormatValue(b.radius) + " differs from beacon 0's " +
                              cosim::FormatValue(radius_) + ": the beacons must share one radius"});
    }
  }
  if (!(range_min_ < range_max_)) {
    problems.push_back({"range_max", std::nullopt,
                        "must be > range_min (" + cosim::FormatValue(range_min_) + "), got " +
                            cosim::FormatValue(range_max_)});
  }
  if (angular_step_ * (beam_count_ - 1) >= 2.0 * std::numbers::pi) {
    problems.push_back({"angular_step", std::nullopt,
                        "the " + std::to_string(beam_count_) +
                            " beams must fit in one turn: angular_step < 2 pi / (beams - 1)"});
  }
  return problems;
}

void BeaconLocalizationUnit::Setup(cosim::TimeNs start, cosim::TimeNs) { start_ = start; }

void BeaconLocalizationUnit::Derive() {
  // The installation's survey: Box-Muller normals from its own generator
  // (the same draws on every Derive).
  std::mt19937_64 survey(
      installation_seed_ >= 0
          ? cosim::DeriveSeed(static_cast<std::uint64_t>(installation_seed_), name() + " survey")
          : seed_);
  const auto uniform = [&survey] {
    return (static_cast<double>(survey() >> 11) + 0.5) * 0x1.0p-53;  // (0, 1)
  };
  for (std::size_t j = 0; j < scene_beacons_.size(); ++j) {
    const double r = std::sqrt(-2.0 * std::log(uniform())), a = 2.0 * std::numbers::pi * uniform();
    beacons_[j] = {scene_beacons_[j].x + survey_sigma_ * r * std::cos(a),
                   scene_beacons_[j].y + survey_sigma_ * r * std::sin(a), scene_beacons_[j].radius};
  }
  const std::size_t nb = beacons_.size();
  for (std::size_t a = 0; a < nb; ++a) {
    for (std::size_t b = 0; b < nb; ++b) {
      beacon_distance_[a * nb + b] =
          std::hypot(beacons_[a].x - beacons_[b].x, beacons_[a].y - beacons_[b].y);
    }
  }
  for (int i = 0; i < beam_count_; ++i) {
    const double a = first_beam_angle_ + i * angular_step_;
    cos_a_[static_cast<std::size_t>(i)] = std::cos(a);
    sin_a_[static_cast<std::size_t>(i)] = std::sin(a);
  }
}

void BeaconLocalizationUnit::Initialize() {
  ThrowIfBadParameters();
  Derive();
  last_count_ = scan_count_;
  last_scan_time_ = scan_time_;
  was_active_ = false;
  started_ = false;
  active_since_ns_ = start_;
  x_ = {0.0, 0.0, 0.0};
  p_ = {};
  g_ = {};
  detection_count_ = 0;
  position_ = {0.0, 0.0};
  yaw_ = 0.0;
  std::fill(covariance_.begin(), covariance_.end(), 0.0);
  valid_ = false;
  beacons_seen_ = 0;
  scans_used_ = 0;
  scan_index_ = 0;
  std::fill(beacon_last_scan_.begin(), beacon_last_scan_.end(), -1);
}

bool BeaconLocalizationUnit::FitCircle(int first, int end, double bearing, Detection& d) {
  const double r = radius_;
  // The silhouette's bearing as one more residual, in units of range_sigma:
  // (range_sigma / bearing_sigma) (atan2(cy, cx) - bearing).
  const double bearing_sigma = angular_step_ / std::sqrt(6.0);
  const double wb = range_sigma_ / bearing_sigma;
  // Start: the nearest point moved r farther along the silhouette's bearing.
  double nearest = std::numeric_limits<double>::infinity();
  int n = 0;
  for (int i = first; i < end; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (!use_[k]) continue;
    ++n;
    nearest = std::min(nearest, ranges_[k]);
  }
  if (n < min_points_) return false;
  double cx = (nearest + r) * std::cos(bearing), cy = (nearest + r) * std::sin(bearing);
  double a = 0, b = 0, c = 0, ss = 0;  // J^T J = [a b; b c]
  const auto accumulate = [&](double& gx, double& gy) {
    a = b = c = ss = 0;
    gx = gy = 0;
    for (int i = first; i < end; ++i) {
      const auto k = static_cast<std::size_t>(i);
      if (!use_[k]) continue;
      const double dx = px_[k] - cx, dy = py_[k] - cy;
      const double rho = std::hypot(dx, dy);
      if (rho < 1e-9) continue;
      const double jx = -dx / rho, jy = -dy / rho, res = rho - r;
      a += jx * jx;
      b += jx * jy;
      c += jy * jy;
      gx += jx * res;
      gy += jy * res;
      ss += res * res;
    }
    const double d2 = cx * cx + cy * cy;
    const double res = wb * std::remainder(std::atan2(cy, cx) - bearing, 2.0 * std::numbers::pi);
    const double jx = -wb * cy / d2, jy = wb * cx / d2;
    a += jx * jx;
    b += jx * jy;
    c += jy * jy;
    gx += jx * res;
    gy += jy * res;
  };
  for (int it = 0; it < 20; ++it) {
    double gx = 0, gy = 0;
    accumulate(gx, gy);
    const double det = a * c - b * b;
    if (!(det > 1e-12 * (a + c) * (a + c))) return false;
    const double sx = -(c * gx - b * gy) / det, sy = -(a * gy - b * gx) / det;
    cx += sx;
    cy += sy;
    if (std::hypot(sx, sy) < 1e-8) break;
  }
  // The covariance and residual at the final centre.
  double gx = 0, gy = 0;
  accumulate(gx, gy);
  const double det = a * c - b * b;
  if (!(det > 1e-12 * (a + c) * (a + c)) || !std::isfinite(cx) || !std::isfinite(cy)) return false;
  const double s2 = range_sigma_ * range_sigma_;
  d.x = cx;
  d.y = cy;
  d.cxx = s2 * c / det;
  d.cxy = -s2 * b / det;
  d.cyy = s2 * a / det;
  d.rms = std::sqrt(ss / n);
  d.points = n;
  return true;
}

void BeaconLocalizationUnit::Detect() {
  detection_count_ = 0;
  const int n = beam_count_;
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double r = ranges_[k];
    const bool ok = r > 0.0 && r >= range_min_ && r <= range_max_;
    valid_beam_[k] = ok ? 1 : 0;
    px_[k] = ok ? r * cos_a_[k] : 0.0;
    py_[k] = ok ? r * sin_a_[k] : 0.0;
  }
  std::fill(use_.begin(), use_.end(), 0);
  const double step = angular_step_;
  const double r0 = radius_;
  for (int i = 0; i < n && detection_count_ < kMaxDetections; ++i) {
    const auto ki = static_cast<std::size_t>(i);
    if (!valid_beam_[ki]) continue;
    const double ri = ranges_[ki];
    // A seed: the nearest return within a beacon's angular half width at
    // its range (the nearest point of a cylinder faces the laser).
    // In beams, at most all of them (a tiny angular_step must not overflow
    // the int).
    const int w = static_cast<int>(std::min(
        std::ceil(std::asin(std::min(1.0, r0 / (ri + r0))) / step), static_cast<double>(n)));
    bool seed = true;
    for (int j = std::max(0, i - w); j <= std::min(n - 1, i + w) && seed; ++j) {
      const auto kj = static_cast<std::size_t>(j);
      if (j == i || !valid_beam_[kj]) continue;
      if (ranges_[kj] < ri || (ranges_[kj] == ri && j < i)) seed = false;
    }
    if (!seed) continue;
    // The beacon's silhouette: the run of foreground beams (nearer than
    // the axis plus 2 range_sigma) around the seed. A beacon stands free of
    // its background: the run ends (a farther return or none) on both
    // sides within a beacon's full width, where a wall's nearest point
    // goes on.
    const double fore = ri + r0 + 2.0 * range_sigma_;
    const int limit = 2 * w + 2;
    const auto foreground = [&](int j) {
      const auto kj = static_cast<std::size_t>(j);
      return j >= 0 && j < n && valid_beam_[kj] && ranges_[kj] < fore + flank_margin_;
    };
    int lo = i, hi = i;
    while (lo > i - limit && foreground(lo - 1)) --lo;
    while (hi < i + limit && foreground(hi + 1)) ++hi;
    if (foreground(lo - 1) || foreground(hi + 1)) continue;
    // Cut by the field of view's edge (its bearing unknown), or wider than
    // a beacon (2 w + 1 beams) and a mixed pixel on either side.
    if (lo == 0 || hi == n - 1 || hi - lo + 1 > 2 * w + 3) continue;
    // The fit: the run less edge_trim beams at either edge (the mixed
    // pixels and grazing returns at the silhouette).
    const int a = lo + static_cast<int>(edge_trim_), b = hi + 1 - static_cast<int>(edge_trim_);
    if (b - a < min_points_) continue;
    Detection& d = detections_[static_cast<std::size_t>(detection_count_)];
    for (int k = a; k < b; ++k) {
      const auto kk = static_cast<std::size_t>(k);
      use_[kk] = valid_beam_[kk] && ranges_[kk] < fore ? 1 : 0;
    }
    const double bearing = first_beam_angle_ + 0.5 * (lo + hi) * step;
    bool ok = FitCircle(a, b, bearing, d);
    if (ok) {
      // Outliers (a mixed pixel the trim missed): out, and fit again.
      const double gate = outlier_sigmas_ * range_sigma_;
      int dropped = 0;
      for (int k = a; k < b; ++k) {
        const auto kk = static_cast<std::size_t>(k);
        if (use_[kk] && std::abs(std::hypot(px_[kk] - d.x, py_[kk] - d.y) - r0) > gate) {
          use_[kk] = 0;
          ++dropped;
        }
      }
      if (dropped > 0) ok = FitCircle(a, b, bearing, d);
    }
    for (int k = a; k < b; ++k) use_[static_cast<std::size_t>(k)] = 0;
    if (!ok || d.rms > max_fit_rms_ || !(std::hypot(d.x, d.y) > ri)) continue;
    // The same beacon from another seed.
    bool twice = false;
    for (int k = 0; k < detection_count_ && !twice; ++k) {
      const Detection& e = detections_[static_cast<std::size_t>(k)];
      twice = std::hypot(e.x - d.x, e.y - d.y) < r0;
    }
    if (twice) continue;
    d.first_beam = a;
    d.last_beam = b - 1;
    d.beacon = -1;
    ++detection_count_;
  }
}

namespace {
// A hypothesis of the geometric association: its detection-beacon pairs
// and their RMS distance after the rigid fit.
struct Assignment {
  int pairs = 0;
  double rms = 0.0;
};
}  // namespace

bool BeaconLocalizationUnit::AssociateByGeometry(std::array<double, 3>& laser_pose) {
  const int nd = detection_count_;
  const int nb = static_cast<int>(beacons_.size());
  if (nd < min_beacons_) return false;
  const double m2 = match_distance_ * match_distance_;
  // Each detection, put into the map by the laser pose, to the nearest
  // beacon within match_distance (one detection per beacon: the nearer
  // wins): fills beacon_taken_, beacon_d2_ and the detections' `beacon`.
  const auto assign = [&](double lx, double ly, double lyaw) {
    const double c = std::cos(lyaw), s = std::sin(lyaw);
    std::fill(beacon_taken_.begin(), beacon_taken_.end(), -1);
    for (int k = 0; k < nd; ++k) {
      Detection& d = detections_[static_cast<std::size_t>(k)];
      d.beacon = -1;
      const double qx = lx + c * d.x - s * d.y, qy = ly + s * d.x + c * d.y;
      int best = -1;
      double best_d2 = m2;
      for (int j = 0; j < nb; ++j) {
        const Beacon& b = beacons_[static_cast<std::size_t>(j)];
        const double d2 = (qx - b.x) * (qx - b.x) + (qy - b.y) * (qy - b.y);
        if (d2 < best_d2) {
          best_d2 = d2;
          best = j;
        }
      }
      if (best >= 0) Claim(k, best, best_d2);
    }
  };
  // The least-squares rigid fit (2D Procrustes) of the assigned pairs: the
  // laser pose and the pairs' RMS.
  const auto refine = [&](std::array<double, 3>& pose) {
    Assignment out;
    double dx = 0, dy = 0, bx = 0, by = 0;
    ForEachPair([&](const Detection& d, const Beacon& b) {
      dx += d.x;
      dy += d.y;
      bx += b.x;
      by += b.y;
      ++out.pairs;
    });
    if (out.pairs < 2) return out;
    const double inv = 1.0 / out.pairs;
    dx *= inv;
    dy *= inv;
    bx *= inv;
    by *= inv;
    double sc = 0, sx = 0;
    ForEachPair([&](const Detection& d, const Beacon& b) {
      const double ux = d.x - dx, uy = d.y - dy, vx = b.x - bx, vy = b.y - by;
      sc += ux * vx + uy * vy;
      sx += ux * vy - uy * vx;
    });
    const double yaw = std::atan2(sx, sc);
    const double c = std::cos(yaw), s = std::sin(yaw);
    pose = {bx - (c * dx - s * dy), by - (s * dx + c * dy), yaw};
    double ss = 0;
    ForEachPair([&](const Detection& d, const Beacon& b) {
      const double qx = pose[0] + c * d.x - s * d.y, qy = pose[1] + s * d.x + c * d.y;
      ss += (qx - b.x) * (qx - b.x) + (qy - b.y) * (qy - b.y);
    });
    out.rms = std::sqrt(ss * inv);
    return out;
  };

  const double hint = heading_hint_ + mount_yaw_;
  Assignment best;
  std::array<double, 3> best_pose{};
  for (int i = 0; i < nd; ++i) {
    const Detection& di = detections_[static_cast<std::size_t>(i)];
    for (int j = i + 1; j < nd; ++j) {
      const Detection& dj = detections_[static_cast<std::size_t>(j)];
      const double dij = std::hypot(dj.x - di.x, dj.y - di.y);
      const double dir_d = std::atan2(dj.y - di.y, dj.x - di.x);
      for (int a = 0; a < nb; ++a) {
        for (int b = 0; b < nb; ++b) {
          if (a == b) continue;
          const auto ab = static_cast<std::size_t>(a * nb + b);
          if (std::abs(dij - beacon_distance_[ab]) > pair_tolerance_) continue;
          const Beacon& ba = beacons_[static_cast<std::size_t>(a)];
          const Beacon& bb = beacons_[static_cast<std::size_t>(b)];
          const double yaw = std::atan2(bb.y - ba.y, bb.x - ba.x) - dir_d;
          const double c = std::cos(yaw), s = std::sin(yaw);
          const double mx = 0.5 * (di.x + dj.x), my = 0.5 * (di.y + dj.y);
          const double lx = 0.5 * (ba.x + bb.x) - (c * mx - s * my);
          const double ly = 0.5 * (ba.y + bb.y) - (s * mx + c * my);
          assign(lx, ly, yaw);
          std::array<double, 3> pose{};
          Assignment h = refine(pose);
          if (h.pairs < 2) continue;
          // Once more at the refined pose (a pair off by the tolerance can
          // leave a beacon just outside match_distance).
          assign(pose[0], pose[1], pose[2]);
          h = refine(pose);
          if (h.pairs < 2) continue;
          bool better = false;
          if (h.pairs > best.pairs) {
            better = true;
          } else if (h.pairs == best.pairs) {
            const bool same =
                std::hypot(pose[0] - best_pose[0], pose[1] - best_pose[1]) < kSamePosition &&
                std::abs(WrapAngle(pose[2] - best_pose[2])) < kSameYaw;
            if (same || std::abs(h.rms - best.rms) > kTieRms) {
              better = h.rms < best.rms;
            } else {
              better =
                  std::abs(WrapAngle(pose[2] - hint)) < std::abs(WrapAngle(best_pose[2] - hint));
            }
          }
          if (better) {
            best = h;
            best_pose = pose;
          }
        }
      }
    }
  }
  if (best.pairs < min_beacons_) {
    for (int k = 0; k < nd; ++k) detections_[static_cast<std::size_t>(k)].beacon = -1;
    return false;
  }
  assign(best_pose[0], best_pose[1], best_pose[2]);
  laser_pose = best_pose;
  return true;
}

void BeaconLocalizationUnit::Observe(int j, std::array<double, 2>& z,
                                     std::array<double, 6>& h) const {
  const Beacon& b = beacons_[static_cast<std::size_t>(j)];
  const double ct = std::cos(x_[2]), st = std::sin(x_[2]);
  const double lx = x_[0] + ct * mount_x_ - st * mount_y_;
  const double ly = x_[1] + st * mount_x_ + ct * mount_y_;
  const double phi = x_[2] + mount_yaw_;
  const double c = std::cos(phi), s = std::sin(phi);
  const double dx = b.x - lx, dy = b.y - ly;
  z = {c * dx + s * dy, -s * dx + c * dy};
  // dL/dyaw, then dz/dyaw = (z1, -z0) - R(phi)^T dL/dyaw.
  const double lqx = -st * mount_x_ - ct * mount_y_, lqy = ct * mount_x_ - st * mount_y_;
  h = {-c, -s, z[1] - (c * lqx + s * lqy), s, -c, -z[0] - (-s * lqx + c * lqy)};
}

void BeaconLocalizationUnit::AssociateByPrediction() {
  std::fill(beacon_taken_.begin(), beacon_taken_.end(), -1);
  const int nb = static_cast<int>(beacons_.size());
  const double sys2 = systematic_sigma_ * systematic_sigma_;
  std::array<double, 2> z{};
  std::array<double, 6> h{};
  for (int k = 0; k < detection_count_; ++k) {
    Detection& d = detections_[static_cast<std::size_t>(k)];
    d.beacon = -1;
    int best = -1;
    double best_d2 = gate_;
    for (int j = 0; j < nb; ++j) {
      Observe(j, z, h);
      // S = H P H^T + R + sys^2 u u^T.
      const std::array<double, 6> hp = Product<2, 3, 3>(h, p_);  // H P
      double s00 = d.cxx, s01 = d.cxy, s11 = d.cyy;
      for (std::size_t q = 0; q < 3; ++q) {
        s00 += hp[q] * h[q];
        s01 += hp[q] * h[3 + q];
        s11 += hp[3 + q] * h[3 + q];
      }
      const double zn = std::hypot(z[0], z[1]);
      if (zn > 0) {
        const double ux = z[0] / zn, uy = z[1] / zn;
        s00 += sys2 * ux * ux;
        s01 += sys2 * ux * uy;
        s11 += sys2 * uy * uy;
      }
      const double det = s00 * s11 - s01 * s01;
      if (!(det > 0)) continue;
      const double vx = d.x - z[0], vy = d.y - z[1];
      const double d2 = (s11 * vx * vx - 2 * s01 * vx * vy + s00 * vy * vy) / det;
      if (d2 < best_d2) {
        best_d2 = d2;
        best = j;
      }
    }
    if (best >= 0) Claim(k, best, best_d2);
  }
}

void BeaconLocalizationUnit::Claim(int k, int j, double d2) {
  const auto bj = static_cast<std::size_t>(j);
  if (beacon_taken_[bj] >= 0) {
    if (beacon_d2_[bj] <= d2) return;
    detections_[static_cast<std::size_t>(beacon_taken_[bj])].beacon = -1;
  }
  beacon_taken_[bj] = k;
  beacon_d2_[bj] = d2;
  detections_[static_cast<std::size_t>(k)].beacon = j;
}

int BeaconLocalizationUnit::Update() {
  int used = 0;
  std::array<double, 9> info{};   // sum H^T R^-1 H at the prior
  std::array<double, 3> drift{};  // sum H^T R^-1 u
  std::array<double, 2> z{};
  std::array<double, 6> h{};
  for (int k = 0; k < detection_count_; ++k) {
    const Detection& d = detections_[static_cast<std::size_t>(k)];
    if (d.beacon < 0) continue;
    Observe(d.beacon, z, h);
    // R^-1.
    const double rdet = d.cxx * d.cyy - d.cxy * d.cxy;
    if (!(rdet > 0)) continue;
    const double ri00 = d.cyy / rdet, ri01 = -d.cxy / rdet, ri11 = d.cxx / rdet;
    const double zn = std::hypot(z[0], z[1]);
    const double ux = zn > 0 ? z[0] / zn : 0.0, uy = zn > 0 ? z[1] / zn : 0.0;
    for (std::size_t r = 0; r < 3; ++r) {
      // (H^T R^-1) row r: h0r, h1r times R^-1.
      const double h0 = h[r], h1 = h[3 + r];
      const double w0 = h0 * ri00 + h1 * ri01, w1 = h0 * ri01 + h1 * ri11;
      for (std::size_t q = 0; q < 3; ++q) info[r * 3 + q] += w0 * h[q] + w1 * h[3 + q];
      drift[r] += w0 * ux + w1 * uy;
    }
    // The update: S = H P H^T + R, K = P H^T S^-1, Joseph form.
    const std::array<double, 6> ph = Product<3, 3, 2, true>(p_, h);  // P H^T
    double s00 = d.cxx, s01 = d.cxy, s11 = d.cyy;
    for (std::size_t q = 0; q < 3; ++q) {
      s00 += h[q] * ph[q * 2];
      s01 += h[q] * ph[q * 2 + 1];
      s11 += h[3 + q] * ph[q * 2 + 1];
    }
    const double sdet = s00 * s11 - s01 * s01;
    if (!(sdet > 0)) continue;
    const double si00 = s11 / sdet, si01 = -s01 / sdet, si11 = s00 / sdet;
    std::array<double, 6> kg{};  // K (3 x 2)
    for (std::size_t r = 0; r < 3; ++r) {
      const double a = ph[r * 2], b = ph[r * 2 + 1];
      kg[r * 2] = a * si00 + b * si01;
      kg[r * 2 + 1] = a * si01 + b * si11;
    }
    const double vx = d.x - z[0], vy = d.y - z[1];
    for (std::size_t r = 0; r < 3; ++r) x_[r] += kg[r * 2] * vx + kg[r * 2 + 1] * vy;
    x_[2] = WrapAngle(x_[2]);
    // A = I - K H; P = A P A^T + K R K^T.
    std::array<double, 9> am{};
    for (std::size_t r = 0; r < 3; ++r) {
      for (std::size_t q = 0; q < 3; ++q) {
        am[r * 3 + q] = (r == q ? 1.0 : 0.0) - kg[r * 2] * h[q] - kg[r * 2 + 1] * h[3 + q];
      }
    }
    const std::array<double, 9> apa = Product<3, 3, 3, true>(Product<3, 3, 3>(am, p_), am);
    for (std::size_t r = 0; r < 3; ++r) {
      for (std::size_t q = r; q < 3; ++q) {
        const double k0r = kg[r * 2], k1r = kg[r * 2 + 1], k0q = kg[q * 2], k1q = kg[q * 2 + 1];
        const double krk = k0r * (d.cxx * k0q + d.cxy * k1q) + k1r * (d.cxy * k0q + d.cyy * k1q);
        p_[r * 3 + q] = p_[q * 3 + r] = apa[r * 3 + q] + krk;
      }
    }
    ++used;
  }
  // The pose's sensitivity to a common range offset under this geometry.
  std::array<double, 9> inv{};
  if (used >= 2 && Inverse3(info, inv)) {
    for (std::size_t r = 0; r < 3; ++r) {
      g_[r] = inv[r * 3] * drift[0] + inv[r * 3 + 1] * drift[1] + inv[r * 3 + 2] * drift[2];
    }
  }
  return used;
}

void BeaconLocalizationUnit::PublishOutputs() {
  position_[0] = x_[0];
  position_[1] = x_[1];
  yaw_ = WrapAngle(x_[2]);
  const double sys2 = systematic_sigma_ * systematic_sigma_;
  for (std::size_t r = 0; r < 3; ++r) {
    for (std::size_t q = 0; q < 3; ++q)
      covariance_[r * 3 + q] = p_[r * 3 + q] + sys2 * g_[r] * g_[q];
  }
}

void BeaconLocalizationUnit::ProcessScan() {
  Detect();
  if (!started_) {
    std::array<double, 3> laser{};
    if (!AssociateByGeometry(laser)) {
      beacons_seen_ = 0;
      valid_ = false;
      ++scan_index_;
      return;
    }
    // The robot's pose from the laser's.
    const double yaw = WrapAngle(laser[2] - mount_yaw_);
    const double c = std::cos(yaw), s = std::sin(yaw);
    x_ = {laser[0] - (c * mount_x_ - s * mount_y_), laser[1] - (s * mount_x_ + c * mount_y_), yaw};
    const double pp = initial_sigma_position_ * initial_sigma_position_;
    p_ = {pp, 0, 0, 0, pp, 0, 0, 0, initial_sigma_yaw_ * initial_sigma_yaw_};
    g_ = {};
    started_ = true;
    std::fill(beacon_last_scan_.begin(), beacon_last_scan_.end(), -1);
  } else {
    const double dt = std::max(0.0, scan_time_ - last_scan_time_);
    const double qp = process_noise_position_ * process_noise_position_ * dt;
    p_[0] += qp;
    p_[4] += qp;
    p_[8] += process_noise_yaw_ * process_noise_yaw_ * dt;
    AssociateByPrediction();
  }
  last_scan_time_ = scan_time_;
  const int used = Update();
  beacons_seen_ = used;
  if (used > 0) ++scans_used_;
  ++scan_index_;
  for (int k = 0; k < detection_count_; ++k) {
    const int j = detections_[static_cast<std::size_t>(k)].beacon;
    if (j >= 0) beacon_last_scan_[static_cast<std::size_t>(j)] = scan_index_;
  }
  std::int64_t recent = 0;
  for (const std::int64_t last : beacon_last_scan_) {
    if (last >= 0 && last > scan_index_ - valid_scans_) ++recent;
  }
  valid_ = recent >= min_beacons_;
  PublishOutputs();
  // Lost (nothing associated for valid_scans scans): from geometry again.
  if (recent == 0) started_ = false;
}

cosim::StepResult BeaconLocalizationUnit::DoStep(cosim::TimeNs t, cosim::TimeNs) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  if (active_ && !was_active_) {
    // Uncovered (again): the robot may have moved meanwhile.
    started_ = false;
    scans_used_ = 0;
    active_since_ns_ = t;
  }
  was_active_ = active_;
  if (scan_count_ != last_count_) {
    last_count_ = scan_count_;
    if (active_ && InputTimeNs(scan_time_, "scan_time") >=
                       active_since_ns_ + cosim::SecondsToNs(uncover_delay_)) {
      ProcessScan();
    }
  }
  if (!active_) valid_ = false;
  return cosim::StepResult::kOk;
}

void BeaconLocalizationUnit::SaveInternal(cosim::UnitState& state) const {
  state.integers = {start_, was_active_ ? 1 : 0, started_ ? 1 : 0, scan_index_, active_since_ns_};
  state.integers.insert(state.integers.end(), beacon_last_scan_.begin(), beacon_last_scan_.end());
  state.reals = {last_count_, last_scan_time_};
  state.reals.insert(state.reals.end(), x_.begin(), x_.end());
  state.reals.insert(state.reals.end(), p_.begin(), p_.end());
  state.reals.insert(state.reals.end(), g_.begin(), g_.end());
}

void BeaconLocalizationUnit::RestoreInternal(const cosim::UnitState& state) {
  const std::size_t ni = 5 + beacon_last_scan_.size();
  if (state.integers.size() != ni || state.reals.size() != 17) {
    throw cosim::UnitError(Where() + ": saved state has " + std::to_string(state.reals.size()) +
                           " reals and " + std::to_string(state.integers.size()) +
                           " integers, expected 17 and " + std::to_string(ni));
  }
  scan_index_ = state.integers[3];
  active_since_ns_ = state.integers[4];
  std::copy(state.integers.begin() + 5, state.integers.end(), beacon_last_scan_.begin());
  start_ = state.integers[0];
  was_active_ = state.integers[1] != 0;
  started_ = state.integers[2] != 0;
  last_count_ = state.reals[0];
  last_scan_time_ = state.reals[1];
  std::copy(state.reals.begin() + 2, state.reals.begin() + 5, x_.begin());
  std::copy(state.reals.begin() + 5, state.reals.begin() + 14, p_.begin());
  std::copy(state.reals.begin() + 14, state.reals.begin() + 17, g_.begin());
  detection_count_ = 0;
  Derive();
}

}  // namespace linesim::evaluation
