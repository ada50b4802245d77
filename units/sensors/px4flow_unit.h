#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"
#include "models/scene.h"
#include "units/sensors/px4flow_image.h"

namespace linesim::sensors {

/// One PX4Flow optic-flow sensor looking straight down from a fixed height
/// (paper 1, Unhelkar et al. ICRA 2014: four of them at 0.1841 m at the
/// corners of the Rob@Work 3, with an added light).
///
/// Physics: the velocity of the surface under the sensor point (its belt's
/// `belt_velocity` when the point lies on a scene belt, else 0) relative to
/// the sensor point (v + omega x r), in the sensor frame; the true flow is
/// that velocity * frame interval * focal_length_px / mount_height px per
/// frame, positive along the surface's motion in the image, so that the
/// firmware's velocity -flow/f/dt*distance is the sensor's velocity over
/// the surface.
///
/// Fast model, per camera frame (frames at k / frame_rate from the start,
/// computed inside the step that contains them): auto exposure (AutoExposure)
/// gives exposure time, gain, mean level and temporal noise for the
/// surface's illumination plus `added_light`. Each of the 25 blocks draws
/// the firmware's texture measure (compute_diff)
///   M = 19.15 (sqrt(D^2 X + N^2) + 0.2 N z),
///   D = 0.45 mean_dn contrast sqrt((1 + 1 / (1 + (blur_px / 1.8)^2)) / 2),
///   N^2 = 2 noise_dn^2 + 1/6 (temporal noise and 8-bit rounding),
///   X ~ Gamma(3, 1/3) (block-to-block texture), z of zero mean and unit
///   variance (Irwin-Hall: a sum of four uniforms, close to normal, cheap),
/// (19.15 = 24 sqrt(2/pi): the mean of 24 absolute differences of Gaussian
/// variables; blur_px = |flow| * exposure * frame_rate) and is used when
/// M >= feature_threshold. A used block matches the true offset with
/// probability p = 1 / (1 + (0.18 / snr)^3), snr = D / noise_dn * (A^(1/2) /
/// B)^(1/2) (B = sqrt((1 + A) / 2) the blur factor in D, A = 1 / (1 +
/// (blur_px / 1.8)^2) the along-motion part's: placing the block along the
/// motion needs the texture the blur smooths), plus
/// min(0.42 / snr, 1) times such a z per axis, rounded to half pixels as the
/// sub-pixel search does; otherwise it matches noise (uniform on the
/// half-pixel grid within +-(S - 1/2)). Beyond the window (e = |flow| -
/// (S + 1/2) > 0 on either axis) a block still finds the window's edge with
/// probability exp(-(e / 2.3)^2) (the texture is correlated over a few
/// pixels) and otherwise an unrelated patch anywhere in the window: the
/// reading falls back towards 0 as the flow grows, wrong and not flagged.
/// The frame's flow is the mean of the used blocks, valid when more than 10
/// are used; quality = blocks * 255 / 25 (flow.c, compute_flow).
///
/// Calibration: 0.45, 1.8 and the Gamma shape come from the image-level
/// reference's compute_diff mean and spread over contrast 0.02..0.3,
/// 20..3000 lx, 0..0.7 m/s (texture lattice 1 mm, height 0.1841 m); 0.2 from
/// its spread on a featureless image; 0.18, 0.42, 1 from its frame-flow
/// bias and standard deviation at low light and contrast; 2.3 from its mean
/// reading at 4.5..8 px/frame with S = 4. The agreement is checked by
/// tests/units/sensors/px4flow_fast_vs_image_test.cc.
///
/// Integration (main.c, OPTICAL_FLOW_RAD): over frames of quality > 0 only,
/// integrated_x += flow_y / f, integrated_y -= flow_x / f, integration_time
/// += frame interval, integrated_gyro += gyro * frame interval, quality sum;
/// published and reset at publish_rate.
///
/// Disturbances (issue 21: each a mechanism of the device, with its unit
/// parameter and source in models/sensors/px4flow.yaml, each switchable
/// off) act on the image motion before the matcher, or on the firmware's
/// arithmetic after it, identically in both modes:
///  - rotation: the body's roll and pitch rates (the chassis' angular
///    velocity) plus the mount's shake add the apparent flow omega f /
///    frame_rate px per frame (omega x h in metres); the sensor's real
///    height (the chassis' z and attitude plus the shake's heave) scales
///    the translation flow, while the firmware converts with mount_height.
///  - shake: the wheels roll over the surface's height profile (scene
///    surface roughness_m, roughness_length_m): four Gauss-Markov contact
///    heights in travelled distance give the body's pitch, roll and heave
///    (a rigid body on stiff tyres follows the profile).
///  - acceleration pitch: the body pitches and rolls on its tyres' compliance
///    under horizontal acceleration (pitch_per_acceleration, a second-order
///    mode at tyre_mode_frequency): nose up when speeding up, so the
///    rotation flow first opposes the translation (PX4-Flow #23).
///  - gyro compensation (gyro_compensation, paper 1 Sec. IV-A: the flow is
///    compensated "using on-board gyroscope"): the frame flow minus the
///    board gyro's rate (lagged by gyro_lag, with gyro_bias drawn per
///    device and gyro_noise) times f / frame_rate; the residual is the
///    gyro's error times h.
///  - flicker: the ambient light (not the robot's own) of a surface with
///    flicker_hz and flicker_depth changes between exposures; the SAD is
///    not brightness invariant, so a brightness step Delta between frames
///    shrinks the SAD gap between the true and a wrong offset (fast model:
///    each block's snr bounded by 0.82 (d_block / Delta)^1.25, the gap
///    against the texture's spread, so that a faint block is lost first; the
///    half-pixel refinement's by the gap from folded-normal means; image
///    model: the frame rendered brighter or darker).
///  - periodic texture (surface texture_period_m, texture_periodic_share):
///    a block may match one period off (x - p or x + p) when its aperiodic
///    part cannot tell them apart.
///  - scale: the lens' focal length differs per device by a draw of
///    sigma scale_error from the unit's seed (the firmware uses the nominal
///    focal_length_px).
///  - the compute rate: frame_rate.
///  - defocus (f_number, focus_distance): a thin lens focused at
///    focus_distance images the floor at the sensor's real height as a
///    uniform blur circle of diameter (f / N) |v_h - v_f| / v_h on the
///    sensor (v_s = f s / (s - f)), in binned pixels of pixel_pitch. Image
///    model: rendered through that disk; fast model: the disk as a box
///    blur of the same variance per axis (length c sqrt(12 / 16)) on both
///    axes, added in quadrature to the motion blur along the motion, in
///    the blur law above (texture measure and match).
///
/// After the frames (both modes alike), what the messages carry:
///  - the sonar (MaxBotix HRLV-MaxSonar-EZ4 on the board; PX4/Flow
///    sonar.c): a reading every sonar_period of the real height, but never
///    below sonar_min_range (the HRLV reports targets closer than 300 mm
///    as 300 mm), with sonar_noise, rounded to sonar_resolution (its
///    serial output in mm); the firmware keeps readings inside
///    (sonar_min, sonar_max) and filters them (a position-velocity Kalman
///    filter with the fixed gains sonar_gain_position and
///    sonar_gain_velocity, SONAR_KAL_L1 and L2); the distance is valid
///    while the filtered value is inside the band. OPTICAL_FLOW carries
///    `distance` (ground_distance: the raw reading, or the filtered one
///    with sonar_filtered; 0 when invalid) and `sonar_velocity`
///    (flow_comp_m: the mean over the message's frames of quality > 0
///    and a valid distance of flow / f / frame interval times the
///    filtered distance). `velocity` is either that (velocity_scaling
///    sonar) or the flow scaled by the fixed mount_height (fixed_height:
///    paper 1 Sec. IV-A, "the fixed height of the sensor is used in
///    calculating velocity, rather than the noisy sonar measurements").
///  - the message cadence: a message every 1 / publish_rate (the firmware
///    sends OPTICAL_FLOW every BFLOW_THROTT computed frames: publish_rate
///    = frame_rate / BFLOW_THROTT; px4flow_node publishes each one).
///  - an UNEXPLAINED RESIDUAL (residual, residual_flow_noise): white noise
///    per message and axis, in rad/s of flow (velocity: times the height
///    used for the scaling), for what the device's measured noise has
///    beyond the mechanisms above. It has no mechanism and no source of
///    its own: its size is calibrated to the published noise figures
///    (models/sensors/px4flow.yaml says how). Its draws have a generator
///    of their own, so switching it off leaves every other draw as it was.
///
/// With `mode: image` each frame is rendered and matched instead
/// (Px4FlowImageModel: the 64 x 64 binned image of the surface's procedural
/// texture with its exposure, blur and noise, and the firmware's SAD search
/// with half-pixel refinement); everything after the frame's flow and
/// quality is the same. It is the slow reference (about 2-3 ms a frame);
/// its state (the texture and the last image) is not saved, so SaveState
/// refuses it.
class Px4FlowUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "px4flow";

