#include "units/sensors/laser_scanner_unit.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <utility>

#include "cosim/seed.h"
#include "models/moving_solids.h"
#include "models/rotation.h"

namespace linesim::sensors {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Marsaglia and Tsang's ziggurat for the normal distribution ("The
// Ziggurat Method for Generating Random Variables", J. Stat. Softw. 5(8),
// 2000), 256 layers of equal area v under f(x) = exp(-x^2 / 2): layer 0 is
// the rectangle [0, r] x [0, f(r)] with the tail beyond r, layer i >= 1 the
// rectangle of width x_i between heights f(x_i) and f(x_{i+1}).
struct Ziggurat {
  static constexpr double kR = 3.6541528853610088;  // x_1, the tail's start
  static constexpr double kV = 4.92867323399e-3;    // each layer's area
  std::array<double, 257> x{};  // x_0 = v / f(r) (layer 0's pseudo width) > x_1 = r > ... > x_256 = 0
  std::array<double, 257> f{};  // f(x_i)
  Ziggurat() {
    x[0] = kV / std::exp(-0.5 * kR * kR);
    x[1] = kR;
    for (std::size_t i = 1; i < 255; ++i) {
      x[i + 1] = std::sqrt(-2.0 * std::log(kV / x[i] + std::exp(-0.5 * x[i] * x[i])));
    }
    x[256] = 0.0;
    for (std::size_t i = 0; i < 257; ++i) f[i] = std::exp(-0.5 * x[i] * x[i]);
  }
};

const Ziggurat& ZigguratTables() {
  static const Ziggurat z;
  return z;
}

// Uniform in [0, 1) from the top 53 bits (converted as signed: the unsigned
// conversion costs a branch without AVX-512).
double Uniform(std::mt19937_64& rng) {
  return static_cast<double>(static_cast<std::int64_t>(rng() >> 11)) * 0x1.0p-53;
}

// std::nearbyint in the default rounding mode (to nearest, ties to even),
// without the library call (which saves and restores the floating-point
// environment): below 2^51 in magnitude, adding and subtracting 1.5 * 2^52
// leaves the nearest integer (the sum's unit in the last place is 1). The
// same value as nearbyint but for the sign of a zero (-0.4 gives +0), which
// the reported range's max(0, .) makes moot.
double RoundHalfEven(double x) {
  constexpr double kMagic = 0x1.8p52;
  if (!(std::abs(x) < 0x1.0p51)) return std::nearbyint(x);
  // (Not folded away: without -ffast-math the compiler keeps IEEE sums.)
  const double sum = x + kMagic;
  return sum - kMagic;
}

}  // namespace

