#include "units/sensors/imu_unit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <utility>

#include "models/rotation.h"

namespace linesim::sensors {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using Vec3 = std::array<double, 3>;
using Mat3 = models::Matrix3;

Vec3 Cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

// m^T v.
Vec3 TransposeTimes(const Mat3& m, const Vec3& v) {
  return {m[0] * v[0] + m[3] * v[1] + m[6] * v[2], m[1] * v[0] + m[4] * v[1] + m[7] * v[2],
          m[2] * v[0] + m[5] * v[1] + m[8] * v[2]};
}

// Rounded to the resolution (if any) after clipping to +-range: what the
// device's output register holds.
double Digitize(double x, double range, double resolution) {
  x = std::clamp(x, -range, range);
  return resolution > 0.0 ? std::round(x / resolution) * resolution : x;
}

}  // namespace

ImuUnit::ImuUnit(std::string name, std::uint64_t seed)
    : cosim::Unit(kTypeName, std::move(name)),
      seed_(seed),
      rng_(seed),
      mount_x_(kNaN),
      mount_y_(kNaN),
      mount_z_(kNaN),
      mount_roll_(kNaN),
      mount_pitch_(kNaN),
      mount_yaw_(kNaN),
      gyro_noise_density_(kNaN),
      gyro_bias_instability_(kNaN),
      gyro_turn_on_bias_(kNaN),
      gyro_range_(kNaN),
      gyro_resolution_(kNaN),
      accel_noise_density_(kNaN),
      accel_bias_instability_(kNaN),
      accel_turn_on_bias_(kNaN),
      accel_range_(kNaN),
      accel_resolution_(kNaN),
      bias_instability_time_(kNaN),
      orientation_{1.0, 0.0, 0.0, 0.0},
      velocity_(3, 0.0),
      angular_velocity_in_(3, 0.0),
      angular_velocity_out_(3, 0.0),
      linear_acceleration_{0.0, 0.0, kGravity} {
  auto& v = variables();
  const auto finite = cosim::Rule::Finite().NoDefault();
  const auto non_negative = cosim::Rule::NonNegative().NoDefault();
  const auto positive = cosim::Rule::Positive().NoDefault();
  v.Parameter("mount_x", "m", &mount_x_, "IMU origin in base_link, x (robot-specific)", finite);
  v.Parameter("mount_y", "m", &mount_y_, "IMU origin in base_link, y (robot-specific)", finite);
  v.Parameter("mount_z", "m", &mount_z_, "IMU origin in base_link, z (robot-specific)", finite);
  v.Parameter("mount_roll", "rad", &mount_roll_,
              "IMU frame in base_link: roll about x, applied first (robot-specific)", finite);
  v.Parameter("mount_pitch", "rad", &mount_pitch_,
              "IMU frame in base_link: pitch about y, after roll (robot-specific)", finite);
  v.Parameter("mount_yaw", "rad", &mount_yaw_,
              "IMU frame in base_link: yaw about z, applied last (robot-specific)", finite);
  v.Parameter("gyro_noise_density", "rad/(s.Hz^0.5)", &gyro_noise_density_,
              "gyroscope rate noise density (datasheet); a sample's white noise has standard "
              "deviation noise_density / sqrt(sample interval)",
              non_negative);
  v.Parameter("gyro_bias_instability", "rad/s", &gyro_bias_instability_,
              "gyroscope in-run bias stability: the floor of the Allan deviation (datasheet)",
              non_negative);
  v.Parameter("gyro_turn_on_bias", "rad/s", &gyro_turn_on_bias_,
              "standard deviation of the gyroscope bias drawn at start, per axis", non_negative);
  v.Parameter("gyro_range", "rad/s", &gyro_range_, "gyroscope measurement range, +-", positive);
  v.Parameter("gyro_resolution", "rad/s", &gyro_resolution_,
              "gyroscope output resolution (one LSB; 0: not quantized)", non_negative);
  v.Parameter("accel_noise_density", "m/(s2.Hz^0.5)", &accel_noise_density_,
              "accelerometer noise density (datasheet)", non_negative);
  v.Parameter("accel_bias_instability", "m/s2", &accel_bias_instability_,
              "accelerometer in-run bias stability: the floor of the Allan deviation "
              "(datasheet)",
              non_negative);
  v.Parameter("accel_turn_on_bias", "m/s2", &accel_turn_on_bias_,
              "standard deviation of the accelerometer bias drawn at start, per axis",
              non_negative);
  v.Parameter("accel_range", "m/s2", &accel_range_, "accelerometer measurement range, +-",
              positive);
  v.Parameter("accel_resolution", "m/s2", &accel_resolution_,
              "accelerometer output resolution (one LSB; 0: not quantized)", non_negative);
  v.Parameter("bias_instability_time", "s", &bias_instability_time_,
              "averaging time at which the Allan deviation reaches the bias instability; the "
              "bias random walk rate is bias_instability * sqrt(3 / this)",
              positive);

  v.Input("orientation", "1", &orientation_,
          "quaternion w, x, y, z of base_link in the map (normalised here)");
  v.Input("velocity_3d", "m/s", &velocity_, "velocity of base_link's origin in the map");
  v.Input("base_angular_velocity", "rad/s", &angular_velocity_in_,
          "angular velocity of base_link, in base_link (connect the chassis' angular_velocity; "
          "named apart from the output)");
  v.Output("angular_velocity", "rad/s", &angular_velocity_out_,
           "gyroscope reading in the IMU frame: truth + bias + noise, clipped and quantized",
           {"orientation", "velocity_3d", "base_angular_velocity"});
  v.Output("linear_acceleration", "m/s2", &linear_acceleration_,
           "accelerometer reading in the IMU frame: specific force (acceleration of the "
           "mount point minus gravity; +9.80665 on z at rest, level) + bias + noise, clipped "
           "and quantized",
           {"orientation", "velocity_3d", "base_angular_velocity"});
}