  /// The scene gives the surfaces (texture contrast, illumination), the
  /// floor's surface and the belts (area, surface); one `belt_velocity`
  /// pair per scene belt is an input when the scene has belts.
  Px4FlowUnit(std::string name, const models::Scene& scene, std::uint64_t seed);

  std::vector<cosim::ParameterProblem> CheckParameters() const override;
  void Setup(cosim::TimeNs start, cosim::TimeNs stop) override;
  void Initialize() override;
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;
  /// True flow (px per frame, sensor frame) at the current inputs, of the
  /// translation only, at mount_height and the nominal focal length.
  void TrueFlow(double& fx, double& fy, int& surface) const;

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  /// The constructor's declarations: parameters, then inputs (the belts'
  /// velocity with `belts`) and outputs.
  void DeclareParameters();
  void DeclareInputsAndOutputs(bool belts);
  void CacheCamera();
  /// TrueFlow, and the direction of the surface's length (its belt's
  /// direction, map x for the floor) in the sensor frame.
  void TrueFlowAndDirection(double& fx, double& fy, int& surface, double& dir_c,
                            double& dir_s) const;
  void Frame(cosim::TimeNs t);
  /// The fast model's frame: quality and flow (px) of the true flow (fx, fy)
  /// over surface `surf` under the frame's exposure `e`; q stays 0 with 10
  /// or fewer blocks.
  void FastFrame(double fx, double fy, const models::Surface& surf, const Exposure& e, int& q,
                 double& flow_x, double& flow_y);
  /// Integrates a frame of quality q (> 0: counted) into OPTICAL_FLOW_RAD.
  void CommitFrame(int q, double flow_x, double flow_y);
  /// Advances the body's shake and acceleration pitch by one frame; sets
  /// rot_x_, rot_y_ (the sensor's rotation over the frame, rad, sensor
  /// frame) and height_ (m).
  void BodyMotion(double rel_speed, const models::Surface& surf);
  /// The lens' blur circle diameter on the sensor (binned px) for a floor
  /// at `height` (m): 0 when focused there.
  double DefocusPx(double height) const;
  /// The sonar readings due up to time t (ns) and the firmware's filter
  /// (sonar.c sonar_read); one reading of the height `height` (m).
  void SonarUpTo(cosim::TimeNs t, double height);
  void SonarReading(double t_s, double height, bool settle);
  /// The ambient light's brightness over the exposure ending at time t (s),
  /// relative to its mean (1 without flicker).
  double Brightness(const models::Surface& surf, double t, double exposure_s) const;
  void Publish();
  /// The light on `surf` under the sensor (0 in an injected dark spell).
  double Illuminance(const models::Surface& surf) const {
    return dark_ ? 0.0 : surf.illumination_lux + added_light_;
  }

