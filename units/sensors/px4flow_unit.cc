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
constexpr double kNoiseSpread = 0.2;       // relative spread of a noise-only measure
constexpr double kLostSnr = 0.18;          // snr at which half the blocks match noise
constexpr double kMatchNoise = 0.42;       // block offset std * snr (px)
constexpr double kMatchNoiseMax = 1.0;     // its limit at low snr (px)
constexpr double kAliasScalePx = 2.3;      // beyond the window: P(edge match) = exp(-(e/2.3)^2)
// Under a brightness step delta between the frames the whole-pixel match's
// margin is the SAD gap, about d^2 / (2 |delta|) per pixel (E|delta + t| -
// |delta| for a texture difference t of std d, |delta| >> d), against a
// spread of the wrong offsets' SADs set by the texture (std ~ d), not by
// the sensor's noise: a block's snr is bounded by kFlickerSnr (d /
// |delta|)^kFlickerPow (the margin argument gives the power 1; 1.25 is
// fitted), combined with its noise snr as 1 / snr^2 = 1 / snr_noise^2 +
// 1 / snr_step^2, with the block's own texture (d sqrt(X)): faint blocks
// go first. Fitted to the image-level reference's mean frame flow at
// 0.2 m/s under 120 Hz flicker of depth 0.1..0.3 over texture contrast
// 0.03..0.2, where its lost share depends on depth / contrast alone, as
// this law says (tests/units/sensors/px4flow_fast_vs_image_test.cc,
// FlickerAgrees).
constexpr double kFlickerSnr = 0.82;
constexpr double kFlickerPow = 1.25;
// A uniform disk of diameter c has the per-axis variance c^2 / 16, a box of
// length b b^2 / 12: the box of the same variance is c sqrt(12 / 16) long.
constexpr double kDiskToBox = 0.8660254037844386;

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

// ... and a Gamma(3, 1/3) variable (mean 1; the shape 3 is the fitted one
// of the block-to-block texture variance): the mean of three unit
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

// E|mu + s Z| for a standard normal Z (the folded normal's mean): the mean
// absolute difference a pixel adds to the SAD when the two frames differ by
// a brightness step mu and a zero-mean difference of std s.
inline double FoldedMean(double mu, double s) {
  constexpr double kSqrt2OverPi = 0.7978845608028654;
  if (s <= 0.0) return std::abs(mu);
  const double r = mu / s;
  return s * kSqrt2OverPi * std::exp(-0.5 * r * r) + mu * std::erf(r * 0.7071067811865476);
}

// Salts keeping the per-device and per-run draws apart from the frame stream.
constexpr std::uint64_t kDeviceSalt = 0xd1b54a32d192ed03ULL;
constexpr std::uint64_t kSonarSalt = 0x8bb84b93962eacc9ULL;
constexpr std::uint64_t kResidualSalt = 0x4f1bbcdcbfa53e0bULL;

}  // namespace

Px4FlowUnit::Px4FlowUnit(std::string name, const models::Scene& scene, std::uint64_t seed)
    : cosim::Unit(kTypeName, std::move(name)),
      surfaces_(scene.surfaces),
      seed_(seed),
      rng_(seed),
      sonar_rng_(seed ^ kSonarSalt),
      residual_rng_(seed ^ kResidualSalt) {
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
  sonar_velocity_.assign(2, 0.0);

  DeclareParameters();
  DeclareInputsAndOutputs(n_belts > 0);
}