void ImuUnit::NormalPair(double& a, double& b) {
  // Uniforms with 53 random bits; u1 in (0, 1] so that log(u1) is finite.
  constexpr double kScale = 1.0 / 9007199254740992.0;  // 2^-53
  const double u1 = 1.0 - static_cast<double>(rng_() >> 11) * kScale;
  const double u2 = static_cast<double>(rng_() >> 11) * kScale;
  const double r = std::sqrt(-2.0 * std::log(u1));
  const double phi = 2.0 * std::numbers::pi * u2;
  a = r * std::cos(phi);
  b = r * std::sin(phi);
}

void ImuUnit::CacheMount() {
  mount_rotation_ = models::RollPitchYawMatrix(mount_roll_, mount_pitch_, mount_yaw_);
}

void ImuUnit::Initialize() {
  ThrowIfBadParameters();
  CacheMount();
  rng_.seed(seed_);
  // Turn-on biases: gyro x y z, accel x y z.
  double z[6];
  NormalPair(z[0], z[1]);
  NormalPair(z[2], z[3]);
  NormalPair(z[4], z[5]);
  for (std::size_t i = 0; i < 3; ++i) {
    bias_[i] = gyro_turn_on_bias_ * z[i];
    bias_[3 + i] = accel_turn_on_bias_ * z[3 + i];
  }
  noise_.fill(0.0);
  previous_velocity_.fill(0.0);
  previous_angular_velocity_.fill(0.0);
  interval_ = 0;
  UpdateOutputs();
}

void ImuUnit::UpdateOutputs() {
  // Rotation of base_link in the map (base vectors to map vectors); a zero
  // quaternion (unset) reads as identity, and DoStep refuses it.
  const Mat3 rot = models::QuaternionMatrix(orientation_[0], orientation_[1], orientation_[2],
                                            orientation_[3]);
  const Vec3 omega = {angular_velocity_in_[0], angular_velocity_in_[1], angular_velocity_in_[2]};
  for (std::size_t i = 0; i < 3; ++i) {
    sampled_velocity_[i] = velocity_[i];
    sampled_angular_velocity_[i] = omega[i];
  }
  Vec3 accel_origin{0.0, 0.0, 0.0}, alpha{0.0, 0.0, 0.0};
  if (interval_ > 0) {
    const double inv_dt = 1.0 / cosim::NsToSeconds(interval_);
    const Vec3 a_map = {(velocity_[0] - previous_velocity_[0]) * inv_dt,
                        (velocity_[1] - previous_velocity_[1]) * inv_dt,
                        (velocity_[2] - previous_velocity_[2]) * inv_dt};
    accel_origin = TransposeTimes(rot, a_map);
    for (std::size_t i = 0; i < 3; ++i) {
      alpha[i] = (omega[i] - previous_angular_velocity_[i]) * inv_dt;
    }
  }
  const Vec3 r = {mount_x_, mount_y_, mount_z_};
  const Vec3 tangential = Cross(alpha, r);
  const Vec3 centripetal = Cross(omega, Cross(omega, r));
  // -R^T g = R^T (0, 0, g0): the third row of R times g0.
  const Vec3 specific_force = {
      accel_origin[0] + tangential[0] + centripetal[0] + kGravity * rot[6],
      accel_origin[1] + tangential[1] + centripetal[1] + kGravity * rot[7],
      accel_origin[2] + tangential[2] + centripetal[2] + kGravity * rot[8]};
  const Vec3 omega_imu = TransposeTimes(mount_rotation_, omega);
  const Vec3 force_imu = TransposeTimes(mount_rotation_, specific_force);
  for (std::size_t i = 0; i < 3; ++i) {
    angular_velocity_out_[i] =
        Digitize(omega_imu[i] + bias_[i] + noise_[i], gyro_range_, gyro_resolution_);
    linear_acceleration_[i] = Digitize(force_imu[i] + bias_[3 + i] + noise_[3 + i],
                                       accel_range_, accel_resolution_);
  }
}

