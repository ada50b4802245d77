#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"
#include "models/scene.h"

namespace linesim::estimation {

/// Surface sensing that fuses the optic flow with the laser localization
/// and the wheel encoders: paper 1's future work (Unhelkar et al., ICRA
/// 2014, Sec. VI-D: "additional measures to improve the reliability of
/// surface sensing using position and velocity information obtained from
/// laser scanner-based localization and encoder information").
///
/// Why the laser: a wheel's encoder measures its contact point's velocity
/// RELATIVE to the surface it rolls on (e_j, base_link: the wheel
/// odometry's wheel_velocity, not rectified), and so does the optic flow
/// (the surface relative to its point). The belt's absolute velocity needs
/// an absolute reference: the laser localization, which places the robot in
/// the map. Rigid body, contacts that roll without sliding:
///   v_map(r_j) = R(theta) e_j + u_{surface(j)}            (paper 1 Eq. 3)
/// (u: the surface's velocity in the map, 0 for the floor).
///
/// State, map frame: x = [D, u_1, ..., u_K], D (2) the residual between the
/// laser's position of base_link and the encoders' dead reckoning P_enc
/// (the rigid-body least-squares fit of the unrectified wheel velocities at
/// base_link's origin, the swerve odometry's fit, paper 1 Eq. 1 inverted,
/// turned to map by the estimated heading and integrated), u_k (2) the
/// velocity of scene belt k. With the fit's 2 x 2 block B_j of wheel j at
/// the origin,
///   dD/dt = sum_k M_k u_k,  M_k = sum_{j over belt k} R B_j R^T
/// (all wheels on belt k: M_k = I; the left ones: M_k = I/2 plus the turn
/// their difference implies; none: 0, and the floor contributes nothing).
/// Prediction per step h: D += h sum_k M_k u_k; process noise
/// dead_reckoning_noise^2 h on D (the contacts' creep, the fit's error) and
/// belt_random_walk^2 h on each u_k (paper 1's process noise, 3 sigma = 1
/// cm/s per 0.1 s sample: (0.01 / 3) / sqrt(0.1) = 0.0105 m/s/sqrt(s)), or
/// ramp_random_walk^2 h during a detected switch.
///
/// Laser (each new accepted match, its position at match_time t_m, about
/// 40 ms before the step t): z = p_match - P_enc(t_m) (the dead reckoning's
/// history interpolated at t_m) = D(t) - (t - t_m) sum_k M_k u_k + n,
/// n ~ N(0, laser_position_sigma^2 I). The laser's position error is white
/// at the match rate (its autocorrelation at 40 ms: 0.12, measured), so no
/// window is needed: the Kalman filter is the optimal slope of the
/// residual, with the encoders' resolution (2 pi r / cpr: 6 um per count on
/// the Rob@Work 3) far below the laser's.
///
/// Optic flow (each new valid PX4Flow message of quality > 0 whose window
/// lay over one belt k): the sensor reads f = u_k - v_map(p) (the surface
/// relative to its point p, turned to map by its mount and the mean heading
/// over the window). The point's velocity by the encoders is the fit at p,
/// v_map(p) = R C(p) e + sum_j R B_j(p) R^T u_{surface(j)}, so
///   y = f + R C(p) e + sum_{j over other belts} R B_j(p) R^T u_{s(j)}
///     = (I - M_k(p)) u_k + n,  n ~ N(0, flow_sigma^2 I),
/// each term averaged over the message's window. No wheel on belt k
/// (crossing: the corner sensors reach the belt first): H = I, the flow
/// alone measures the belt with the floor wheels' encoders as the robot's
/// motion. Every wheel on belt k: H = 0, the flow and the encoders measure
/// the same relative motion and the belt comes from the laser alone.
/// Straddling: in between. The flow is independent of the laser.
///
/// Updates: the Kalman filter's (2 x dim), a measurement whose squared
/// Mahalanobis innovation exceeds outlier_gate is not used.
///
/// State switches (the SwitchDetector of steady_state_kalman.h): the random
/// walk models a belt's velocity within one on/off state (paper 1 Sec.
/// II); a switch (a ramp of about 1 s) would lag by the filter's time
/// constant. Two detectors on the matches, each a run of switch_samples
/// beyond its gate on one side: (1) each component of the match's
/// innovation in sigmas of sqrt(S_ii) (switch_gate 3, 2 samples: at most
/// 4 Q(3)^2 = 7.3e-6 false alarms per match on the model, one per 1.5 h at
/// 25 matches/s); (2) the least-squares slope of the last slope_matches
/// residuals against the drift the state predicts, sum_k M_k u_k, in
/// sigmas of sigma_p^2 / sum (t - mean t)^2 + M P_uu M^T (slope_gate 4:
/// successive slopes share most of their matches, so a run is about one
/// independent draw per window: 4 Q(4) per 0.2 s, one false alarm per 26
/// min). A detection restarts: D from this match (plus the drift since it),
/// and, with one belt under the wheels and det M > 0.1 (a third of the
/// wheels on it), u from the slope of the last switch_samples + 1
/// residuals solved through M, with its variance; else the belts under the
/// wheels reopen to initial_sigma. For ramp_time (the line's ramps: about
/// 1 s) the belt follows ramp_random_walk.
///
/// Wheel slip: the chassis is ODE with real friction contacts, so a wheel
/// can creep or slide when the belt starts under it (the measured robot
/// lagged a starting belt by up to 3 cm/s in some hold_on_belt runs). That is
/// the model error dead_reckoning_noise stands for; a gross slide shows as
/// an outlier or as a detected switch.
///
/// The IMU (structural key `imu`): the belt under the wheels carries the
/// robot, and the accelerometer feels it at once while the laser needs
/// 0.2-0.3 s to see the drift clear its noise. The specific force f
/// (IMU frame; level floor: its x, y are the body's horizontal
/// acceleration) turned to map by the estimated heading and the mount's
/// yaw and integrated over each step gives V_imu; minus the encoders' fit
/// at base_link's origin (map) it is
///   W = V_imu - R fit(e) = sum_k M_k u_k + b,
/// b (2, map) the integration's offset: its start, the bias beta (2, IMU
/// frame) integrated, b' = R beta, white noise imu_velocity_noise. The
/// state grows by [b, beta]; each step updates with z = W, H = [0, M_1 ..
/// M_K, I, 0], r = dead_reckoning_noise^2 / h (the same contact creep the
/// residual D walks by, as a velocity over one step). beta starts at the
/// device's turn-on bias sigma and walks at its bias random walk; over the
/// floor (M = 0) W measures b alone, and the laser ties u down, so b and
/// beta are learnt while the line stands. A switch detector on W's
/// innovation (switch_gate, switch_samples) reopens the belts under the
/// wheels as the match detectors do: at 0.5 m/s^2 a ramp leaves the 3 sigma
/// gate (about 3 cm/s with one step's creep) within about 0.07 s. The unit
/// should step at the IMU's rate (the sample is the mean specific force
/// over the IMU's interval: stepping slower skips samples).
///
/// Outputs per wheel: the estimate of the belt the map puts it over,
/// base_link (0 over the floor); per sensor the same in map (for the
/// flow_error evaluation); per belt its estimate, sigma and switches.
///
/// No output depends directly on an input: the outputs after DoStep(t, dt)
/// come from the inputs at t (one communication step of delay), so the
/// unit adds no algebraic loop to localization -> estimation -> control.
/// Its output rectifies the odometry (Eq. 3), which feeds the pose fusion
/// and the matcher's motion prediction; this unit reads the matcher's
/// positions and the UNrectified wheel velocities, not the fusion's
/// velocity, so its own estimate does not come back to it as a
/// measurement.
class SurfaceFusionUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "surface_fusion";
  /// Dead-reckoning steps kept for matches that refer to the past (1.28 s
  /// at 20 ms; a match is about 40 ms old).
  static constexpr std::size_t kHistory = 64;