  struct BeltArea {
    models::Rect area;
    int surface;
    double cos_dir, sin_dir;  // of area.direction_rad
  };
  std::vector<models::Surface> surfaces_;
  std::vector<BeltArea> belts_;
  int floor_surface_ = 0;

  // Parameters.
  double mount_x_ = std::numeric_limits<double>::quiet_NaN();  // required
  double mount_y_ = std::numeric_limits<double>::quiet_NaN();
  double mount_height_ = std::numeric_limits<double>::quiet_NaN();
  double mount_yaw_ = 0.0;
  double focal_length_px_ = 666.7, frame_rate_ = 400.0, publish_rate_ = 10.0;
  std::int64_t feature_threshold_ = 30, search_range_ = 4;
  double max_exposure_ = 0.0025, max_gain_ = 4.0, target_brightness_ = 80.0;
  double responsivity_ = 42.0, shot_noise_gain_ = 0.0128, read_noise_ = 0.5;
  double added_light_ = 0.0;
  // A fault to inject: no light at all on the surface in [dark_from, dark_until) s.
  double dark_from_ = 0.0, dark_until_ = 0.0;
  bool dark_ = false;  // the frame being computed falls in it
  double sonar_noise_ = 0.005, sonar_min_ = 0.12, sonar_max_ = 3.5;
  double sonar_min_range_ = 0.3, sonar_resolution_ = 0.001, sonar_period_ = 0.1;
  double sonar_gain_position_ = 0.8461, sonar_gain_velocity_ = 6.2034;
  bool sonar_filtered_ = false;
  // `velocity_scaling`: "fixed_height" (paper 1) or "sonar" (flow_comp_m).
  std::string velocity_scaling_ = "fixed_height";
  // Defocus: the lens' f-number, the distance it is focused at (0: at
  // mount_height) and the binned pixel's pitch on the sensor.
  double f_number_ = 1.4, focus_distance_ = 0.0, pixel_pitch_ = 24e-6;
  // The unexplained residual (rad/s of flow per message and axis).
  double residual_flow_noise_ = 0.0;
  bool residual_ = true;
  double gyro_noise_ = 0.0, gyro_range_ = 4.363323129985824;  // 250 deg/s
  bool gyro_compensation_ = false;
  double gyro_bias_ = 0.0, gyro_lag_ = 0.0, scale_error_ = 0.0;
  double pitch_per_acceleration_ = 0.0, roll_per_acceleration_ = 0.0;
  double tyre_mode_frequency_ = 15.0, tyre_mode_damping_ = 0.1;
  double wheelbase_ = 0.736, track_ = 0.32;
  // Mechanisms switched off one at a time (their share in the error).
  bool rotation_ = true, shake_ = true, flicker_ = true, periodic_texture_ = true;

