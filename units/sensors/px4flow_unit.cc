#include "units/sensors/px4flow_unit.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <utility>

namespace linesim::sensors {

namespace {

// Keeps the image mode's texture stream apart from the fast model's.
constexpr std::uint64_t kImageSeedSalt = 0x9e3779b97f4a7c15ULL;

// Fast-model constants fitted to the image-level reference (px4flow_image.h)
// at texture_scale 1 mm, mount height 0.1841 m, over contrast 0.02..0.3,
// 20..3000 lx, 0..0.7 m/s (see the class comment and the calibration test
// tests/units/sensors/px4flow_fast_vs_image_test.cc).
constexpr double kDiffPerSigma = 19.1492;  // 24 * sqrt(2 / pi)
constexpr double kNeighbourDiff = 0.45;    // std of a neighbour difference / (mean * contrast)
constexpr double kBlurScalePx = 1.8;       // blur length halving the along-motion part
constexpr double kBlockShape = 3.0;        // Gamma shape of the block-to-block texture variance
constexpr double kNoiseSpread = 0.2;       // relative spread of a noise-only measure
constexpr double kLostSnr = 0.18;          // snr at which half the blocks match noise
constexpr double kMatchNoise = 0.42;       // block offset std * snr (px)
constexpr double kMatchNoiseMax = 1.0;     // its limit at low snr (px)
constexpr double kAliasScalePx = 2.3;      // beyond the window: P(edge match) = exp(-(e/2.3)^2)

inline double Uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

// The block draws are many (25 per frame, 400 frames per second per
// sensor), so they use one 64-bit draw for several numbers:
// a zero-mean unit-variance Irwin-Hall variable (the sum of four 16-bit
// uniforms; bounded at +-3.46, close to normal) ...
inline double IrwinHall4(std::uint64_t r) {
  const double sum =
      static_cast<double>((r & 0xffff) + ((r >> 16) & 0xffff) + ((r >> 32) & 0xffff) + (r >> 48));
  return (sum * (1.0 / 65536.0) - 2.0) * 1.7320508075688772;
}

// ... and a Gamma(3, 1/3) variable (mean 1): the mean of three unit
// exponentials from three 21-bit uniforms in (0, 1].
inline double Gamma3(std::uint64_t r) {
  constexpr double k = 1.0 / 2097152.0;
  const double u1 = static_cast<double>((r & 0x1fffff) + 1) * k;
  const double u2 = static_cast<double>(((r >> 21) & 0x1fffff) + 1) * k;
  const double u3 = static_cast<double>(((r >> 42) & 0x1fffff) + 1) * k;
  return -std::log(u1 * u2 * u3) * (1.0 / 3.0);
}

// 16-bit and 24-bit uniforms in [0, 1) from parts of a draw.
inline double U16(std::uint64_t r, int shift) {
  return static_cast<double>((r >> shift) & 0xffff) * (1.0 / 65536.0);
}
inline double U24(std::uint64_t r, int shift) {
  return static_cast<double>((r >> shift) & 0xffffff) * (1.0 / 16777216.0);
}

// One standard normal by Box-Muller (one value per call, no cache, so the
// generator's state is the whole state): sonar and gyro noise.
inline double Normal(std::mt19937_64& rng) {
  const double u1 = 1.0 - Uniform(rng);  // (0, 1]
  const double u2 = Uniform(rng);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

inline double RoundHalf(double x) { return 0.5 * std::nearbyint(2.0 * x); }

}  // namespace

Px4FlowUnit::Px4FlowUnit(std::string name, const models::Scene& scene, std::uint64_t seed)
    : cosim::Unit(kTypeName, std::move(name)), surfaces_(scene.surfaces), seed_(seed), rng_(seed) {
  if (surfaces_.empty()) throw cosim::UnitError(Where() + ": the scene has no surfaces");
  floor_surface_ = scene.floor.surface;
  for (const models::Belt& b : scene.belts) {
    belts_.push_back(
        {b.area, b.surface, std::cos(b.area.direction_rad), std::sin(b.area.direction_rad)});
  }
  const auto n_belts = belts_.size();
  position_.assign(2, 0.0);
  linear_velocity_.assign(2, 0.0);
  angular_velocity_.assign(3, 0.0);
  belt_velocity_.assign(2 * n_belts, 0.0);
  integrated_gyro_.assign(3, 0.0);
  velocity_.assign(2, 0.0);
  frame_flow_.assign(2, 0.0);

  using cosim::Rule;
  auto& v = variables();
  v.Parameter("mount_x", "m", &mount_x_, "sensor position along base_link x",
              Rule::Finite().NoDefault());
  v.Parameter("mount_y", "m", &mount_y_, "sensor position along base_link y",
              Rule::Finite().NoDefault());
  v.Parameter("mount_height", "m", &mount_height_,
              "height of the lens above the floor (fixed; paper 1: 0.1841)",
              Rule::Range(0.01, 5.0).NoDefault());
  v.Parameter("mount_yaw", "rad", &mount_yaw_,
              "sensor x axis relative to base_link x, counter-clockwise in the floor plane",
              Rule::Finite());
  v.Parameter("mode", &mode_,
              "fast: the per-frame model of the firmware's block statistics; image: every frame "
              "rendered and block-matched as the firmware does (the slow reference)",
              Rule::OneOf({"fast", "image"}));
  v.Parameter("focal_length_px", "1", &focal_length_px_,
              "focal length in binned pixels (16 mm / (6 um * 4) = 666.7)", Rule::Positive());
  v.Parameter("frame_rate", "Hz", &frame_rate_, "camera frame rate (flow computations per s)",
              Rule::Range(1.0, 1000.0));
  v.Parameter("publish_rate", "Hz", &publish_rate_,
              "OPTICAL_FLOW_RAD rate (BFLOW_RATE, default 10)", Rule::Range(0.1, 1000.0));
  v.Parameter("feature_threshold", &feature_threshold_,
              "BFLOW_F_THLD: a block is used when compute_diff reaches it", Rule::Range(0, 6120));
  v.Parameter("search_range", &search_range_,
              "BFLOW_MAX_PIX: integer SAD search over +-this many pixels (4 before Sep 2016, 8 "
              "after)",
              Rule::Range(1, 8));
  v.Parameter("max_exposure", "s", &max_exposure_, "longest exposure the AEC may choose",
              Rule::Range(1e-5, 0.1));
  v.Parameter("max_gain", "1", &max_gain_, "highest analog gain the AGC may choose",
              Rule::Range(1.0, 64.0));
  v.Parameter("target_brightness", "1", &target_brightness_,
              "mean 8-bit image level the AEC/AGC aims at", Rule::Range(1.0, 254.0));
  v.Parameter("responsivity", "1/(lx.s)", &responsivity_,
              "8-bit image level per lux at the floor and second of exposure at gain 1",
              Rule::Positive());
  v.Parameter("shot_noise_gain", "1", &shot_noise_gain_,
              "8-bit levels per photo-electron at gain 1 (sets the shot noise)", Rule::Positive());
  v.Parameter("read_noise", "1", &read_noise_, "read noise at gain 1, 8-bit levels",
              Rule::NonNegative());
  v.Parameter("added_light", "lx", &added_light_,
              "illuminance the robot's own light adds at the floor under the sensor",
              Rule::NonNegative());
  v.Parameter("dark_from", "s", &dark_from_,
              "fault injection: from this time the surface gets no light at all (the hall's "
              "lights and the sensor's own off) ...",
              Rule::NonNegative());
  v.Parameter("dark_until", "s", &dark_until_,
              "... until this time (dark_until <= dark_from: never)", Rule::NonNegative());
  v.Parameter("sonar_noise", "m", &sonar_noise_, "standard deviation of the sonar distance",
              Rule::NonNegative());
  v.Parameter("sonar_min", "m", &sonar_min_, "shortest valid sonar distance", Rule::Positive());
  v.Parameter("sonar_max", "m", &sonar_max_, "longest valid sonar distance", Rule::Positive());
  v.Parameter("gyro_noise", "rad/s", &gyro_noise_,
              "standard deviation of each gyro axis per frame sample", Rule::NonNegative());
  v.Parameter("gyro_range", "rad/s", &gyro_range_, "gyro full scale (saturates beyond)",
              Rule::Positive());

  v.Input("position", "m", &position_, "base_link x, y in map");
  v.Input("yaw", "rad", &yaw_, "base_link yaw in map");
  v.Input("linear_velocity", "m/s", &linear_velocity_, "base_link vx, vy in map");
  v.Input("yaw_rate", "rad/s", &yaw_rate_, "base_link yaw rate");
  v.Input("angular_velocity", "rad/s", &angular_velocity_,
          "base_link angular velocity in base_link (the board gyro)");
  if (n_belts > 0) {
    v.Input("belt_velocity", "m/s", &belt_velocity_,
            "surface velocity of each scene belt in map: vx, vy per belt");
  }

  v.Output("integrated_x", "rad", &integrated_x_,
           "OPTICAL_FLOW_RAD integrated_x: sum of flow_y / f over the last message's frames of "
           "quality > 0 (rotation about the sensor x axis)",
           {});
  v.Output("integrated_y", "rad", &integrated_y_,
           "OPTICAL_FLOW_RAD integrated_y: minus the sum of flow_x / f", {});
  v.Output("integration_time", "s", &integration_time_,
           "OPTICAL_FLOW_RAD integration_time_us: frame intervals of the frames of quality > 0",
           {});
  v.Output("quality", "1", &quality_,
           "OPTICAL_FLOW_RAD quality: mean frame quality over frames of quality > 0 (0..255), 0 "
           "when none",
           {});
  v.Output("integrated_gyro", "rad", &integrated_gyro_,
           "OPTICAL_FLOW_RAD integrated_xgyro, ygyro, zgyro (sensor frame)", {});
  v.Output("distance", "m", &distance_,
           "OPTICAL_FLOW_RAD distance: sonar distance, -1 outside sonar_min..sonar_max", {});
  v.Output("frame_count", "1", &frame_count_, "frames of quality > 0 in the last message", {});
  v.Output("velocity", "m/s", &velocity_,
           "surface velocity relative to the sensor in the sensor frame, from the integrated "
           "flow and the known mount_height (paper 1); held when valid is 0",
           {});
  v.Output("valid", "1", &valid_, "1 if velocity is from the last message, 0 if held", {});
  v.Output("message_count", "1", &message_count_,
           "messages published so far (a new message: the count changed)", {});
  v.Output("frame_quality", "1", &frame_quality_, "quality of the last camera frame (0..255)", {});
  v.Output("frame_flow", "1", &frame_flow_,
           "flow of the last camera frame, x and y, pixels per frame (0 when quality is 0)", {});
}

std::vector<cosim::ParameterProblem> Px4FlowUnit::CheckParameters() const {
  auto problems = cosim::Unit::CheckParameters();
  if (sonar_min_ >= sonar_max_) {
    problems.push_back({"sonar_max", std::nullopt,
                        "must be greater than sonar_min (" + cosim::FormatValue(sonar_min_) + ")"});
  }
  if (publish_rate_ > frame_rate_) {
    problems.push_back({"publish_rate", std::nullopt,
                        "must not exceed frame_rate (" + cosim::FormatValue(frame_rate_) + ")"});
  }
  const auto n = static_cast<int>(surfaces_.size());
  if (floor_surface_ < 0 || floor_surface_ >= n) {
    problems.push_back({"scene.floor.surface", std::nullopt, "is not a surface index"});
  }
  for (std::size_t b = 0; b < belts_.size(); ++b) {
    if (belts_[b].surface < 0 || belts_[b].surface >= n) {
      problems.push_back({"scene.belts." + std::to_string(b) + ".surface", std::nullopt,
                          "is not a surface index"});
    }
  }
  return problems;
}

void Px4FlowUnit::CacheCamera() {
  cos_mount_ = std::cos(mount_yaw_);
  sin_mount_ = std::sin(mount_yaw_);
  cam_.focal_length_px = focal_length_px_;
  cam_.frame_rate_hz = frame_rate_;
  cam_.search_range_px = static_cast<int>(search_range_);
  cam_.feature_threshold = static_cast<int>(feature_threshold_);
  cam_.max_exposure_s = max_exposure_;
  cam_.max_gain = max_gain_;
  cam_.target_brightness_dn = target_brightness_;
  cam_.responsivity_dn = responsivity_;
  cam_.full_well_dn = shot_noise_gain_;
  cam_.read_noise_dn = read_noise_;
}

void Px4FlowUnit::Setup(cosim::TimeNs start, cosim::TimeNs) { start_ = start; }

void Px4FlowUnit::Initialize() {
  ThrowIfBadParameters();
  CacheCamera();
  // Its own texture and noise stream, from the unit's seed.
  image_ = mode_ == "image" ? std::make_unique<Px4FlowImageModel>(cam_, seed_ ^ kImageSeedSalt)
                            : nullptr;
  // The first frame at the start has no previous frame; frames then follow
  // at k / frame_rate, messages at m / publish_rate.
  frame_index_ = 1;
  publish_index_ = 1;
  next_frame_ = start_ + static_cast<cosim::TimeNs>(std::llround(1e9 / frame_rate_));
  next_publish_ = start_ + static_cast<cosim::TimeNs>(std::llround(1e9 / publish_rate_));
  acc_x_ = acc_y_ = 0.0;
  acc_gyro_[0] = acc_gyro_[1] = acc_gyro_[2] = 0.0;
  acc_count_ = acc_quality_ = 0;
  integrated_x_ = integrated_y_ = integration_time_ = quality_ = frame_count_ = 0.0;
  std::fill(integrated_gyro_.begin(), integrated_gyro_.end(), 0.0);
  std::fill(velocity_.begin(), velocity_.end(), 0.0);
  std::fill(frame_flow_.begin(), frame_flow_.end(), 0.0);
  valid_ = frame_quality_ = message_count_ = 0.0;
  distance_ = (mount_height_ >= sonar_min_ && mount_height_ <= sonar_max_) ? mount_height_ : -1.0;
}

void Px4FlowUnit::TrueFlow(double& fx, double& fy, int& surface) const {
  const double c = std::cos(yaw_), s = std::sin(yaw_);
  const double rx = c * mount_x_ - s * mount_y_, ry = s * mount_x_ + c * mount_y_;
  const double px = position_[0] + rx, py = position_[1] + ry;
  // Velocity of the sensor point in map: v + omega x r.
  const double vsx = linear_velocity_[0] - yaw_rate_ * ry;
  const double vsy = linear_velocity_[1] + yaw_rate_ * rx;
  double ux = 0.0, uy = 0.0;
  surface = floor_surface_;
  for (std::size_t b = 0; b < belts_.size(); ++b) {
    if (models::InsideRect(belts_[b].area, belts_[b].cos_dir, belts_[b].sin_dir, px, py)) {
      ux = belt_velocity_[2 * b];
      uy = belt_velocity_[2 * b + 1];
      surface = belts_[b].surface;
      break;
    }
  }
  const double rel_x = ux - vsx, rel_y = uy - vsy;
  // cos and sin of yaw + mount_yaw by the angle sum.
  const double ca = c * cos_mount_ - s * sin_mount_, sa = s * cos_mount_ + c * sin_mount_;
  const double scale = focal_length_px_ / (frame_rate_ * mount_height_);
  fx = (ca * rel_x + sa * rel_y) * scale;
  fy = (-sa * rel_x + ca * rel_y) * scale;
}

void Px4FlowUnit::Frame() {
  double fx = 0.0, fy = 0.0;
  int surface = 0;
  TrueFlow(fx, fy, surface);
  const models::Surface& surf = surfaces_[static_cast<std::size_t>(surface)];
  int q = 0;
  double flow_x = 0.0, flow_y = 0.0;
  if (image_) {
    // The surface's velocity relative to the sensor (m/s, sensor frame).
    const double to_mps = frame_rate_ * mount_height_ / focal_length_px_;
    const FlowResult r = image_->Step(fx * to_mps, fy * to_mps, mount_height_,
                                      surf.texture_contrast, Illuminance(surf));
    q = r.quality;
    flow_x = r.flow_x_px;
    flow_y = r.flow_y_px;
  } else {
    FastFrame(fx, fy, surf, q, flow_x, flow_y);
  }
  CommitFrame(q, flow_x, flow_y);
}

void Px4FlowUnit::FastFrame(double fx, double fy, const models::Surface& surf, int& q,
                            double& flow_x, double& flow_y) {
  const Exposure e = AutoExposure(cam_, Illuminance(surf));
  const double blur_px = std::sqrt(fx * fx + fy * fy) * e.exposure_s * frame_rate_;
  const double br = blur_px / kBlurScalePx;
  const double d = kNeighbourDiff * e.mean_dn * surf.texture_contrast *
                   std::sqrt(0.5 * (1.0 + 1.0 / (1.0 + br * br)));
  const double n2 = 2.0 * e.noise_dn * e.noise_dn + 1.0 / 6.0;
  const double n = std::sqrt(n2);
  const double snr = d / std::max(e.noise_dn, 1e-9);
  const double lost_ratio = kLostSnr / std::max(snr, 1e-9);
  const double p_true = 1.0 / (1.0 + lost_ratio * lost_ratio * lost_ratio);
  const double sigma_b = std::min(kMatchNoise / std::max(snr, 1e-9), kMatchNoiseMax);
  const double S = static_cast<double>(search_range_);
  const double thr = static_cast<double>(feature_threshold_);
  const double edge = S + 0.5;  // largest offset the search can report
  const double beyond = std::max({std::abs(fx) - edge, std::abs(fy) - edge, 0.0});
  const double bb = beyond / kAliasScalePx;
  const double p_edge = beyond > 0.0 ? std::exp(-bb * bb) : 1.0;

  double sum_x = 0.0, sum_y = 0.0;
  int used = 0;
  for (int k = 0; k < 25; ++k) {
    const double x = Gamma3(rng_());
    const double m =
        kDiffPerSigma * (std::sqrt(d * d * x + n2) + kNoiseSpread * n * IrwinHall4(rng_()));
    if (m < thr) continue;
    double ox, oy;
    const std::uint64_t r = rng_();
    const double u = U16(r, 48);
    if (u < p_true * p_edge) {
      // The true match (or, just beyond the window, its edge: the texture
      // is correlated over a few pixels), refined to half pixels.
      const double zx = sigma_b > 0.0 ? IrwinHall4(rng_()) : 0.0;
      const double zy = sigma_b > 0.0 ? IrwinHall4(rng_()) : 0.0;
      ox = std::clamp(RoundHalf(fx + sigma_b * zx), -edge, edge);
      oy = std::clamp(RoundHalf(fy + sigma_b * zy), -edge, edge);
    } else if (u < p_true) {
      // Aliased: the true match lies outside the window; the SAD minimum
      // is an unrelated patch anywhere in it (wrong, not flagged).
      const double cells = 4.0 * S + 3.0;
      ox = -edge + 0.5 * std::floor(U24(r, 0) * cells);
      oy = -edge + 0.5 * std::floor(U24(r, 24) * cells);
    } else {
      // A match on noise (dark or featureless image).
      const double cells = 4.0 * S - 1.0;
      ox = -(S - 0.5) + 0.5 * std::floor(U24(r, 0) * cells);
      oy = -(S - 0.5) + 0.5 * std::floor(U24(r, 24) * cells);
    }
    sum_x += ox;
    sum_y += oy;
    ++used;
  }
  if (used > 10) {
    q = used * 255 / 25;
    flow_x = sum_x / used;
    flow_y = sum_y / used;
  }
}

void Px4FlowUnit::CommitFrame(int q, double flow_x, double flow_y) {
  const double dt = 1.0 / frame_rate_;
  if (q > 0) {
    frame_quality_ = q;
    frame_flow_[0] = flow_x;
    frame_flow_[1] = flow_y;
    acc_x_ += flow_y / focal_length_px_;
    acc_y_ -= flow_x / focal_length_px_;
    // The board gyro, in the sensor frame (z down the optical axis is the
    // body z; the mount turns x, y by mount_yaw), saturating at its range.
    const double cm = cos_mount_, sm = sin_mount_;
    const double g[3] = {cm * angular_velocity_[0] + sm * angular_velocity_[1],
                         -sm * angular_velocity_[0] + cm * angular_velocity_[1],
                         angular_velocity_[2]};
    for (int i = 0; i < 3; ++i) {
      double r = g[i];
      if (gyro_noise_ > 0.0) r += gyro_noise_ * Normal(rng_);
      acc_gyro_[i] += std::clamp(r, -gyro_range_, gyro_range_) * dt;
    }
    ++acc_count_;
    acc_quality_ += q;
  } else {
    frame_quality_ = 0.0;
    frame_flow_[0] = frame_flow_[1] = 0.0;
  }
}

void Px4FlowUnit::Publish() {
  integrated_x_ = acc_x_;
  integrated_y_ = acc_y_;
  // Every counted frame adds one frame interval (main.c: deltatime since
  // the previous frame): count / frame_rate, exact.
  integration_time_ = static_cast<double>(acc_count_) / frame_rate_;
  frame_count_ = static_cast<double>(acc_count_);
  quality_ = acc_count_ > 0 ? static_cast<double>(acc_quality_ / acc_count_) : 0.0;
  for (int i = 0; i < 3; ++i) integrated_gyro_[static_cast<std::size_t>(i)] = acc_gyro_[i];
  double sonar = mount_height_;
  if (sonar_noise_ > 0.0) sonar += sonar_noise_ * Normal(rng_);
  distance_ = (sonar >= sonar_min_ && sonar <= sonar_max_) ? sonar : -1.0;
  if (acc_count_ > 0) {
    // Surface relative to the sensor: +flow / f / T * h; flow_x = -f * integrated_y.
    velocity_[0] = -acc_y_ / integration_time_ * mount_height_;
    velocity_[1] = acc_x_ / integration_time_ * mount_height_;
    valid_ = 1.0;
  } else {
    valid_ = 0.0;
  }
  acc_x_ = acc_y_ = 0.0;
  acc_gyro_[0] = acc_gyro_[1] = acc_gyro_[2] = 0.0;
  acc_count_ = acc_quality_ = 0;
  message_count_ += 1.0;
}

cosim::StepResult Px4FlowUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  const cosim::TimeNs t_end = t + dt;
  const double frame_ns = 1e9 / frame_rate_, publish_ns = 1e9 / publish_rate_;
  // Frames and messages inside (t, t_end], in time order (a frame at the
  // same time as a message goes into it).
  while (next_frame_ <= t_end || next_publish_ <= t_end) {
    if (next_frame_ <= next_publish_) {
      const double frame_s = cosim::NsToSeconds(next_frame_);
      dark_ = frame_s >= dark_from_ && frame_s < dark_until_;
      Frame();
      ++frame_index_;
      next_frame_ = start_ + static_cast<cosim::TimeNs>(
                                 std::llround(frame_ns * static_cast<double>(frame_index_)));
    } else {
      Publish();
      ++publish_index_;
      next_publish_ = start_ + static_cast<cosim::TimeNs>(
                                   std::llround(publish_ns * static_cast<double>(publish_index_)));
    }
  }
  return cosim::StepResult::kOk;
}

void Px4FlowUnit::SaveInternal(cosim::UnitState& state) const {
  if (image_) {
    throw cosim::UnitError(Where() +
                           ": mode image cannot save its state (the rendered texture "
                           "and the last image are not kept); use mode fast");
  }
  std::ostringstream rng;
  rng << rng_;
  state.strings = {rng.str()};
  state.reals = {acc_x_, acc_y_, acc_gyro_[0], acc_gyro_[1], acc_gyro_[2]};
  state.integers = {start_,         next_frame_, next_publish_, frame_index_,
                    publish_index_, acc_count_,  acc_quality_};
}

void Px4FlowUnit::RestoreInternal(const cosim::UnitState& state) {
  if (state.strings.size() != 1 || state.reals.size() != 5 || state.integers.size() != 7) {
    throw cosim::UnitError(Where() + ": saved state has the wrong shape");
  }
  std::istringstream rng_text(state.strings[0]);
  std::mt19937_64 rng;
  rng_text >> rng;
  if (!rng_text) throw cosim::UnitError(Where() + ": saved generator state is not readable");
  rng_ = rng;
  acc_x_ = state.reals[0];
  acc_y_ = state.reals[1];
  for (int i = 0; i < 3; ++i) acc_gyro_[i] = state.reals[static_cast<std::size_t>(2 + i)];
  start_ = state.integers[0];
  next_frame_ = state.integers[1];
  next_publish_ = state.integers[2];
  frame_index_ = state.integers[3];
  publish_index_ = state.integers[4];
  acc_count_ = state.integers[5];
  acc_quality_ = state.integers[6];
  CacheCamera();
}

}  // namespace linesim::sensors