void Px4FlowUnit::DeclareParameters() {
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
  v.Parameter("sonar_noise", "m", &sonar_noise_,
              "standard deviation of a sonar reading (before its rounding)", Rule::NonNegative());
  v.Parameter("sonar_min", "m", &sonar_min_,
              "the firmware keeps readings above this and flags a filtered distance below it "
              "invalid (sonar.c SONAR_MIN)",
              Rule::Positive());
  v.Parameter("sonar_max", "m", &sonar_max_, "... and below this (SONAR_MAX)", Rule::Positive());
  v.Parameter("sonar_min_range", "m", &sonar_min_range_,
              "the sonar reports anything closer as this distance (HRLV-MaxSonar-EZ: 300 mm)",
              Rule::NonNegative());
  v.Parameter("sonar_resolution", "m", &sonar_resolution_,
              "the sonar's reading is a whole number of these (0: exact)", Rule::NonNegative());
  v.Parameter("sonar_period", "s", &sonar_period_, "time between sonar readings",
              Rule::Range(1e-3, 10.0));
  v.Parameter("sonar_gain_position", "1", &sonar_gain_position_,
              "the firmware's sonar filter: position gain (SONAR_KAL_L1)", Rule::Range(0.0, 1.0));
  v.Parameter("sonar_gain_velocity", "1/s", &sonar_gain_velocity_,
              "... velocity gain (SONAR_KAL_L2)", Rule::NonNegative());
  v.Parameter("sonar_filtered", &sonar_filtered_,
              "OPTICAL_FLOW's ground_distance is the filtered sonar distance (SONAR_FILTERED; "
              "default: the raw reading)");
  v.Parameter("velocity_scaling", &velocity_scaling_,
              "the distance `velocity` scales the flow with: fixed_height (mount_height, paper 1) "
              "or sonar (the firmware's flow_comp_m, the filtered sonar distance)",
              Rule::OneOf({"fixed_height", "sonar"}));
  v.Parameter("f_number", "1", &f_number_, "the lens' f-number (its aperture is f / N)",
              Rule::Range(0.5, 64.0));
  v.Parameter("focus_distance", "m", &focus_distance_,
              "the distance the lens is focused at (0: at mount_height; a large value: far away)",
              Rule::NonNegative());
  v.Parameter("pixel_pitch", "m", &pixel_pitch_,
              "the binned pixel's size on the sensor (6 um x 4 binning)", Rule::Positive());
  v.Parameter("residual", &residual_,
              "add the unexplained residual (residual_flow_noise) to each message (off: the "
              "modelled mechanisms alone)");
  v.Parameter("residual_flow_noise", "rad/s", &residual_flow_noise_,
              "UNEXPLAINED RESIDUAL: standard deviation per message and axis of white noise on "
              "the message's flow rate, calibrated to the device's measured noise (see "
              "models/sensors/px4flow.yaml); no mechanism of its own",
              Rule::NonNegative());
  v.Parameter("gyro_noise", "rad/s", &gyro_noise_,
              "standard deviation of each gyro axis per frame sample", Rule::NonNegative());
  v.Parameter("gyro_range", "rad/s", &gyro_range_, "gyro full scale (saturates beyond)",
              Rule::Positive());
  v.Parameter("gyro_compensation", &gyro_compensation_,
              "firmware subtracts the board gyro's rotation from each frame's flow before "
              "`velocity` (paper 1 Sec. IV-A: on); integrated_x/y stay uncompensated");
  v.Parameter("gyro_bias", "rad/s", &gyro_bias_,
              "standard deviation of each gyro axis' constant bias, drawn once per device from "
              "the seed",
              Rule::NonNegative());
  v.Parameter("gyro_lag", "s", &gyro_lag_,
              "time constant of the gyro's low-pass and read delay against the image",
              Rule::Range(0.0, 1.0));
  v.Parameter("scale_error", "1", &scale_error_,
              "standard deviation of the device's focal length over its nominal, drawn once per "
              "device from the seed (what a calibration leaves)",
              Rule::Range(0.0, 0.5));
  v.Parameter("pitch_per_acceleration", "rad.s^2/m", &pitch_per_acceleration_,
              "static body pitch on the tyres per m/s^2 of forward acceleration (nose up)",
              Rule::NonNegative());
  v.Parameter("roll_per_acceleration", "rad.s^2/m", &roll_per_acceleration_,
              "static body roll on the tyres per m/s^2 of leftward acceleration",
              Rule::NonNegative());
  v.Parameter("tyre_mode_frequency", "Hz", &tyre_mode_frequency_,
              "natural frequency of the body's pitch and roll on its tyres",
              Rule::Range(0.1, 200.0));
  v.Parameter("tyre_mode_damping", "1", &tyre_mode_damping_, "damping ratio of that mode",
              Rule::Range(0.0, 10.0));
  v.Parameter("wheelbase", "m", &wheelbase_,
              "distance between front and rear wheel contacts (pitch from the surface profile)",
              Rule::Positive());
  v.Parameter("track", "m", &track_,
              "distance between left and right wheel contacts (roll from the surface profile)",
              Rule::Positive());
  v.Parameter("rotation_flow", &rotation_,
              "the chassis' roll and pitch rates (angular_velocity x, y) turn the sensor: its "
              "image and its gyro (off: they are ignored)");
  v.Parameter("shake", &shake_,
              "the wheels rolling over the surface's roughness shake the body (scene surface "
              "roughness_m)");
  v.Parameter("flicker", &flicker_,
              "the ambient light flickers (scene surface flicker_hz, flicker_depth)");
  v.Parameter("periodic_texture", &periodic_texture_,
              "the surface's periodic texture can alias (scene surface texture_period_m)");
}

