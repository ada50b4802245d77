#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"
#include "models/scene.h"

namespace linesim::evaluation {

/// The ground truth system of paper 2 (Sobreira et al. 2019, Sec. 6.1): a
/// beacon-based localization after Sobreira et al. 2016 (Industrial Robot
/// 43(6)) that estimates the robot's pose with an Extended Kalman Filter
/// from cylindrical beacons seen by the robot's 2D laser; paper 2 installed
/// four in the van and uncovered them only once the robot stood inside
/// (input `active`).
///
/// Beacons: the scene's obstacles of kind `beacon`, vertical cylinders of
/// one radius (position and radius from the scene). The scan plane is
/// taken level (3-DoF, as laser_localization): a beacon is a circle of its
/// radius around its axis.
///
/// Per new scan (scan_count changed) while `active`, from the first scan
/// that starts uncover_delay after `active` rose:
///  1. detection: the beams with a range in [range_min, range_max] as
///     points of the laser frame. A beacon candidate is seeded at every
///     beam nearest within a beacon's angular half width at its range
///     (asin(radius / (range + radius))). Its silhouette is the run of
///     beams around the seed nearer than the seed's range + radius + 2
///     range_sigma (+ flank_margin); the run must end on both sides within
///     a beacon's full width (a beacon stands free of its background, a
///     wall's nearest point does not). Not a segmentation by range jumps:
///     a jump threshold must exceed 3 sigma of the difference of two 12 mm
///     ranges (5 cm) plus the up to 2.5 cm a 4 cm cylinder recedes between
///     beams near its edge at 1 m, while the van's beacons stand 9 cm
///     before the wall and the LMS151's spot (15 mrad + 8 mm, SICK
///     8012471) puts a mixed pixel between them: in the simulated scans
///     the steps from beacon to wall were 1.6-9 cm, and an 8 cm threshold
///     merged the rear beacons with the wall. The run less edge_trim beams at
///     either edge (mixed pixels, grazing returns) is fitted with a circle
///     of the known radius: least squares for the centre c on sum
///     ((|p_i - c| - R) / range_sigma)^2 plus ((bearing(c) - b_s) /
///     sigma_b)^2, b_s the middle of the silhouette, sigma_b = angular_step
///     / sqrt(6) (each edge known within +-1 beam: the beam step and the
///     mixed pixel at the edge, uniform). The laser sees less than half of
///     a 4 cm circle, and the silhouette's edges, not the noisy ranges near
///     them, fix the centre across the line of sight: without that term
///     a single scan's centre was off by up to 5 cm sideways at 1 m (12 mm
///     range noise on 6-7 points). Gauss-Newton from the nearest point
///     moved R away along b_s; points whose residual exceeds
///     outlier_sigmas range_sigma are dropped and the circle fitted again.
///     Accepted: at least min_points points, residual RMS <= max_fit_rms,
///     the centre farther than the nearest point, not within a radius of
///     an accepted one. The centre's 2 x 2 covariance is range_sigma^2
///     (J^T J)^-1 of the fit.
///  2. association: until the filter has a pose (after Initialize and at
///     every rising edge of `active`: the robot may have moved while the
///     beacons were covered) by geometry alone: for every pair of
///     detections and every ordered pair of known beacons whose distances
///     agree within pair_tolerance, the laser pose that puts the pair on
///     the beacons; the other detections within match_distance of a beacon
///     join it; the hypothesis is refined by a least-squares rigid fit
///     (2D Procrustes) of its pairs. The most pairs win, then the lowest
///     RMS; hypotheses within 5 mm RMS of each other with different poses
///     (a symmetric layout: the van's rectangle of four beacons fits a pose
///     and its half-turn about the rectangle's centre equally) are decided
///     by heading_hint (the one whose yaw is nearer: any hint within 90
///     deg of the true yaw). At least min_beacons pairs start the filter
///     at that pose (P = diag(initial_sigma_position^2 x 2,
///     initial_sigma_yaw^2)). Afterwards each detection is associated with
///     the beacon nearest in Mahalanobis distance under the filter's
///     prediction, when below `gate` (chi-square, 2 dof), one detection
///     per beacon.
///  3. EKF over the robot pose [x, y, yaw]: a static robot (paper 2 takes
///     the pose once the robot stopped): prediction x unchanged, P +=
///     diag(q_p^2, q_p^2, q_yaw^2) dt (dt between scan starts; a random
///     walk of process_noise_position, process_noise_yaw per sqrt(s): the
///     robot settling on its tyres and the van on its suspension). Update:
///     sequentially per associated beacon, the observation the fitted
///     centre in the laser frame, h(x) = R(yaw + mount_yaw)^T (b - L(x)),
///     L the laser's position (mount_x, mount_y in base_link), noise the
///     fit's covariance (statistical error only: it averages over scans).
///
/// Systematic error: the LMS151's range error has a part fixed per device
/// (+-30 mm typical, SICK 8012471) that no averaging removes: every fitted
/// centre moves along its line of sight by it. The output covariance is the
/// filter's P plus systematic_sigma^2 g g^T, g the pose's sensitivity to a
/// common range offset under the last scan's geometry (g = I^-1 sum H_j^T
/// R_j^-1 u_j, u_j the line of sight, I the scan's information); the gate
/// adds systematic_sigma^2 along each line of sight.
///
/// The installation: the filter knows the beacons where they were surveyed,
/// which is not exactly where they stand: each surveyed coordinate is the
/// scene's plus survey_sigma N(0, 1), drawn once per installation (from
/// installation_seed when >= 0, so all runs of `--runs N` share one van
/// fit-out as paper 2's 20 runs did; else from the run's seed). Paper 2
/// (Sec. 6.1) states the system's accuracy as 5 mm and 0.2 deg; for four
/// beacons of a rectangle the pose's yaw error from independent survey
/// errors is survey_sigma / sqrt(sum_j |b_j - centroid|^2) and its position
/// error at the centroid survey_sigma / 2: see scenarios/van_entry.yaml for
/// the value this gives. The survey error is systematic for one
/// installation (no averaging over scans removes it) and is not in the
/// output covariance.
///
/// Outputs hold their last values while inactive; `valid` is 1 while
/// active, the filter started, and at least min_beacons distinct beacons
/// were associated within the last valid_scans scans. When no beacon was
/// associated for valid_scans scans in a row (the robot moved away from
/// the filter's pose: the unit assumes it stands), the filter restarts
/// from geometry. Allocation-free per scan (buffers sized in the
/// constructor).
class BeaconLocalizationUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "beacon_localization";
  /// Beacon candidates per scan beyond this are ignored.
  static constexpr int kMaxDetections = 64;
  static constexpr int kMaxBeacons = 64;