  /// `sensors` PX4Flow (>= 0) and `wheels` (>= 2) wheels, else
  /// cosim::UnitError; the belts are every belt of `scene`; `imu`: the
  /// accelerometer's input and state (see the class comment).
  SurfaceFusionUnit(std::string name, int sensors, int wheels, const models::Scene& scene,
                    bool imu = false);

  void Setup(cosim::TimeNs start, cosim::TimeNs stop) override;
  void Initialize() override;
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

  std::size_t belt_count() const { return belts_.size(); }

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  /// The rigid-body least-squares fit (C for each sensor point) from the
  /// wheel positions.
  void Cache();
  void ResetState();
  /// The prediction over h seconds ending at t: D += h sum_k M_k u_k
  /// (drift_), random walks.
  void Predict(double h, cosim::TimeNs t);
  /// One Kalman update with z = H x + n, n ~ N(0, r I); H row-major 2 x
  /// dim_. Returns false (not applied) beyond the outlier gate. `nu`
  /// receives the innovation, `s_diag` the diagonal of S.
  bool Update(const double* h, const double z[2], double r, double nu[2], double s_diag[2]);
  /// A match's update: z = D(t) - lag sum_k M_k u_k + n.
  void UpdatePosition(const double z[2], double lag, double nu[2], double s_diag[2]);
  /// The 2 x 2 block at state index a: uncorrelated, variance sigma^2.
  void ReopenBlock(std::size_t a, double sigma);
  /// The least-squares slope (m/s, map) of the last `count` matches'
  /// residuals and its variance per component; false if they are at one
  /// time.
  bool Slope(std::size_t count, double slope[2], double& variance) const;
  /// The dead reckoning at `time` from the history; false if older.
  bool DeadReckoningAt(cosim::TimeNs time, double out[2]) const;
  void WriteOutputs(double c, double s);
  /// The IMU's update (z = W) and its switch detector; `enc` is the
  /// encoders' fit at the origin this step (map).
  void UpdateImu(const double enc[2], double h, cosim::TimeNs t);

