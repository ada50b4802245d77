#pragma once

// Image-level reference of the PX4Flow optic-flow sensor: the camera
// (MT9V034 with 4x binning, 64x64 window, auto exposure) rendering a
// procedurally textured floor, and the firmware's block matching
// (PX4/Flow src/modules/flow/flow.c, compute_flow) run on two frames.
// The fast model of px4flow_unit.h is calibrated against it.

#include <array>
#include <cstdint>
#include <random>
#include <vector>

namespace linesim::sensors {

/// Camera and firmware settings shared by the image-level reference and the
/// fast model. Defaults are the device's (see models/sensors/px4flow.yaml for
/// the sources).
struct Px4FlowCamera {
  double focal_length_px = 666.7;    // 16 mm lens / (6 um * 4 binning)
  double frame_rate_hz = 400.0;      // PX4Flow README
  int search_range_px = 4;           // BOTTOM_FLOW_SEARCH_WINDOW_SIZE (2013-2016 firmware)
  int feature_threshold = 30;        // BFLOW_F_THLD
  double max_exposure_s = 0.0025;    // EXPOSURE_MAX rows, capped by the frame interval
  double max_gain = 4.0;             // MT9V034 analog gain 1x..4x
  double target_brightness_dn = 80;  // AEC/AGC desired bin BRIGHT = 20 of 64 -> 80 of 255
  double responsivity_dn = 42.0;     // 8-bit DN per (lux at the floor * s) at gain 1
  double full_well_dn = 0.0128;      // DN per electron at gain 1 (8-bit), for shot noise
  double read_noise_dn = 0.5;        // read noise at gain 1, 8-bit DN
  double texture_scale_m = 0.001;    // lattice of the procedural texture
};

/// Result of the sensor's auto exposure / gain for an illuminance.
struct Exposure {
  double exposure_s;  // integration time
  double gain;        // analog gain
  double mean_dn;     // mean image level, 8-bit DN (before noise)
  double noise_dn;    // std of the temporal noise at mean_dn (shot + read), 8-bit DN
};

/// The MT9V034's AEC/AGC loop at its steady state: exposure first, up to its
/// maximum, then gain, until the mean reaches the target brightness.
Exposure AutoExposure(const Px4FlowCamera& cam, double lux);

/// One frame's result of the firmware's compute_flow.
struct FlowResult {
  double flow_x_px = 0.0, flow_y_px = 0.0;  // 0 when quality is 0
  int quality = 0;                          // blocks * 255 / 25, 0 unless > 10 blocks
  int blocks = 0;                           // blocks that passed the texture and SAD tests
  std::array<int, 25> diff{};               // compute_diff of each block
};

constexpr int kImageSize = 64;
using Image = std::array<std::uint8_t, kImageSize * kImageSize>;

/// compute_diff of flow.c: the sum of the 24 absolute differences between
/// vertical and horizontal neighbours of the 4x4 pixels at (x+2, y+2).
int ComputeDiff(const Image& img, int x, int y);

/// The firmware's compute_flow without gyro compensation and without the
/// histogram filter (BFLOW_HIST_FIL = 0, BFLOW_GYRO_COM = 0): texture test,
/// full integer SAD search over (2S+1)^2 offsets (first minimum in scan
/// order), SAD acceptance (BFLOW_V_THLD = 5000), half-pixel refinement at
/// the 8 neighbours with the truncating averages of __UHADD8, mean of the
/// blocks' offsets.
FlowResult ComputeFlow(const Image& previous, const Image& current, int search_range,
                       int feature_threshold);

/// Renders frames of a textured floor seen by the camera and runs the
/// firmware on them. The texture is a value-noise field on a square lattice
/// (texture_scale_m), bilinearly interpolated and scaled to unit standard
/// deviation; reflectance = mean * (1 + contrast * field).
class Px4FlowImageModel {
 public:
  Px4FlowImageModel(const Px4FlowCamera& cam, std::uint64_t seed);

  /// Renders the frame whose exposure ends when the surface has moved by
  /// (dx, dy) metres relative to the sensor (in the sensor frame), with
  /// the surface moving at (vx, vy) m/s during the exposure (motion blur),
  /// height h (m), contrast c and illuminance `lux` (which sets the auto
  /// exposure); `brightness` scales the light of this exposure against the
  /// one the auto exposure adapted to (a flickering lamp: 1 + its deviation
  /// averaged over the exposure); `defocus_px`: the diameter of the lens'
  /// blur circle on the sensor, in binned pixels (a uniform disk: a thin
  /// lens focused at another distance; 0: in focus).
  void Render(double dx_m, double dy_m, double vx_mps, double vy_mps, double height_m,
              double contrast, double lux, Image& out, double brightness = 1.0,
              double defocus_px = 0.0);

  /// Renders the next frame after a frame interval at the given relative
  /// velocity and returns the firmware's flow between the two frames.
  FlowResult Step(double vx_mps, double vy_mps, double height_m, double contrast, double lux,
                  double brightness = 1.0, double defocus_px = 0.0);

  /// A periodic part of the texture (slats, a weave): period (m) along the
  /// direction (cos, sin) in the sensor frame, carrying `share` of the
  /// texture's variance (0: none, the default).
  void SetPeriodicTexture(double period_m, double cos_dir, double sin_dir, double share);

 private:
  double Field(double x, double y) const;

  Px4FlowCamera cam_;
  double period_m_ = 0.0, period_cos_ = 1.0, period_sin_ = 0.0, periodic_share_ = 0.0;
  std::uint64_t texture_seed_;
  std::mt19937_64 rng_;
  double dx_m_ = 0.0, dy_m_ = 0.0;
  bool have_previous_ = false;
  Image previous_{}, current_{};
  std::vector<double> disk_;  // the blur circle's sample offsets (m), x y per point
};

}  // namespace linesim::sensors