  struct Beacon {
    double x, y, radius;
  };
  /// A fitted beacon candidate of the last processed scan (laser frame).
  struct Detection {
    double x = 0, y = 0;               // centre (m)
    double cxx = 0, cxy = 0, cyy = 0;  // its covariance (m^2)
    double rms = 0;                    // fit residual RMS (m)
    int points = 0;                    // points in the final fit
    int first_beam = 0, last_beam = 0;
    int beacon = -1;  // associated known beacon, -1: none
  };

  /// The scene's obstacles of kind `beacon` (any shape; the factory
  /// refuses non-cylinders).
  static std::vector<const models::Obstacle*> SceneBeacons(const models::Scene& scene);

  /// `beacons`: any number (CheckParameters wants min_beacons..kMaxBeacons
  /// of one radius: a scene without them still builds for `inspect`);
  /// `beam_count` 1..100000 (throws cosim::UnitError otherwise).
  /// `seed`: the run's seed for this unit (the installation's survey
  /// errors when installation_seed < 0).
  BeaconLocalizationUnit(std::string name, std::vector<Beacon> beacons, int beam_count,
                         std::uint64_t seed = 0);

  /// The beacons as the installation's survey gives them (after Initialize).
  const std::vector<Beacon>& surveyed_beacons() const { return beacons_; }

  std::vector<cosim::ParameterProblem> CheckParameters() const override;
  void Setup(cosim::TimeNs start, cosim::TimeNs stop) override;
  void Initialize() override;
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