LaserScannerUnit::LaserScannerUnit(std::string name, const models::Scene& scene, int beam_count,
                                   std::vector<std::array<double, 2>> protective_field,
                                   std::uint64_t seed, int moving_cylinders, int moving_boxes)
    : cosim::Unit(kTypeName, std::move(name)),
      beam_count_(beam_count),
      has_field_(!protective_field.empty()),
      field_(std::move(protective_field)),
      rays_(scene),
      rng_(seed) {
  if (beam_count < 1) {
    throw cosim::UnitError(Where() + ": beam_count must be at least 1, got " +
                           std::to_string(beam_count));
  }
  if (has_field_ && field_.size() < 3) {
    throw cosim::UnitError(Where() + ": the protective field needs at least 3 corners, got " +
                           std::to_string(field_.size()));
  }
  const auto n = static_cast<std::size_t>(beam_count);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  scan_period_ = first_beam_angle_ = angular_step_ = range_min_ = range_max_ = range_resolution_ =
      noise_sigma_ = max_incidence_ = echo_separation_ = no_return_value_ = nan;
  position_.assign(3, 0.0);
  orientation_ = {1.0, 0.0, 0.0, 0.0};
  velocity_.assign(3, 0.0);
  angular_velocity_.assign(3, 0.0);
  belt_travel_.assign(scene.belts.size(), 0.0);
  belt_speed_.assign(scene.belts.size(), 0.0);
  if (moving_cylinders < 0 || moving_boxes < 0) {
    throw cosim::UnitError(Where() + ": moving_cylinders and moving_boxes must be >= 0, got " +
                           std::to_string(moving_cylinders) + " and " +
                           std::to_string(moving_boxes));
  }
  // Length 0 until connected: absent.
  moving_boxes_.assign(models::MovingBox::kValues * static_cast<std::size_t>(moving_boxes), 0.0);
  // Far below the floor until connected: seen by no beam.
  moving_.assign(RayScene::kMovingValues * static_cast<std::size_t>(moving_cylinders), 0.0);
  for (std::size_t i = 0; i < moving_.size(); i += RayScene::kMovingValues) {
    moving_[i + 5] = -2.0;
    moving_[i + 6] = -1.0;
  }
  ranges_.assign(n, 0.0);
  beam_rays_.resize(n);
  centre_.resize(n);
  samples_.resize(n);
  scan_ranges_.assign(n, 0.0);
  beam_perp_.resize(n);
  step_s_.assign(n, 0.0);
  step_sin_.assign(n, 0.0);
  step_vers_.assign(n, 0.0);
  edge_beam_.assign(n, 0);
  edge_rays_.resize(4 * n);
  edge_hits_.resize(4 * n);

  auto& v = variables();
  const auto mount = [&](const char* key, const char* unit, double* x, const char* what) {
    v.Parameter(key, unit, x, what, cosim::Rule::Finite());
  };
  mount("mount_x", "m", &mount_x_, "scanner origin in base_link, x");
  mount("mount_y", "m", &mount_y_, "scanner origin in base_link, y");
  mount("mount_z", "m", &mount_z_, "scanner origin in base_link, z (scan plane height at rest)");
  mount("mount_roll", "rad", &mount_roll_, "scanner roll in base_link (pi: mounted upside down)");
  mount("mount_pitch", "rad", &mount_pitch_, "scanner pitch in base_link");
  mount("mount_yaw", "rad", &mount_yaw_, "scanner yaw in base_link (direction of beam angle 0)");
  v.Parameter("scan_period", "s", &scan_period_, "one turn of the mirror (one scan)",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("first_beam_angle", "rad", &first_beam_angle_,
              "direction of beam 0 in the scanner frame, counter-clockwise from x",
              cosim::Rule::Range(-2 * std::numbers::pi, 2 * std::numbers::pi).NoDefault());
  v.Parameter("angular_step", "rad", &angular_step_, "angle between neighbouring beams",
              cosim::Rule::Range(0, false, std::numbers::pi, true).NoDefault());
  v.Parameter("range_min", "m", &range_min_, "nearest distance measured",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("range_max", "m", &range_max_, "farthest distance measured",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("range_resolution", "m", &range_resolution_, "step of the reported range",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("noise_sigma", "m", &noise_sigma_, "statistical range error (1 sigma), per beam",
              cosim::Rule::NonNegative().NoDefault());
  v.Parameter("bias_sigma", "m", &bias_sigma_,
              "systematic range error: one bias per device drawn from N(0, bias_sigma)",
              cosim::Rule::NonNegative());
  v.Parameter("bias_max", "m", &bias_max_, "the drawn bias is clamped to +-bias_max",
              cosim::Rule::NonNegative());
  v.Parameter("device_seed", &device_seed_,
              "which physical unit: >= 0 draws the bias from this seed and the unit's name, "
              "the same in every run (one scanner for all runs); -1: a new unit per run "
              "(the bias from the run's seed)",
              cosim::Rule::Range(-1, 4294967295.0));
  v.Parameter("max_incidence", "rad", &max_incidence_,
              "no return when the beam meets the surface further than this from its normal",
              cosim::Rule::Range(0, false, std::numbers::pi / 2, true).NoDefault());
  v.Parameter("spot_divergence", "rad", &spot_divergence_,
              "spot diameter = range * spot_divergence + spot_offset", cosim::Rule::NonNegative());
  v.Parameter("spot_offset", "m", &spot_offset_, "spot diameter at the front window",
              cosim::Rule::NonNegative());
  v.Parameter("echo_separation", "m", &echo_separation_,
              "two surfaces within one spot further apart than this give separate echoes "
              "(the first is reported); closer, one mixed echo",
              cosim::Rule::Positive().NoDefault());
  v.Parameter("no_return_value", "m", &no_return_value_,
              "the range the device reports for a beam without echo", cosim::Rule::Finite().NoDefault());
  v.Parameter("blackout_from", "s", &blackout_from_,
              "fault injection: beams measured from this time get no echo (a covered window) ...",
              cosim::Rule::NonNegative());
  v.Parameter("blackout_until", "s", &blackout_until_,
              "... until this time (blackout_until <= blackout_from: never)",
              cosim::Rule::NonNegative());
  if (has_field_) {
    v.Parameter("multiple_sampling", &multiple_sampling_,
                "consecutive scans with an object in the protective field before field_clear "
                "goes to 0",
                cosim::Rule::OneOf({2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16}));
  }

  v.Input("position_3d", "m", &position_, "base_link origin in map");
  v.Input("orientation", "1", &orientation_, "base_link in map, quaternion w x y z");
  v.Input("velocity_3d", "m/s", &velocity_, "base_link origin velocity in map");
  v.Input("angular_velocity", "rad/s", &angular_velocity_, "angular velocity in base_link");
  if (!scene.belts.empty()) {
    v.Input("belt_travel", "m", &belt_travel_, "distance each scene belt has moved");
    v.Input("belt_speed", "m/s", &belt_speed_, "speed of each scene belt");
  }
  if (!moving_.empty()) {
    v.Input("moving_cylinders", "m, m/s", &moving_,
            "per moving cylinder (a worker's leg or torso) [x, y, vx, vy, radius, z_bottom, "
            "z_top] in map");
  }
  if (!moving_boxes_.empty()) {
    v.Parameter("own_box", &own_box_,
                "the box of moving_boxes that is the scanner's own robot (not seen); -1: none",
                cosim::Rule::Range(-1, 100000));
    v.Input("moving_boxes", "m, rad, m/s, rad/s", &moving_boxes_,
            "per moving box (a robot's body, its chassis' body_box) [x, y, yaw, vx, vy, "
            "yaw_rate, length, width, z_bottom, z_top] in map");
  }
  v.Output("ranges", "m", &ranges_,
           "range of each beam of the last complete scan (no_return_value: no echo)", {});
  v.Output("scan_time", "s", &scan_time_, "start time of the last complete scan", {});
  v.Output("scan_count", "1", &scan_count_, "complete scans so far", {});
  v.Output("range_bias", "m", &bias_,
           "this device's systematic range error (constant: what a calibration against a "
           "known target reads; maps built by SLAM with this scanner carry it)",
           {});
  if (has_field_) {
    v.Output("field_clear", "1", &field_clear_,
             "1: protective field clear (OSSDs on), 0: object in the field (OSSDs off)", {});
  }

  // The device's bias, drawn once, first (as a unit normal: scaled by
  // bias_sigma and clamped when the parameters are known).
  bias_draw_ = Normal();
}

double LaserScannerUnit::Normal() { return NormalFrom(rng_); }

double LaserScannerUnit::NormalFrom(std::mt19937_64& rng) {
  // The ziggurat (see Ziggurat): one 64-bit draw gives the layer (8 bits),
  // the sign (1 bit) and the abscissa (53 bits); 98.8 % of the draws end in
  // a layer's rectangle, without log, sqrt or division. Nothing is cached
  // between calls: the generator's state is the whole state.
  const Ziggurat& zg = ZigguratTables();
  while (true) {
    const std::uint64_t u = rng();
    const auto i = static_cast<std::size_t>(u & 0xffu);
    // The sign as a bit flip: the same value as a product by -1 or 1, but
    // without a branch on a random bit (mispredicted half the time).
    const std::uint64_t sign_bit = (u & 0x100u) << 55;
    const auto sign = [sign_bit](double v) {
      return std::bit_cast<double>(std::bit_cast<std::uint64_t>(v) ^ sign_bit);
    };
    const double z = static_cast<double>(static_cast<std::int64_t>(u >> 11)) * 0x1.0p-53 * zg.x[i];
    if (z < zg.x[i + 1]) return sign(z);
    if (i == 0) {
      // The tail beyond r (Marsaglia 1964): r + a with a = -ln(U1) / r,
      // accepted when -2 ln(U2) > a^2.
      double a, b;
      do {
        a = -std::log(1.0 - Uniform(rng)) / Ziggurat::kR;
        b = -std::log(1.0 - Uniform(rng));
      } while (b + b < a * a);
      return sign(Ziggurat::kR + a);
    }
    // The wedge: a uniform height in the layer, under the curve or not.
    const double y = zg.f[i] + Uniform(rng) * (zg.f[i + 1] - zg.f[i]);
    if (y < std::exp(-0.5 * z * z)) return sign(z);
  }
}

std::vector<cosim::ParameterProblem> LaserScannerUnit::CheckParameters() const {
  auto problems = cosim::Unit::CheckParameters();
  if (range_min_ >= range_max_) {
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

bool LaserScannerUnit::InField(double x, double y) const {
  // Even-odd rule.
  bool inside = false;
  for (std::size_t i = 0, j = field_.size() - 1; i < field_.size(); j = i++) {
    const auto& a = field_[i];
    const auto& b = field_[j];
    if ((a[1] > y) != (b[1] > y) && x < (b[0] - a[0]) * (y - a[1]) / (b[1] - a[1]) + a[0]) {
      inside = !inside;
    }
  }
  return inside;
}

void LaserScannerUnit::Derive() {
  period_ns_ = cosim::SecondsToNs(scan_period_);
  beam_offset_ns_.resize(static_cast<std::size_t>(beam_count_));
  cos_a_.resize(beam_offset_ns_.size());
  sin_a_.resize(beam_offset_ns_.size());
  for (int i = 0; i < beam_count_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    beam_offset_ns_[k] = static_cast<cosim::TimeNs>(std::llround(
        static_cast<double>(period_ns_) * i * angular_step_ / (2.0 * std::numbers::pi)));
    const double a = first_beam_angle_ + i * angular_step_;
    cos_a_[k] = std::cos(a);
    sin_a_[k] = std::sin(a);
  }
  // The field's reach along each beam: its corners' largest projection on
  // the beam's direction (a point of the polygon lies in its corners'
  // convex hull, so no farther along the beam than that).
  field_reach_.assign(static_cast<std::size_t>(beam_count_), -kInf);
  for (std::size_t k = 0; has_field_ && k < field_reach_.size(); ++k) {
    for (const auto& c : field_) {
      field_reach_[k] = std::max(field_reach_[k], c[0] * cos_a_[k] + c[1] * sin_a_[k]);
    }
  }
  // The scanner's x and y axes in base_link: the mount rotation's columns.
  const models::Matrix3 mount = models::RollPitchYawMatrix(mount_roll_, mount_pitch_, mount_yaw_);
  mount_in_base_ = {std::array<double, 3>{mount[0], mount[3], mount[6]},
                    std::array<double, 3>{mount[1], mount[4], mount[7]},
                    std::array<double, 3>{mount_x_, mount_y_, mount_z_}};
  cos_max_incidence_ = std::cos(max_incidence_);
  double draw = bias_draw_;
  if (device_seed_ >= 0) {
    std::mt19937_64 device(cosim::DeriveSeed(static_cast<std::uint64_t>(device_seed_),
                                             name() + " range bias"));
    draw = NormalFrom(device);
  }
  bias_ = std::clamp(draw * bias_sigma_, -bias_max_, bias_max_);
}

void LaserScannerUnit::Setup(cosim::TimeNs start, cosim::TimeNs) { start_ = start; }

void LaserScannerUnit::Initialize() {
  ThrowIfBadParameters();
  Derive();
  scan_start_ = start_;
  next_beam_ = 0;
  finalized_ = 0;
  infringing_scans_ = 0;
  scan_time_ = cosim::NsToSeconds(start_);
  scan_count_ = 0.0;
  field_clear_ = 1.0;
  std::fill(ranges_.begin(), ranges_.end(), no_return_value_);
}

void LaserScannerUnit::PrepareStep() {
  // Over the step the base turns at the constant body rate w = |w| k:
  // R(s) = R0 E(s), E(s) v = v + sin(w s) k x v + (1 - cos(w s)) k x (k x v)
  // (Rodrigues). For the three vectors the beams need (the scanner's x and
  // y axes and its origin, in base_link) R0 v, R0 (k x v) and
  // R0 (k x (k x v)) are fixed over the step: a beam's pose is then two
  // scalars and a few multiply-adds.
  // Rotation preserves cross products: R0 (k x v) = (R0 k) x (R0 v), so
  // one rotation matrix from q0 and three of its products do it all.
  // The rotation of q whatever its norm (a quaternion off unit length by
  // rounding or an FMU's output still gives unit ray directions; DoStep
  // refuses a zero one).
  const models::Matrix3 m =
      models::QuaternionMatrix(orientation_[0], orientation_[1], orientation_[2], orientation_[3]);
  const auto rotate = [&m](const std::array<double, 3>& v) {
    return std::array<double, 3>{m[0] * v[0] + m[1] * v[1] + m[2] * v[2],
                                 m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
                                 m[6] * v[0] + m[7] * v[1] + m[8] * v[2]};
  };
  const double wx = angular_velocity_[0], wy = angular_velocity_[1], wz = angular_velocity_[2];
  rate_ = std::sqrt(wx * wx + wy * wy + wz * wz);
  const std::array<double, 3> k =
      rate_ > 0.0 ? rotate({wx / rate_, wy / rate_, wz / rate_}) : std::array<double, 3>{0.0, 0.0, 0.0};
  const auto cross = [](const std::array<double, 3>& u, const std::array<double, 3>& v) {
    return std::array<double, 3>{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                                 u[0] * v[1] - u[1] * v[0]};
  };
  for (std::size_t j = 0; j < 3; ++j) {
    frame_[j][0] = rotate(mount_in_base_[j]);
    frame_[j][1] = cross(k, frame_[j][0]);
    frame_[j][2] = cross(k, frame_[j][1]);
  }
}

void LaserScannerUnit::BeamRay(int i, double s, double sn, double vc) {
  // The scanner's x, y axes and origin offset in map, in scalars (stored
  // and reloaded arrays stall store forwarding here).
  const auto& fx = frame_[0];
  const auto& fy = frame_[1];
  const auto& fo = frame_[2];
  const double x0 = fx[0][0] + sn * fx[1][0] + vc * fx[2][0];
  const double x1 = fx[0][1] + sn * fx[1][1] + vc * fx[2][1];
  const double x2 = fx[0][2] + sn * fx[1][2] + vc * fx[2][2];
  const double y0 = fy[0][0] + sn * fy[1][0] + vc * fy[2][0];
  const double y1 = fy[0][1] + sn * fy[1][1] + vc * fy[2][1];
  const double y2 = fy[0][2] + sn * fy[1][2] + vc * fy[2][2];
  const auto k = static_cast<std::size_t>(i);
  const double ca = cos_a_[k], sa = sin_a_[k];
  Ray& r = beam_rays_[k];
  r.origin[0] = position_[0] + velocity_[0] * s + (fo[0][0] + sn * fo[1][0] + vc * fo[2][0]);
  r.origin[1] = position_[1] + velocity_[1] * s + (fo[0][1] + sn * fo[1][1] + vc * fo[2][1]);
  r.origin[2] = position_[2] + velocity_[2] * s + (fo[0][2] + sn * fo[1][2] + vc * fo[2][2]);
  r.direction[0] = ca * x0 + sa * y0;
  r.direction[1] = ca * x1 + sa * y1;
  r.direction[2] = ca * x2 + sa * y2;
  auto& perp = beam_perp_[k];
  perp[0] = -sa * x0 + ca * y0;
  perp[1] = -sa * x1 + ca * y1;
  perp[2] = -sa * x2 + ca * y2;
  // Far enough for a spot sample beyond range_max to still be met.
  r.max_range = range_max_ * 1.5;
  r.dt_s = s;
}

void LaserScannerUnit::CastBeams(int first, int end, cosim::TimeNs t) {
  step_t_ = t;
  const auto n = static_cast<std::size_t>(end - first);
  // In three passes: the beams' times, their turn's sin(w s) and
  // 1 - cos(w s), their poses (each pass without a dependency between
  // beams: the series' chains of multiply-adds overlap).
  for (int i = first; i < end; ++i) {
    step_s_[static_cast<std::size_t>(i)] = cosim::NsToSeconds(scan_start_ + BeamOffset(i) - t);
  }
  const double th_max = rate_ * std::max(std::abs(step_s_[static_cast<std::size_t>(first)]),
                                         std::abs(step_s_[static_cast<std::size_t>(end - 1)]));
  if (th_max < 0.1) {
    // Within a step the turn is small: the series of sin and 1 - cos to
    // th^9 and th^10 are exact to double rounding for |th| < 0.1 (the next
    // terms are below 0.1^11 / 11! = 2.5e-19) and cheaper than sin and cos.
    // Horner in th^2 with the factorials' reciprocals (no divisions).
    for (int i = first; i < end; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const double th = rate_ * step_s_[k], t2 = th * th;
      step_sin_[k] = th * (1.0 + t2 * (-1.0 / 6.0 + t2 * (1.0 / 120.0 + t2 * (-1.0 / 5040.0 +
                                                                           t2 * (1.0 / 362880.0)))));
      step_vers_[k] = t2 * (0.5 + t2 * (-1.0 / 24.0 + t2 * (1.0 / 720.0 + t2 * (-1.0 / 40320.0 +
                                                                           t2 * (1.0 / 3628800.0)))));
    }
  } else {
    for (int i = first; i < end; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const double th = rate_ * step_s_[k];
      step_sin_[k] = std::sin(th);
      step_vers_[k] = 1.0 - std::cos(th);
    }
  }
  for (int i = first; i < end; ++i) {
    const auto k = static_cast<std::size_t>(i);
    BeamRay(i, step_s_[k], step_sin_[k], step_vers_[k]);
  }
  rays_.Cast(std::span<const Ray>(beam_rays_.data() + first, n),
             std::span<RayHit>(centre_.data() + first, n), belt_travel_, belt_speed_, moving_,
             moving_boxes_, static_cast<int>(own_box_));
  for (int i = first; i < end; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const RayHit& h = centre_[k];
    const double e = std::isinf(h.range) ? 0.0 : h.cos_incidence / (h.range * h.range);
    samples_[k].fill({h.range, e, h.cos_incidence});
  }
  // Edges between neighbours, each side sampled across its spot.
  int edges = 0;
  if (spot_divergence_ > 0.0 || spot_offset_ > 0.0) {
    for (int i = std::max(first, 1); i < end; ++i) {
      const RayHit& a = centre_[static_cast<std::size_t>(i - 1)];
      const RayHit& b = centre_[static_cast<std::size_t>(i)];
      const bool edge = a.object != b.object ||
                        (a.object >= 0 && std::abs(a.range - b.range) > echo_separation_);
      if (edge) {
        // Its four samples, cast with the batch's other edges' below.
        PrepareEdge(i, &edge_rays_[4 * static_cast<std::size_t>(edges)]);
        edge_beam_[static_cast<std::size_t>(edges++)] = i;
      }
    }
  }
  if (edges > 0) {
    const auto m = 4 * static_cast<std::size_t>(edges);
    rays_.Cast(std::span<const Ray>(edge_rays_.data(), m), std::span<RayHit>(edge_hits_.data(), m),
               belt_travel_, belt_speed_, moving_, moving_boxes_,
             static_cast<int>(own_box_));
    for (int e = 0; e < edges; ++e) {
      ApplyEdge(edge_beam_[static_cast<std::size_t>(e)], &edge_hits_[4 * static_cast<std::size_t>(e)]);
    }
  }
}

void LaserScannerUnit::PrepareEdge(int i, Ray* sub) const {
  // Beam i - 1 is sampled towards + (its +h/2 and +h), beam i towards -.
  for (int side = 0; side < 2; ++side) {
    const auto k = static_cast<std::size_t>(i - 1 + side);
    const Ray& r = beam_rays_[k];
    double d = centre_[k].range;
    if (std::isinf(d)) d = centre_[static_cast<std::size_t>(i - side)].range;
    const double h = 0.5 * (spot_divergence_ + spot_offset_ / std::max(d, 1e-3));
    const double sgn = side == 0 ? 1.0 : -1.0;
    for (int j = 0; j < 2; ++j) {
      const double alpha = sgn * h * (j == 0 ? 0.5 : 1.0);
      const double ca = std::cos(alpha), sa = std::sin(alpha);
      Ray& s = sub[2 * side + j];
      s = r;
      // The sample's time relative to this step's inputs.
      s.dt_s = cosim::NsToSeconds(scan_start_ + BeamOffset(i - 1 + side) - step_t_);
      for (std::size_t c = 0; c < 3; ++c) s.direction[c] = ca * r.direction[c] + sa * beam_perp_[k][c];
    }
  }
}

void LaserScannerUnit::ApplyEdge(int i, const RayHit* hit) {
  // Sample slots: 0: -h, 1: -h/2, 2: centre, 3: +h/2, 4: +h.
  constexpr std::size_t kSlot[4] = {3, 4, 1, 0};
  for (std::size_t j = 0; j < 4; ++j) {
    const auto k = static_cast<std::size_t>(i - 1 + (j < 2 ? 0 : 1));
    const RayHit& h = hit[j];
    const double e = std::isinf(h.range) ? 0.0 : h.cos_incidence / (h.range * h.range);
    samples_[k][kSlot[j]] = {h.range, e, h.cos_incidence};
  }
}

void LaserScannerUnit::Finalize(int first, int end) {
  // In two passes: each beam's echo and noise draw (the draws in beam
  // order), then the reported ranges (the divisions of the second pass do
  // not wait on one another or on the generator).
  for (int i = first; i < end; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const auto& sm = samples_[k];
    bool uniform = true;
    for (const Sample& x : sm) uniform = uniform && x.range == sm[2].range;
    double r = kInf, cos_inc = 0.0;
    if (uniform) {
      r = sm[2].range;
      cos_inc = sm[2].cos_incidence;
    } else {
      MixEcho(sm, r, cos_inc);
    }
    // The measured range before rounding; NaN: no return.
    double m = std::numeric_limits<double>::quiet_NaN();
    const double beam_s = cosim::NsToSeconds(scan_start_ + BeamOffset(i));
    const bool blackout = beam_s >= blackout_from_ && beam_s < blackout_until_;
    if (!blackout && r >= range_min_ && r <= range_max_ && cos_inc >= cos_max_incidence_) {
      m = r + bias_ + noise_sigma_ * Normal();
    }
    scan_ranges_[k] = m;
  }
  for (int i = first; i < end; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const double m = scan_ranges_[k];
    scan_ranges_[k] = std::isnan(m) ? no_return_value_
                                    : std::max(0.0, RoundHalfEven(m / range_resolution_) *
                                                        range_resolution_);
  }
}

void LaserScannerUnit::MixEcho(const std::array<Sample, kSpotSamples>& sm, double& r,
                               double& cos_inc) const {
  // Nearest echo: the samples within echo_separation of one another,
  // starting from the nearest.
  std::array<Sample, kSpotSamples> sorted = sm;
  std::sort(sorted.begin(), sorted.end(),
            [](const Sample& a, const Sample& b) { return a.range < b.range; });
  if (!std::isinf(sorted[0].range)) {
    double sum_e = 0.0, sum_er = 0.0;
    for (std::size_t j = 0; j < sorted.size(); ++j) {
      if (std::isinf(sorted[j].range)) break;
      if (j > 0 && sorted[j].range - sorted[j - 1].range > echo_separation_) break;
      sum_e += sorted[j].energy;
      sum_er += sorted[j].energy * sorted[j].range;
      cos_inc = std::max(cos_inc, sorted[j].cos_incidence);
    }
    r = sum_e > 0.0 ? sum_er / sum_e : sorted[0].range;
  }
}

void LaserScannerUnit::CompleteScan() {
  std::copy(scan_ranges_.begin(), scan_ranges_.end(), ranges_.begin());
  scan_time_ = cosim::NsToSeconds(scan_start_);
  scan_count_ += 1.0;
  if (has_field_) {
    bool infringed = false;
    for (int i = 0; i < beam_count_ && !infringed; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const double r = ranges_[k];
      if (r == no_return_value_ || r > field_reach_[k]) continue;
      infringed = InField(r * cos_a_[k], r * sin_a_[k]);
    }
    infringing_scans_ = infringed ? infringing_scans_ + 1 : 0;
    if (infringing_scans_ >= multiple_sampling_) field_clear_ = 0.0;
    if (!infringed) field_clear_ = 1.0;
  }
  scan_start_ += period_ns_;
  next_beam_ = 0;
  finalized_ = 0;
}

cosim::StepResult LaserScannerUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  const double q2 = orientation_[0] * orientation_[0] + orientation_[1] * orientation_[1] +
                    orientation_[2] * orientation_[2] + orientation_[3] * orientation_[3];
  if (!(q2 > 1e-12)) {
    return Fail(Where() + ": input 'orientation' is a zero quaternion at t = " +
                cosim::FormatSeconds(t) + " s: no attitude to cast the beams from");
  }
  const cosim::TimeNs t_end = t + dt;
  PrepareStep();
  while (true) {
    int end = next_beam_;
    while (end < beam_count_ && scan_start_ + BeamOffset(end) < t_end) ++end;
    if (end > next_beam_) {
      CastBeams(next_beam_, end, t);
      // The edge between the last beam of the previous batch and the first
      // of this one.
      next_beam_ = end;
    }
    // Every beam but the last cast one is final (its right edge is known).
    const int final_end = next_beam_ == beam_count_ ? beam_count_ : next_beam_ - 1;
    if (finalized_ < final_end) {
      Finalize(finalized_, final_end);
      finalized_ = final_end;
    }
    if (next_beam_ == beam_count_) {
      CompleteScan();
      continue;
    }
    break;
  }
  return cosim::StepResult::kOk;
}

void LaserScannerUnit::SaveInternal(cosim::UnitState& state) const {
  std::ostringstream rng;
  rng << rng_;
  state.strings = {rng.str()};
  state.integers = {start_, scan_start_, next_beam_, finalized_, infringing_scans_};
  state.reals = {bias_draw_};
  state.reals.insert(state.reals.end(), scan_ranges_.begin(), scan_ranges_.end());
  for (int i = 0; i < next_beam_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    const Ray& r = beam_rays_[k];
    state.reals.insert(state.reals.end(), {r.origin[0], r.origin[1], r.origin[2], r.direction[0],
                                           r.direction[1], r.direction[2], r.max_range, r.dt_s,
                                           centre_[k].range, centre_[k].cos_incidence,
                                           static_cast<double>(centre_[k].object),
                                           beam_perp_[k][0], beam_perp_[k][1], beam_perp_[k][2]});
    for (const Sample& s : samples_[k]) {
      state.reals.insert(state.reals.end(), {s.range, s.energy, s.cos_incidence});
    }
  }
}

void LaserScannerUnit::RestoreInternal(const cosim::UnitState& state) {
  const auto n = static_cast<std::size_t>(beam_count_);
  if (state.strings.size() != 1 || state.integers.size() != 5 || state.reals.size() < 1 + n) {
    throw cosim::UnitError(Where() + ": saved state does not fit this unit");
  }
  // Everything is checked before anything is assigned: a state that does
  // not fit leaves the unit as it was.
  const std::int64_t next_beam = state.integers[2], finalized = state.integers[3];
  const std::size_t per_beam = 14 + 3 * kSpotSamples;
  if (next_beam < 0 || next_beam > beam_count_ || finalized < 0 || finalized > next_beam ||
      state.reals.size() != 1 + n + per_beam * static_cast<std::size_t>(next_beam)) {
    throw cosim::UnitError(Where() + ": saved state does not fit this unit");
  }
  std::istringstream rng_text(state.strings[0]);
  std::mt19937_64 rng;
  rng_text >> rng;
  if (!rng_text) throw cosim::UnitError(Where() + ": saved generator state is not readable");
  rng_ = rng;
  start_ = state.integers[0];
  scan_start_ = state.integers[1];
  next_beam_ = static_cast<int>(next_beam);
  finalized_ = static_cast<int>(finalized);
  infringing_scans_ = state.integers[4];
  bias_draw_ = state.reals[0];
  std::copy(state.reals.begin() + 1, state.reals.begin() + 1 + static_cast<std::ptrdiff_t>(n),
            scan_ranges_.begin());
  std::size_t p = 1 + n;
  for (int i = 0; i < next_beam_; ++i) {
    const auto k = static_cast<std::size_t>(i);
    Ray& r = beam_rays_[k];
    r.origin = {state.reals[p], state.reals[p + 1], state.reals[p + 2]};
    r.direction = {state.reals[p + 3], state.reals[p + 4], state.reals[p + 5]};
    r.max_range = state.reals[p + 6];
    r.dt_s = state.reals[p + 7];
    centre_[k] = {state.reals[p + 8], state.reals[p + 9], static_cast<int>(state.reals[p + 10])};
    beam_perp_[k] = {state.reals[p + 11], state.reals[p + 12], state.reals[p + 13]};
    p += 14;
    for (Sample& s : samples_[k]) {
      s = {state.reals[p], state.reals[p + 1], state.reals[p + 2]};
      p += 3;
    }
  }
  Derive();
}

}  // namespace linesim::sensors