void Px4FlowUnit::DeclareInputsAndOutputs(bool belts) {
  auto& v = variables();
  v.Input("position", "m", &position_, "base_link x, y in map");
  v.Input("yaw", "rad", &yaw_, "base_link yaw in map");
  v.Input("linear_velocity", "m/s", &linear_velocity_, "base_link vx, vy in map");
  v.Input("yaw_rate", "rad/s", &yaw_rate_, "base_link yaw rate");
  v.Input("angular_velocity", "rad/s", &angular_velocity_,
          "base_link angular velocity in base_link (the board gyro)");
  if (belts) {
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
           "OPTICAL_FLOW ground_distance: the sonar's raw reading (filtered with "
           "sonar_filtered), 0 while the filtered distance is outside sonar_min..sonar_max",
           {});
  v.Output("sonar_velocity", "m/s", &sonar_velocity_,
           "OPTICAL_FLOW flow_comp_m (turned to the surface relative to the sensor, as "
           "`velocity`): the message's frames' flow scaled by the filtered sonar distance; 0 "
           "without a frame of quality > 0 and a valid distance",
           {});
  v.Output("defocus", "1", &defocus_,
           "diameter of the lens' blur circle on the sensor at the last frame, binned pixels", {});
  v.Output("frame_count", "1", &frame_count_, "frames of quality > 0 in the last message", {});
  v.Output("velocity", "m/s", &velocity_,
           "surface velocity relative to the sensor in the sensor frame, from the integrated "
           "flow and the distance velocity_scaling says (paper 1: the known mount_height); held "
           "when valid is 0",
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
  // The thin lens: the lens' focal length is focal_length_px pixels.
  const double focal_m = focal_length_px_ * pixel_pitch_;
  if (mount_height_ <= 2.0 * focal_m) {
    problems.push_back({"mount_height", std::nullopt,
                        "must be more than twice the focal length (" + cosim::FormatValue(focal_m) +
                            " m: focal_length_px x pixel_pitch)"});
  }
  if (focus_distance_ > 0.0 && focus_distance_ <= 2.0 * focal_m) {
    problems.push_back({"focus_distance", std::nullopt,
                        "must be 0 (at mount_height) or more than twice the focal length (" +
                            cosim::FormatValue(focal_m) + " m)"});
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
  // The gyro's first-order lag per frame interval.
  gyro_lag_factor_ = gyro_lag_ > 0.0 ? 1.0 - std::exp(-1.0 / (frame_rate_ * gyro_lag_)) : 1.0;
  scale_by_sonar_ = velocity_scaling_ == "sonar";
}

double Px4FlowUnit::DefocusPx(double height) const {
  // Thin lens of this device's focal length f: a floor at s is imaged at
  // v_s = f s / (s - f); focused at s_f the sensor sits at v_f, and a point
  // of the floor at `height` spreads over a disk of diameter A |v_h - v_f|
  // / v_h there (A = f / N, the aperture).
  const double f = focal_length_px_ * focal_factor_ * pixel_pitch_;
  const double s_f = focus_distance_ > 0.0 ? focus_distance_ : mount_height_;
  const double h = std::max(height, 2.0 * f);
  const double v_h = f * h / (h - f), v_f = f * s_f / (s_f - f);
  return f / f_number_ * std::abs(v_h - v_f) / v_h / pixel_pitch_;
}

void Px4FlowUnit::SonarUpTo(cosim::TimeNs t, double height) {
  const double period_ns = 1e9 * sonar_period_;
  while (next_sonar_ <= t) {
    SonarReading(cosim::NsToSeconds(next_sonar_), height, false);
    ++sonar_index_;
    next_sonar_ = start_ + static_cast<cosim::TimeNs>(
                               std::llround(period_ns * static_cast<double>(sonar_index_)));
  }
}

void Px4FlowUnit::SonarReading(double t_s, double height, bool settle) {
  // The HRLV-MaxSonar-EZ: closer than its minimum it reports the minimum;
  // its serial output is whole millimetres.
  double r = std::max(height, sonar_min_range_);
  if (sonar_noise_ > 0.0) r += sonar_noise_ * Normal(sonar_rng_);
  if (sonar_resolution_ > 0.0) r = sonar_resolution_ * std::nearbyint(r / sonar_resolution_);
  // sonar.c: a reading inside (SONAR_MIN, SONAR_MAX) enters the filter
  // (sonar_filter: note that the position is predicted with the velocity
  // of the update before last, v_pred, as the firmware does); outside,
  // the distance is invalid until the next one.
  if (r > sonar_min_ && r < sonar_max_) {
    if (settle) {
      // The device has run before the start: its filter sits on the reading.
      sonar_x_ = r;
      sonar_v_ = sonar_v_pred_ = 0.0;
    } else {
      const double dt = t_s - sonar_last_t_;
      if (dt > 0.25) sonar_v_pred_ = 0.0;  // "more than 2 values lost"
      const double x_pred = sonar_x_ + dt * sonar_v_pred_;
      sonar_v_pred_ = sonar_v_;
      const double innovation = r - x_pred;
      sonar_x_ = x_pred + sonar_gain_position_ * innovation;
      sonar_v_ = sonar_v_pred_ + sonar_gain_velocity_ * innovation;
    }
    sonar_last_t_ = t_s;
    sonar_raw_ = r;
    sonar_valid_ = true;
  } else {
    sonar_valid_ = false;
  }
  // sonar_read: a filtered distance out of the band is not valid either.
  if (sonar_x_ < sonar_min_ || sonar_x_ > sonar_max_) sonar_valid_ = false;
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
  acc_x_ = acc_y_ = comp_x_ = comp_y_ = sonar_comp_x_ = sonar_comp_y_ = 0.0;
  acc_gyro_[0] = acc_gyro_[1] = acc_gyro_[2] = 0.0;
  acc_count_ = acc_quality_ = sonar_frames_ = 0;
  // The device's own errors, from its seed (not the frame stream, so that a
  // parameter set to 0 leaves the other draws as they were): its lens'
  // focal length and its gyro's bias; and the mains phase of this run.
  std::mt19937_64 device(seed_ ^ kDeviceSalt);
  focal_factor_ = 1.0 + scale_error_ * Normal(device);
  for (double& b : bias_) b = gyro_bias_ * Normal(device);
  flicker_phase_ = 2.0 * std::numbers::pi * Uniform(device);
  for (double& c : contact_) c = 0.0;
  tyre_pitch_ = tyre_pitch_rate_ = tyre_roll_ = tyre_roll_rate_ = 0.0;
  last_pitch_ = last_roll_ = 0.0;
  for (double& g : gyro_lagged_) g = 0.0;
  accel_x_ = accel_y_ = last_vx_ = last_vy_ = 0.0;
  have_last_velocity_ = false;
  rot_x_ = rot_y_ = 0.0;
  height_ = mount_height_;
  brightness_ = last_brightness_ = 1.0;
  integrated_x_ = integrated_y_ = integration_time_ = quality_ = frame_count_ = 0.0;
  std::fill(integrated_gyro_.begin(), integrated_gyro_.end(), 0.0);
  std::fill(velocity_.begin(), velocity_.end(), 0.0);
  std::fill(frame_flow_.begin(), frame_flow_.end(), 0.0);
  std::fill(sonar_velocity_.begin(), sonar_velocity_.end(), 0.0);
  valid_ = frame_quality_ = message_count_ = 0.0;
  defocus_ = DefocusPx(mount_height_);
  // The sonar: its first reading at the start (the filter settled on it),
  // then one every sonar_period.
  sonar_valid_ = false;
  sonar_x_ = sonar_v_ = sonar_v_pred_ = sonar_raw_ = 0.0;
  sonar_last_t_ = cosim::NsToSeconds(start_);
  SonarReading(sonar_last_t_, mount_height_, true);
  sonar_index_ = 1;
  next_sonar_ = start_ + static_cast<cosim::TimeNs>(std::llround(1e9 * sonar_period_));
  distance_ = sonar_valid_ ? (sonar_filtered_ ? sonar_x_ : sonar_raw_) : 0.0;
}

void Px4FlowUnit::TrueFlow(double& fx, double& fy, int& surface) const {
  double dc = 1.0, ds = 0.0;
  TrueFlowAndDirection(fx, fy, surface, dc, ds);
}

void Px4FlowUnit::TrueFlowAndDirection(double& fx, double& fy, int& surface, double& dir_c,
                                       double& dir_s) const {
  const double c = std::cos(yaw_), s = std::sin(yaw_);
  const double rx = c * mount_x_ - s * mount_y_, ry = s * mount_x_ + c * mount_y_;
  const double px = position_[0] + rx, py = position_[1] + ry;
  // Velocity of the sensor point in map: v + omega x r.
  const double vsx = linear_velocity_[0] - yaw_rate_ * ry;
  const double vsy = linear_velocity_[1] + yaw_rate_ * rx;
  double ux = 0.0, uy = 0.0, mc = 1.0, ms = 0.0;
  surface = floor_surface_;
  for (std::size_t b = 0; b < belts_.size(); ++b) {
    if (models::InsideRect(belts_[b].area, belts_[b].cos_dir, belts_[b].sin_dir, px, py)) {
      ux = belt_velocity_[2 * b];
      uy = belt_velocity_[2 * b + 1];
      surface = belts_[b].surface;
      mc = belts_[b].cos_dir;
      ms = belts_[b].sin_dir;
      break;
    }
  }
  const double rel_x = ux - vsx, rel_y = uy - vsy;
  // cos and sin of yaw + mount_yaw by the angle sum.
  const double ca = c * cos_mount_ - s * sin_mount_, sa = s * cos_mount_ + c * sin_mount_;
  dir_c = ca * mc + sa * ms;
  dir_s = -sa * mc + ca * ms;
  const double scale = focal_length_px_ / (frame_rate_ * mount_height_);
  fx = (ca * rel_x + sa * rel_y) * scale;
  fy = (-sa * rel_x + ca * rel_y) * scale;
}

double Px4FlowUnit::Brightness(const models::Surface& surf, double t, double exposure_s) const {
  if (!flicker_ || surf.flicker_depth <= 0.0 || surf.flicker_hz <= 0.0 || dark_) return 1.0;
  const double total = surf.illumination_lux + added_light_;
  if (total <= 0.0) return 1.0;
  // Mean of sin(2 pi f tau + phase) over the exposure [t - T, t].
  const double w = 2.0 * std::numbers::pi * surf.flicker_hz;
  const double mean_sin =
      (std::cos(w * (t - exposure_s) + flicker_phase_) - std::cos(w * t + flicker_phase_)) /
      (w * exposure_s);
  return 1.0 + surf.flicker_depth * surf.illumination_lux / total * mean_sin;
}

void Px4FlowUnit::BodyMotion(double rel_speed, const models::Surface& surf) {
  const double dt = 1.0 / frame_rate_;
  // The surface's profile under the four wheels, advanced by the distance
  // the wheels roll over it in this frame (a first-order Gauss-Markov
  // process in distance: correlation length roughness_length_m).
  double pitch = 0.0, roll = 0.0, heave = 0.0;
  if (shake_ && surf.roughness_m > 0.0) {
    const double a = std::exp(-rel_speed * dt / surf.roughness_length_m);
    const double b = std::sqrt(std::max(0.0, 1.0 - a * a)) * surf.roughness_m;
    if (b > 0.0) {
      for (double& c : contact_) c = a * c + b * IrwinHall4(rng_());
    }
    const double front = 0.5 * (contact_[0] + contact_[1]),
                 rear = 0.5 * (contact_[2] + contact_[3]);
    const double left = 0.5 * (contact_[0] + contact_[2]),
                 right = 0.5 * (contact_[1] + contact_[3]);
    pitch = -(front - rear) / wheelbase_;  // + nose down (about base_link y)
    roll = (left - right) / track_;        // + left side up (about base_link x)
    heave = 0.25 * (contact_[0] + contact_[1] + contact_[2] + contact_[3]);
  }
  // The body on its tyres: a second-order mode driven by the acceleration
  // (semi-implicit Euler at the frame rate; stable for w dt < 2).
  if (pitch_per_acceleration_ > 0.0 || roll_per_acceleration_ > 0.0) {
    const double wn = 2.0 * std::numbers::pi * tyre_mode_frequency_;
    const double target_pitch = -pitch_per_acceleration_ * accel_x_;
    const double target_roll = roll_per_acceleration_ * accel_y_;
    tyre_pitch_rate_ += dt * (wn * wn * (target_pitch - tyre_pitch_) -
                              2.0 * tyre_mode_damping_ * wn * tyre_pitch_rate_);
    tyre_pitch_ += dt * tyre_pitch_rate_;
    tyre_roll_rate_ += dt * (wn * wn * (target_roll - tyre_roll_) -
                             2.0 * tyre_mode_damping_ * wn * tyre_roll_rate_);
    tyre_roll_ += dt * tyre_roll_rate_;
    pitch += tyre_pitch_;
    roll += tyre_roll_;
  }
  // The body's rotation over this frame (base_link): the chassis' rates and
  // the change of the angles above.
  double bx = roll - last_roll_, by = pitch - last_pitch_;
  last_roll_ = roll;
  last_pitch_ = pitch;
  if (rotation_) {
    bx += angular_velocity_[0] * dt;
    by += angular_velocity_[1] * dt;
  }
  rot_x_ = cos_mount_ * bx + sin_mount_ * by;
  rot_y_ = -sin_mount_ * bx + cos_mount_ * by;
  // The lens' height over the surface: pitch lowers the front, roll raises the left.
  height_ = mount_height_ + heave - pitch * mount_x_ + roll * mount_y_;
}

void Px4FlowUnit::Frame(cosim::TimeNs t) {
  const double t_s = cosim::NsToSeconds(t);
  double fx = 0.0, fy = 0.0, dir_c = 1.0, dir_s = 0.0;
  int surface = 0;
  TrueFlowAndDirection(fx, fy, surface, dir_c, dir_s);
  const models::Surface& surf = surfaces_[static_cast<std::size_t>(surface)];
  const double to_mps = frame_rate_ * mount_height_ / focal_length_px_;
  BodyMotion(std::hypot(fx, fy) * to_mps, surf);
  defocus_ = DefocusPx(height_);
  // main.c reads the sonar once per frame (sonar_read).
  SonarUpTo(t, height_);
  // The image moves by the translation at the real height, seen through
  // this device's lens, plus the rotation (rad) times its focal length.
  const double f_true = focal_length_px_ * focal_factor_;
  const double k = focal_factor_ * mount_height_ / std::max(height_, 1e-3);
  fx *= k;
  fy *= k;
  fx += rot_y_ * f_true;
  fy -= rot_x_ * f_true;
  // A periodic texture's period in the image (px, sensor frame).
  periodic_share_ =
      periodic_texture_ && surf.texture_period_m > 0.0 ? surf.texture_periodic_share : 0.0;
  const double period_px = surf.texture_period_m * f_true / std::max(height_, 1e-3);
  period_px_x_ = period_px * dir_c;
  period_px_y_ = period_px * dir_s;
  const Exposure exposure = AutoExposure(cam_, Illuminance(surf));
  last_brightness_ = brightness_;
  brightness_ = Brightness(surf, t_s, exposure.exposure_s);
  if (frame_index_ == 1) last_brightness_ = brightness_;
  int q = 0;
  double flow_x = 0.0, flow_y = 0.0;
  if (image_) {
    // The image model renders the displacement (fx, fy) px at mount_height.
    image_->SetPeriodicTexture(
        surf.texture_period_m * mount_height_ / std::max(height_, 1e-3) * focal_factor_, dir_c,
        dir_s, periodic_share_);
    const FlowResult r =
        image_->Step(fx * to_mps, fy * to_mps, mount_height_, surf.texture_contrast,
                     Illuminance(surf), brightness_, defocus_);
    q = r.quality;
    flow_x = r.flow_x_px;
    flow_y = r.flow_y_px;
  } else {
    FastFrame(fx, fy, surf, exposure, q, flow_x, flow_y);
  }
  CommitFrame(q, flow_x, flow_y);
}

void Px4FlowUnit::FastFrame(double fx, double fy, const models::Surface& surf, const Exposure& e,
                            int& q, double& flow_x, double& flow_y) {
  const double blur_px = std::sqrt(fx * fx + fy * fy) * e.exposure_s * frame_rate_;
  const double br = blur_px / kBlurScalePx;
  // Defocus: its disk as the box of the same variance on both axes, along
  // the motion added in quadrature to the motion blur.
  double along, across = 1.0;
  if (defocus_ > 0.0) {
    const double bd = kDiskToBox * defocus_ / kBlurScalePx;
    along = 1.0 / (1.0 + br * br + bd * bd);
    across = 1.0 / (1.0 + bd * bd);
  } else {
    along = 1.0 / (1.0 + br * br);
  }
  // The blur keeps the texture across the motion and smooths it along: the
  // texture measure (compute_diff, both axes' differences) keeps
  // sqrt((1 + along) / 2) of it, along = 1 / (1 + (blur / 1.8)^2) the
  // along-motion part's share; the match, which must also place the block
  // along the motion, sees the geometric mean of that and sqrt(along)
  // (fitted to the image-level reference's mean frame flow at long
  // exposures: tests/units/sensors/px4flow_fast_vs_image_test.cc).
  const double texture_blur = std::sqrt(0.5 * (across + along));
  const double d = kNeighbourDiff * e.mean_dn * surf.texture_contrast * texture_blur;
  const double n2 = 2.0 * e.noise_dn * e.noise_dn + 1.0 / 6.0;
  const double n = std::sqrt(n2);
  double snr = d / std::max(e.noise_dn, 1e-9) * std::sqrt(std::sqrt(along) / texture_blur);
  double snr_sub = snr;  // the half-pixel refinement's
  // A brightness step between the frames (a flickering lamp): the whole-
  // pixel match per block (kFlickerSnr, at the top); the half-pixel refinement
  // by the SAD gap at its neighbours: the mean SAD per pixel at the true
  // offset is E|delta + n| (n the two frames' noise, std sqrt(n2)), at a
  // neighbour E|delta + t| (t adds the texture difference, std d / 2
  // there); the step shrinks their gap.
  const bool step = brightness_ != last_brightness_;
  const double delta = e.mean_dn * (brightness_ - last_brightness_);
  if (step) {
    const double s_half = std::sqrt(0.25 * d * d + n2);
    // Without a step the gap is sqrt(2 / pi) (s_half - n) (FoldedMean at 0).
    const double gap0_half = 0.7978845608028654 * (s_half - n);
    if (gap0_half > 0.0) {
      snr_sub *= (FoldedMean(delta, s_half) - FoldedMean(delta, n)) / gap0_half;
    }
  }
  // The match's snr with the step's bound for a block of texture d sqrt(x)
  // (x: its Gamma draw): 1 / bound^2 = 1 / (kFlickerSnr (d / delta)^1.25)^2
  // / x^1.25, the frame's part once (a pow per frame, not per block).
  const double inv_snr2 = 1.0 / (std::max(snr, 1e-9) * std::max(snr, 1e-9));
  const double inv_frame_bound2 =
      step && delta != 0.0
          ? 1.0 / (kFlickerSnr * kFlickerSnr * std::pow(d / std::abs(delta), 2.0 * kFlickerPow))
          : 0.0;
  const auto step_snr = [&](double x) {
    static_assert(kFlickerPow == 1.25, "x^(2 kFlickerPow) below is x sqrt(sqrt(x))");
    return 1.0 / std::sqrt(inv_snr2 + inv_frame_bound2 / (x * std::sqrt(std::sqrt(x))));
  };
  const auto p_match = [](double block_snr) {
    const double lost_ratio = kLostSnr / std::max(block_snr, 1e-9);
    return 1.0 / (1.0 + lost_ratio * lost_ratio * lost_ratio);
  };
  const double p_frame = p_match(snr);
  const double sigma_b = std::min(kMatchNoise / std::max(snr_sub, 1e-9), kMatchNoiseMax);
  const double S = static_cast<double>(search_range_);
  const double thr = static_cast<double>(feature_threshold_);
  const double edge = S + 0.5;  // largest offset the search can report
  const double beyond = std::max({std::abs(fx) - edge, std::abs(fy) - edge, 0.0});
  const double bb = beyond / kAliasScalePx;
  const double p_edge = beyond > 0.0 ? std::exp(-bb * bb) : 1.0;
  // A periodic texture: the match one period off ties with the true one
  // unless the aperiodic part (variance share 1 - s) tells them apart; it
  // does as a block tells its true match from noise (the same lost-snr law).
  double p_alias = 0.0;
  bool alias_minus = false, alias_plus = false;
  if (periodic_share_ > 0.0) {
    const double snr_ap = (step ? step_snr(1.0) : snr) * std::sqrt(1.0 - periodic_share_);
    const double ratio = snr_ap / kLostSnr;
    p_alias = 0.5 / (1.0 + ratio * ratio * ratio);
    alias_minus = std::abs(fx - period_px_x_) <= edge && std::abs(fy - period_px_y_) <= edge;
    alias_plus = std::abs(fx + period_px_x_) <= edge && std::abs(fy + period_px_y_) <= edge;
    if (!alias_minus && !alias_plus) p_alias = 0.0;
  }

  double sum_x = 0.0, sum_y = 0.0;
  int used = 0;
  for (int k = 0; k < 25; ++k) {
    const double x = Gamma3(rng_());
    const double m =
        kDiffPerSigma * (std::sqrt(d * d * x + n2) + kNoiseSpread * n * IrwinHall4(rng_()));
    if (m < thr) continue;
    double ox, oy;
    const double p_true = step ? p_match(step_snr(x)) : p_frame;
    const std::uint64_t r = rng_();
    const double u = U16(r, 48);
    if (u < p_true * p_edge) {
      // The true match (or, just beyond the window, its edge: the texture
      // is correlated over a few pixels), refined to half pixels.
      const double zx = sigma_b > 0.0 ? IrwinHall4(rng_()) : 0.0;
      const double zy = sigma_b > 0.0 ? IrwinHall4(rng_()) : 0.0;
      double tx = fx, ty = fy;
      if (p_alias > 0.0 && U16(r, 0) < p_alias) {
        // One period off: x - p or x + p, whichever the window holds.
        const bool minus = alias_minus && (!alias_plus || (r & 0x10000) != 0);
        tx += minus ? -period_px_x_ : period_px_x_;
        ty += minus ? -period_px_y_ : period_px_y_;
      }
      ox = std::clamp(RoundHalf(tx + sigma_b * zx), -edge, edge);
      oy = std::clamp(RoundHalf(ty + sigma_b * zy), -edge, edge);
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
  // The board gyro (sensor frame; z down the optical axis is the body z):
  // the rotation of this frame as a rate, through its low-pass and read
  // delay, plus its bias and noise, saturating at its range.
  const double g_true[3] = {rot_x_ / dt, rot_y_ / dt, angular_velocity_[2]};
  double g[3];
  // The noise of the three axes from one draw each (a sum of four uniforms:
  // zero mean, unit variance, close to normal; cheap at 400 frames/s).
  for (int i = 0; i < 3; ++i) {
    gyro_lagged_[i] += gyro_lag_factor_ * (g_true[i] - gyro_lagged_[i]);
    double r = gyro_lagged_[i] + bias_[i];
    if (gyro_noise_ > 0.0) r += gyro_noise_ * IrwinHall4(rng_());
    g[i] = std::clamp(r, -gyro_range_, gyro_range_);
  }
  if (q > 0) {
    frame_quality_ = q;
    frame_flow_[0] = flow_x;
    frame_flow_[1] = flow_y;
    acc_x_ += flow_y / focal_length_px_;
    acc_y_ -= flow_x / focal_length_px_;
    // The firmware's compensation: minus the gyro's rotation in pixels
    // (nominal focal length), the inverse of the rotation flow.
    double cx = flow_x, cy = flow_y;
    if (gyro_compensation_) {
      cx = flow_x - g[1] * dt * focal_length_px_;
      cy = flow_y + g[0] * dt * focal_length_px_;
    }
    comp_x_ += cx;
    comp_y_ += cy;
    // flow_comp_m: each frame's flow times the filtered sonar distance,
    // over the frames with a valid distance.
    if (sonar_valid_) {
      sonar_comp_x_ += cx * sonar_x_;
      sonar_comp_y_ += cy * sonar_x_;
      ++sonar_frames_;
    }
    for (int i = 0; i < 3; ++i) acc_gyro_[i] += g[i] * dt;
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
  distance_ = sonar_valid_ ? (sonar_filtered_ ? sonar_x_ : sonar_raw_) : 0.0;
  // The unexplained residual: a flow rate (rad/s) per axis over the
  // message, as if the frames' flow had carried it.
  double nx = 0.0, ny = 0.0;
  if (residual_ && residual_flow_noise_ > 0.0) {
    nx = residual_flow_noise_ * Normal(residual_rng_);
    ny = residual_flow_noise_ * Normal(residual_rng_);
    integrated_x_ += ny * integration_time_;
    integrated_y_ -= nx * integration_time_;
  }
  // flow_comp_m: surface relative to the sensor, +flow / f / dt * distance
  // averaged over the frames (0 without one).
  if (sonar_frames_ > 0) {
    const double per_frame = frame_rate_ / (focal_length_px_ * static_cast<double>(sonar_frames_));
    sonar_velocity_[0] = sonar_comp_x_ * per_frame + nx * sonar_x_;
    sonar_velocity_[1] = sonar_comp_y_ * per_frame + ny * sonar_x_;
  } else {
    sonar_velocity_[0] = sonar_velocity_[1] = 0.0;
  }
  if (acc_count_ > 0) {
    if (scale_by_sonar_) {
      velocity_ = sonar_velocity_;
    } else {
      // Surface relative to the sensor: +flow / f / T * h (the gyro-
      // compensated flow when the firmware compensates).
      velocity_[0] =
          comp_x_ / focal_length_px_ / integration_time_ * mount_height_ + nx * mount_height_;
      velocity_[1] =
          comp_y_ / focal_length_px_ / integration_time_ * mount_height_ + ny * mount_height_;
    }
    valid_ = 1.0;
  } else {
    valid_ = 0.0;
  }
  acc_x_ = acc_y_ = comp_x_ = comp_y_ = sonar_comp_x_ = sonar_comp_y_ = 0.0;
  acc_gyro_[0] = acc_gyro_[1] = acc_gyro_[2] = 0.0;
  acc_count_ = acc_quality_ = sonar_frames_ = 0;
  message_count_ += 1.0;
}

cosim::StepResult Px4FlowUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  const cosim::TimeNs t_end = t + dt;
  const double frame_ns = 1e9 / frame_rate_, publish_ns = 1e9 / publish_rate_;
  // The body's acceleration in base_link over this step (the tyre mode's input).
  {
    const double c = std::cos(yaw_), s = std::sin(yaw_);
    const double vx = c * linear_velocity_[0] + s * linear_velocity_[1];
    const double vy = -s * linear_velocity_[0] + c * linear_velocity_[1];
    const double step_s = cosim::NsToSeconds(dt);
    if (have_last_velocity_ && step_s > 0.0) {
      accel_x_ = (vx - last_vx_) / step_s;
      accel_y_ = (vy - last_vy_) / step_s;
    }
    last_vx_ = vx;
    last_vy_ = vy;
    have_last_velocity_ = true;
  }
  // Frames and messages inside (t, t_end], in time order (a frame at the
  // same time as a message goes into it).
  while (next_frame_ <= t_end || next_publish_ <= t_end) {
    if (next_frame_ <= next_publish_) {
      const double frame_s = cosim::NsToSeconds(next_frame_);
      dark_ = frame_s >= dark_from_ && frame_s < dark_until_;
      Frame(next_frame_);
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
  std::ostringstream rng, sonar_rng, residual_rng;
  rng << rng_;
  sonar_rng << sonar_rng_;
  residual_rng << residual_rng_;
  state.strings = {rng.str(), sonar_rng.str(), residual_rng.str()};
  state.reals = {acc_x_,
                 acc_y_,
                 acc_gyro_[0],
                 acc_gyro_[1],
                 acc_gyro_[2],
                 comp_x_,
                 comp_y_,
                 focal_factor_,
                 bias_[0],
                 bias_[1],
                 bias_[2],
                 contact_[0],
                 contact_[1],
                 contact_[2],
                 contact_[3],
                 tyre_pitch_,
                 tyre_pitch_rate_,
                 tyre_roll_,
                 tyre_roll_rate_,
                 last_pitch_,
                 last_roll_,
                 gyro_lagged_[0],
                 gyro_lagged_[1],
                 gyro_lagged_[2],
                 accel_x_,
                 accel_y_,
                 last_vx_,
                 last_vy_,
                 have_last_velocity_ ? 1.0 : 0.0,
                 brightness_,
                 flicker_phase_,
                 sonar_comp_x_,
                 sonar_comp_y_,
                 sonar_raw_,
                 sonar_x_,
                 sonar_v_,
                 sonar_v_pred_,
                 sonar_last_t_,
                 sonar_valid_ ? 1.0 : 0.0};
  state.integers = {start_,     next_frame_,  next_publish_, frame_index_, publish_index_,
                    acc_count_, acc_quality_, sonar_frames_, next_sonar_,  sonar_index_};
}

void Px4FlowUnit::RestoreInternal(const cosim::UnitState& state) {
  if (state.strings.size() != 3 || state.reals.size() != 39 || state.integers.size() != 10) {
    throw cosim::UnitError(Where() + ": saved state has the wrong shape");
  }
  std::mt19937_64* const generators[] = {&rng_, &sonar_rng_, &residual_rng_};
  for (std::size_t i = 0; i < 3; ++i) {
    std::istringstream rng_text(state.strings[i]);
    std::mt19937_64 rng;
    rng_text >> rng;
    if (!rng_text) throw cosim::UnitError(Where() + ": saved generator state is not readable");
    *generators[i] = rng;
  }
  const auto& r = state.reals;
  acc_x_ = r[0];
  acc_y_ = r[1];
  for (int i = 0; i < 3; ++i) acc_gyro_[i] = r[static_cast<std::size_t>(2 + i)];
  comp_x_ = r[5];
  comp_y_ = r[6];
  focal_factor_ = r[7];
  for (int i = 0; i < 3; ++i) bias_[i] = r[static_cast<std::size_t>(8 + i)];
  for (int i = 0; i < 4; ++i) contact_[i] = r[static_cast<std::size_t>(11 + i)];
  tyre_pitch_ = r[15];
  tyre_pitch_rate_ = r[16];
  tyre_roll_ = r[17];
  tyre_roll_rate_ = r[18];
  last_pitch_ = r[19];
  last_roll_ = r[20];
  for (int i = 0; i < 3; ++i) gyro_lagged_[i] = r[static_cast<std::size_t>(21 + i)];
  accel_x_ = r[24];
  accel_y_ = r[25];
  last_vx_ = r[26];
  last_vy_ = r[27];
  have_last_velocity_ = r[28] != 0.0;
  brightness_ = r[29];
  flicker_phase_ = r[30];
  sonar_comp_x_ = r[31];
  sonar_comp_y_ = r[32];
  sonar_raw_ = r[33];
  sonar_x_ = r[34];
  sonar_v_ = r[35];
  sonar_v_pred_ = r[36];
  sonar_last_t_ = r[37];
  sonar_valid_ = r[38] != 0.0;
  start_ = state.integers[0];
  next_frame_ = state.integers[1];
  next_publish_ = state.integers[2];
  frame_index_ = state.integers[3];
  publish_index_ = state.integers[4];
  acc_count_ = state.integers[5];
  acc_quality_ = state.integers[6];
  sonar_frames_ = state.integers[7];
  next_sonar_ = state.integers[8];
  sonar_index_ = state.integers[9];
  CacheCamera();
}

}  // namespace linesim::sensors