  // Inputs.
  std::vector<double> position_, linear_velocity_, angular_velocity_, belt_velocity_;
  double yaw_ = 0.0, yaw_rate_ = 0.0;

  // Outputs.
  double integrated_x_ = 0.0, integrated_y_ = 0.0, integration_time_ = 0.0, quality_ = 0.0;
  std::vector<double> integrated_gyro_, velocity_, frame_flow_, sonar_velocity_;
  double distance_ = 0.0, valid_ = 0.0, frame_quality_ = 0.0, frame_count_ = 0.0;
  double defocus_ = 0.0;  // the last frame's blur circle (px)
  double message_count_ = 0.0;

  // `mode`: "fast" (the per-frame model above) or "image" (every frame
  // rendered and matched by Px4FlowImageModel: the reference, about 2-3 ms
  // a frame, for checking the fast model inside a scenario).
  std::string mode_ = "fast";

  // Internal state.
  Px4FlowCamera cam_;
  std::uint64_t seed_;
  std::unique_ptr<Px4FlowImageModel> image_;  // image mode only
  double cos_mount_ = 1.0, sin_mount_ = 0.0;  // of mount_yaw (CacheCamera)
  bool scale_by_sonar_ = false;               // velocity_scaling is sonar (CacheCamera)
  std::mt19937_64 rng_;
  cosim::TimeNs start_ = 0, next_frame_ = 0, next_publish_ = 0;
  std::int64_t frame_index_ = 0, publish_index_ = 0;
  double acc_x_ = 0.0, acc_y_ = 0.0, acc_gyro_[3] = {0, 0, 0};
  std::int64_t acc_count_ = 0, acc_quality_ = 0;
  // The firmware's gyro-compensated flow sums (px), for `velocity`, and
  // the same scaled per frame by the filtered sonar distance (px m) over
  // the frames with a valid distance (flow_comp_m).
  double comp_x_ = 0.0, comp_y_ = 0.0, sonar_comp_x_ = 0.0, sonar_comp_y_ = 0.0;
  std::int64_t sonar_frames_ = 0;
  // The sonar and its filter in the firmware: the last reading (m), the
  // filter's position (m) and velocity (m/s) and the time of its last
  // update (s), whether the distance is valid; the next reading's time.
  double sonar_raw_ = 0.0, sonar_x_ = 0.0, sonar_v_ = 0.0, sonar_v_pred_ = 0.0, sonar_last_t_ = 0.0;
  bool sonar_valid_ = false;
  cosim::TimeNs next_sonar_ = 0;
  std::int64_t sonar_index_ = 0;
  // Generators of their own (seeded from the unit's seed), so that the
  // sonar and the residual leave the frame stream's draws as they are.
  std::mt19937_64 sonar_rng_, residual_rng_;
  // Per device (drawn from the seed at Initialize): focal length factor and gyro bias.
  double focal_factor_ = 1.0, bias_[3] = {0, 0, 0};
  // Body motion state: contact heights (m) front-left, front-right,
  // rear-left, rear-right; tyre-mode pitch and roll (rad) and their rates;
  // the previous frame's body angles; the lagged gyro (rad/s, sensor frame).
  double contact_[4] = {0, 0, 0, 0};
  double tyre_pitch_ = 0.0, tyre_pitch_rate_ = 0.0, tyre_roll_ = 0.0, tyre_roll_rate_ = 0.0;
  double last_pitch_ = 0.0, last_roll_ = 0.0;
  double gyro_lagged_[3] = {0, 0, 0};
  double gyro_lag_factor_ = 1.0;  // 1 - exp(-dt / gyro_lag) (CacheCamera)
  // Body acceleration (m/s^2, base_link) over the current step.
  double accel_x_ = 0.0, accel_y_ = 0.0, last_vx_ = 0.0, last_vy_ = 0.0;
  bool have_last_velocity_ = false;
  // The frame being computed: rotation (rad, sensor frame), height (m),
  // brightness and the previous frame's brightness.
  double rot_x_ = 0.0, rot_y_ = 0.0, height_ = 0.0, brightness_ = 1.0, last_brightness_ = 1.0;
  double flicker_phase_ = 0.0;  // mains phase at the start (rad), drawn per run
  // The period of the frame's surface texture in the sensor frame (px; 0: none).
  double period_px_x_ = 0.0, period_px_y_ = 0.0;
  double periodic_share_ = 0.0;
};

}  // namespace linesim::sensors