  std::size_t n_, w_;
  models::BeltMap belts_;  // 0 over the floor, k + 1 over scene belt k

  // Parameters.
  std::vector<double> sensor_x_, sensor_y_, sensor_yaw_, wheel_x_, wheel_y_;
  double belt_random_walk_ = 0.0105;
  double initial_sigma_ = 0.2;
  double flow_sigma_ = 0.03;
  double laser_position_sigma_ = 0.0015;
  double dead_reckoning_noise_ = 0.001;
  double outlier_gate_ = 25.0;
  double switch_gate_ = 3.0;
  std::int64_t switch_samples_ = 2;
  double slope_gate_ = 4.0;
  std::int64_t slope_matches_ = 5;
  double ramp_random_walk_ = 0.1;
  double ramp_time_ = 1.0;
  bool imu_ = false;
  double imu_yaw_ = 0.0;
  double imu_velocity_noise_ = 4.2e-4;
  double imu_bias_sigma_ = 0.049;
  double imu_bias_walk_ = 2.2e-5;

  // Inputs.
  std::vector<double> sensor_velocity_, sensor_valid_, sensor_quality_, sensor_message_count_;
  std::vector<double> position_;
  double yaw_ = 0.0;
  std::vector<double> laser_position_;
  double match_time_ = 0.0, match_count_ = 0.0;
  std::vector<double> wheel_velocity_;
  std::vector<double> imu_acceleration_;

  // Outputs.
  std::vector<double> wheel_surface_velocity_, wheel_on_belt_, sensor_surface_velocity_;
  std::vector<double> belt_velocity_, belt_sigma_, switch_count_, rejected_count_;

  // Cached: per sensor its 2 x 2W fit C (row-major; wheel j's 2 x 2 block
  // is columns 2j, 2j + 1), the same at base_link's origin; the mounts.
  std::vector<double> fit_, origin_fit_;
  std::vector<double> mount_cos_, mount_sin_;

  // State x = [D (2), u_1 (2), ..., u_K (2)] (map) and its covariance
  // (dim_ x dim_, row-major); the detector's runs (2); per belt the end of
  // a detected switch, switches and rejected flow messages; rejected
  // matches.
  static constexpr double kInitialResidualSigma = 0.1;  // m: until the first match
  std::size_t dim_ = 2;
  std::vector<double> state_, cov_;
  std::vector<std::int64_t> run_, slope_run_, ramp_until_, switches_, rejected_;
  std::int64_t rejected_match_ = 0;
  // With the IMU: b's index in the state (beta follows), the integrated
  // velocity V_imu (map) and the W detector's runs (2).
  std::size_t imu_index_ = 0;
  double imu_velocity_[2] = {0.0, 0.0};
  // This step's rotation of the IMU frame to map (yaw + imu_yaw), taken
  // once in DoStep for the integration and the prediction.
  double imu_cos_ = 1.0, imu_sin_ = 0.0;
  std::vector<std::int64_t> imu_run_;
  // The dead reckoning (map) and its history per step (a ring of kHistory,
  // oldest at first_).
  double dead_reckoning_[2] = {0.0, 0.0};
  std::vector<cosim::TimeNs> hist_t_;
  std::vector<double> hist_p_;
  std::size_t first_ = 0, size_ = 0;
  double last_match_count_ = 0.0;
  // The last matches' times (s) and residuals z (map, 2), a ring of
  // kMatches (oldest at match_first_), cleared at a restart.
  static constexpr std::size_t kMatches = 16;
  std::vector<double> match_t_, match_z_;
  std::size_t match_first_ = 0, match_size_ = 0;
  // Per sensor, the message window: the surface it began over, the message
  // count last seen, the accumulated y (map, 2), M (map, 4) and heading (2)
  // times the step, and its length.
  std::vector<std::int64_t> window_surface_;
  std::vector<double> last_count_, acc_y_, acc_m_, acc_h_;
  std::vector<cosim::TimeNs> acc_ns_;
  // Scratch (from the pose each step).
  std::vector<std::int64_t> wheel_surface_, sensor_surface_;
  std::vector<double> drift_;    // per belt M_k (map, 2 x 2) this step
  std::vector<double> scratch_;  // the updates' products

  cosim::TimeNs start_ = 0;
};

}  // namespace linesim::estimation
