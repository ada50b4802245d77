#pragma once

#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"

namespace linesim::sensors {

/// A strapdown MEMS IMU (3-axis gyroscope and accelerometer) fixed to the
/// robot's base at a mount pose, sampled once per unit step (the scenario
/// sets the rate, e.g. 100-200 Hz). The device figures (noise densities,
/// bias instability, turn-on bias, range, resolution) come from a model
/// file in models/sensors/ (see adis16470.yaml).
///
/// Per sample k at time t_k (direct feedthrough: UpdateOutputs computes the
/// sample from the inputs of t_k; DoStep(t_k, dt) commits it):
///  - truth in base_link: omega (input base_angular_velocity), the rotation R of
///    base_link in the map (input orientation, normalised), the acceleration
///    of base_link's origin a = R^T (v_k - v_{k-1}) / dt from the successive
///    velocity_3d samples, the angular acceleration alpha = (omega_k -
///    omega_{k-1}) / dt, and at the mount point r:
///      a_mount = a + alpha x r + omega x (omega x r);
///  - specific force f = a_mount - R^T g, g = (0, 0, -9.80665) m/s^2 (at
///    rest on a level floor f = (0, 0, +9.80665));
///  - both rotated into the IMU frame by the mount rotation (roll, pitch,
///    yaw: R_m = Rz(yaw) Ry(pitch) Rx(roll), IMU axes in base_link);
///  - reading = truth + bias + white noise, clipped to +-range and rounded
///    to the resolution (when > 0). The white noise of a sample has standard
///    deviation noise_density / sqrt(dt), dt its sample interval; the bias is
///    drawn once at Initialize (turn-on bias, standard deviation
///    *_turn_on_bias per axis) and then walks: b_{k+1} = b_k + sigma_b
///    sqrt(dt) N(0, 1), with the rate random walk sigma_b =
///    bias_instability * sqrt(3 / bias_instability_time): a random walk of
///    rate sigma_b has Allan deviation sigma_b sqrt(tau / 3), which reaches
///    the datasheet's bias instability at the averaging time tau =
///    bias_instability_time of the Allan curve's floor.
/// The first sample (no predecessor) has zero linear and angular
/// acceleration of the origin and no white noise (only bias). DoStep(t, dt)
/// commits the sample UpdateOutputs (or Initialize) took at t, whatever
/// inputs it is given since (a Gauss-Seidel master hands it the chassis'
/// values at t + dt).
///
/// Random numbers: one std::mt19937_64 seeded with the constructor's seed
/// (reseeded at Initialize, so Initialize is idempotent), standard normals
/// by Box-Muller in pairs (no cached values outside the saved state).
class ImuUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "imu";
  /// Standard gravity (CGPM 1901), m/s^2.
  static constexpr double kGravity = 9.80665;

  ImuUnit(std::string name, std::uint64_t seed);

  void Initialize() override;
  void UpdateOutputs() override;
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

  /// The current gyroscope and accelerometer biases (IMU frame), for tests.
  std::array<double, 3> gyro_bias() const { return {bias_[0], bias_[1], bias_[2]}; }
  std::array<double, 3> accel_bias() const { return {bias_[3], bias_[4], bias_[5]}; }

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  /// Two standard normals (Box-Muller) from two draws of rng_.
  void NormalPair(double& a, double& b);
  void CacheMount();

  std::uint64_t seed_;
  std::mt19937_64 rng_;

  // Parameters.
  double mount_x_, mount_y_, mount_z_, mount_roll_, mount_pitch_, mount_yaw_;
  double gyro_noise_density_, gyro_bias_instability_, gyro_turn_on_bias_, gyro_range_,
      gyro_resolution_;
  double accel_noise_density_, accel_bias_instability_, accel_turn_on_bias_, accel_range_,
      accel_resolution_;
  double bias_instability_time_;

  // Inputs.
  std::vector<double> orientation_, velocity_, angular_velocity_in_;
  // Outputs.
  std::vector<double> angular_velocity_out_, linear_acceleration_;

  // Mount rotation (row-major, IMU axes as columns in base_link), cached.
  std::array<double, 9> mount_rotation_{};

  // State: the last committed sample's velocity (map) and angular velocity
  // (base_link), the interval since it (0 before the first step), the
  // biases (gyro x y z, accel x y z) and the white noise of the coming
  // sample (same order).
  std::array<double, 3> previous_velocity_{}, previous_angular_velocity_{};
  // The inputs of the sample UpdateOutputs took last (what DoStep commits).
  std::array<double, 3> sampled_velocity_{}, sampled_angular_velocity_{};
  cosim::TimeNs interval_ = 0;
  std::array<double, 6> bias_{}, noise_{};
};

}  // namespace linesim::sensors