cosim::StepResult ImuUnit::DoStep(cosim::TimeNs t, cosim::TimeNs dt) {
  ClearError();
  if (!InputsFinite(t)) return cosim::StepResult::kError;
  const double norm2 = orientation_[0] * orientation_[0] + orientation_[1] * orientation_[1] +
                       orientation_[2] * orientation_[2] + orientation_[3] * orientation_[3];
  if (!(norm2 > 1e-12)) {
    return Fail("input 'orientation' is not a rotation (zero quaternion) at t = " +
                cosim::FormatSeconds(t) + " s");
  }
  // Commit the sample taken at t.
  previous_velocity_ = sampled_velocity_;
  previous_angular_velocity_ = sampled_angular_velocity_;
  interval_ = dt;
  // The biases of the sample at t + dt and its white noise.
  const double dt_s = cosim::NsToSeconds(dt);
  const double sqrt_dt = std::sqrt(dt_s);
  // Rate random walk K = B sqrt(3 / tau) per sqrt(s) (see the header).
  const double walk = std::sqrt(3.0 / bias_instability_time_) * sqrt_dt;
  const double walk_g = gyro_bias_instability_ * walk;
  const double walk_a = accel_bias_instability_ * walk;
  const double white_g = gyro_noise_density_ / sqrt_dt;
  const double white_a = accel_noise_density_ / sqrt_dt;
  double z[12];
  for (std::size_t k = 0; k < 12; k += 2) NormalPair(z[k], z[k + 1]);
  for (std::size_t i = 0; i < 3; ++i) {
    bias_[i] += walk_g * z[i];
    bias_[3 + i] += walk_a * z[3 + i];
    noise_[i] = white_g * z[6 + i];
    noise_[3 + i] = white_a * z[9 + i];
  }
  return cosim::StepResult::kOk;
}

void ImuUnit::SaveInternal(cosim::UnitState& state) const {
  state.reals.clear();
  for (const auto* a : {&previous_velocity_, &previous_angular_velocity_, &sampled_velocity_,
                        &sampled_angular_velocity_}) {
    state.reals.insert(state.reals.end(), a->begin(), a->end());
  }
  for (const auto* a : {&bias_, &noise_}) {
    state.reals.insert(state.reals.end(), a->begin(), a->end());
  }
  state.integers = {interval_};
  std::ostringstream rng;
  rng << rng_;
  state.strings = {rng.str()};
}

void ImuUnit::RestoreInternal(const cosim::UnitState& state) {
  if (state.reals.size() != 24 || state.integers.size() != 1 || state.strings.size() != 1) {
    throw cosim::UnitError(Where() + ": saved state has " + std::to_string(state.reals.size()) +
                           " reals, " + std::to_string(state.integers.size()) + " integers and " +
                           std::to_string(state.strings.size()) +
                           " strings, expected 24, 1 and 1");
  }
  auto it = state.reals.begin();
  std::copy(it, it + 3, previous_velocity_.begin());
  std::copy(it + 3, it + 6, previous_angular_velocity_.begin());
  std::copy(it + 6, it + 9, sampled_velocity_.begin());
  std::copy(it + 9, it + 12, sampled_angular_velocity_.begin());
  std::copy(it + 12, it + 18, bias_.begin());
  std::copy(it + 18, it + 24, noise_.begin());
  interval_ = state.integers[0];
  std::istringstream rng(state.strings[0]);
  rng >> rng_;
  if (!rng) throw cosim::UnitError(Where() + ": saved random generator state is not readable");
  // The mount parameters came back with the variables.
  CacheMount();
}

}  // namespace linesim::sensors