  int beam_count() const { return beam_count_; }
  /// The candidates of the last processed scan (scratch: not saved).
  const std::vector<Detection>& detections() const { return detections_; }
  int detection_count() const { return detection_count_; }
  /// Whether the filter has a pose since the last activation.
  bool started() const { return started_; }
  /// The filter's state [x, y, yaw] and covariance (row-major, without the
  /// systematic part).
  const std::array<double, 3>& state() const { return x_; }
  const std::array<double, 9>& filter_covariance() const { return p_; }

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  void Derive();
  void ProcessScan();
  /// Clusters the scan and fits the candidates into detections_.
  void Detect();
  /// Fits a circle of radius_ to points [first, end) of px_/py_ with
  /// use_[i] and its centre to the silhouette's `bearing`; false when
  /// singular. Writes centre, covariance, rms, count.
  bool FitCircle(int first, int end, double bearing, Detection& d);
  /// Geometric association of detections_; true and the laser pose when at
  /// least min_beacons agree.
  bool AssociateByGeometry(std::array<double, 3>& laser_pose);
  /// Gated association under the filter's prediction.
  void AssociateByPrediction();
  /// Detection k takes beacon j at squared distance d2 unless another
  /// detection holds it nearer (one detection per beacon: the nearer wins).
  void Claim(int k, int j, double d2);
  /// Calls f(detection, its beacon) for each associated detection, in order.
  template <typename F>
  void ForEachPair(F f) const {
    for (int k = 0; k < detection_count_; ++k) {
      const Detection& d = detections_[static_cast<std::size_t>(k)];
      if (d.beacon >= 0) f(d, beacons_[static_cast<std::size_t>(d.beacon)]);
    }
  }
  /// The EKF update with the associated detections; their count.
  int Update();
  /// Predicted laser-frame position of beacon j and its 2 x 3 Jacobian.
  void Observe(int j, std::array<double, 2>& z, std::array<double, 6>& h) const;
  void PublishOutputs();

  std::vector<Beacon> scene_beacons_;  // where they stand
  std::vector<Beacon> beacons_;        // where the survey puts them (the filter's)
  int beam_count_;
  std::uint64_t seed_;
  double radius_ = 0.0;
  std::vector<double> beacon_distance_;  // N x N

  // Parameters.
  double mount_x_, mount_y_, mount_yaw_, first_beam_angle_, angular_step_;
  double range_min_ = 0.5, range_max_ = 18.0;
  double range_sigma_ = 0.012, systematic_sigma_ = 0.015;
  double flank_margin_ = 0.0;
  std::int64_t edge_trim_ = 1, min_points_ = 3, min_beacons_ = 3, valid_scans_ = 5;
  double max_fit_rms_ = 0.03, outlier_sigmas_ = 3.0;
  double pair_tolerance_ = 0.06, match_distance_ = 0.1, gate_ = 13.8;
  double heading_hint_ = 0.0;
  double uncover_delay_ = 1.0;
  double process_noise_position_ = 0.001, process_noise_yaw_ = 0.001;
  double initial_sigma_position_ = 0.1, initial_sigma_yaw_ = 0.1;
  double survey_sigma_ = 0.0;
  std::int64_t installation_seed_ = -1;

  // Inputs.
  std::vector<double> ranges_;
  double scan_count_ = 0.0, scan_time_ = 0.0;
  bool active_ = true;
  // Outputs.
  std::vector<double> position_, covariance_;
  double yaw_ = 0.0;
  bool valid_ = false;
  std::int64_t beacons_seen_ = 0, scans_used_ = 0;

  // Derived: per beam, cos and sin of its angle in the laser frame.
  std::vector<double> cos_a_, sin_a_;

  // Scratch (sized in the constructor).
  std::vector<double> px_, py_;
  std::vector<char> valid_beam_;  // a usable return
  std::vector<char> use_;         // in the fit
  std::vector<Detection> detections_;
  int detection_count_ = 0;
  std::vector<int> beacon_taken_;  // per beacon: the detection, -1
  std::vector<double> beacon_d2_;  // per beacon: its detection's distance^2

  // State.
  cosim::TimeNs start_ = 0;
  double last_count_ = 0.0;
  double last_scan_time_ = 0.0;
  bool was_active_ = false;
  cosim::TimeNs active_since_ns_ = 0;  // the last rising edge of `active`
  bool started_ = false;
  std::array<double, 3> x_{};
  std::array<double, 9> p_{};
  std::int64_t scan_index_ = 0;                 // scans processed while active
  std::vector<std::int64_t> beacon_last_scan_;  // per beacon: its last association's scan_index_
  std::array<double, 3> g_{};                   // sensitivity of the pose to a common range offset
};

}  // namespace linesim::evaluation
