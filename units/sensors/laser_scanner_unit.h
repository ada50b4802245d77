#pragma once

#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"
#include "models/scene.h"
#include "units/sensors/ray_scene.h"

namespace linesim::sensors {

/// A 2D time-of-flight laser scanner (SICK S300, LMS151: models/sensors/),
/// cast in 3D against the scene (RayScene, Embree).
///
/// Frames: the scanner frame is mounted in base_link at (mount_x, mount_y,
/// mount_z) with roll, pitch, yaw (R = Rz(yaw) Ry(pitch) Rx(roll)); beam i
/// leaves along (cos a_i, sin a_i, 0) of the scanner frame, a_i =
/// first_beam_angle + i * angular_step (counter-clockwise seen from +z).
///
/// Timing: the mirror turns once per scan_period; scan k starts at start +
/// k * scan_period and beam i is measured at scan start + i * angular_step /
/// (2 pi) * scan_period (rounded to the nanosecond): the S300's 541 beams
/// take 30 of its 40 ms. The unit steps with the physics; in each step it
/// casts the beams whose time falls in [t, t + dt), with the base pose
/// extrapolated from the inputs at t to the beam time (velocity_3d in map,
/// angular_velocity in base_link: q(t + s) = q(t) exp(w s / 2)) and each
/// carried object where its belt's travel + speed * s puts it.
///
/// Range (per beam, in this order):
///  1. the first hit of the centre ray (exact, double precision);
///  2. spot and mixed pixels: the beam's spot has the diameter
///     range * spot_divergence + spot_offset. Where two neighbouring beams
///     meet different objects, or hit and miss, or differ by more than
///     echo_separation, each of the two is sampled across its spot in the
///     scan plane at 5 points (-h, -h/2, 0, h/2, h, h the half angle of the
///     spot): the two on the side of the edge are cast, those on the far
///     side are taken as the centre (one edge per half spot). Each sample
///     returns energy cos(incidence) / range^2 (a Lambertian target of
///     uniform remission, the sample covers a fifth of the spot). Samples
///     are grouped by range (a gap above echo_separation starts a new echo:
///     the receiver cannot separate pulses closer than that); the device
///     reports the first echo (the nearest group), at the energy-weighted
///     mean range of its samples: a mixed pixel between the edges when
///     they are closer than echo_separation, else the nearer surface.
///  3. no return when the echo is beyond range_max, nearer than range_min,
///     or its incidence angle exceeds max_incidence (the energy of a
///     Lambertian return falls with cos(incidence); see the model files);
///  4. noise: + bias (drawn once per device, N(0, bias_sigma) clamped to
///     +-bias_max; the device is the run's own unless device_seed names
///     one: see Randomness) + N(0, noise_sigma), then rounded to range_resolution
///     (never below 0).
/// A beam without return reads no_return_value (what the device reports).
///
/// Protective field (only when the structural key `protective_field` gives
/// a polygon, in the scanner frame, m): a scan infringes the field when any
/// beam's reported point (r cos a_i, r sin a_i) lies inside the polygon;
/// field_clear goes to 0 after multiple_sampling consecutive infringing
/// scans (the S300's multiple sampling: an object must be detected that
/// many times in succession, at least 2), and back to 1 after a scan that
/// does not infringe (no restart interlock).
///
/// Randomness: one std::mt19937_64 seeded with the constructor's seed: the
/// bias first, then one normal per returning beam, beam after beam (normals
/// by Marsaglia and Tsang's ziggurat: the generator's state is all there is
/// to save). The bias is a property of the physical unit, not of a run:
/// with device_seed >= 0 it is drawn instead from a generator seeded by
/// (device_seed, the unit's name), so every run of `--runs N` (each with
/// its own seed) uses the same scanner, as an experiment's repetitions do
/// (paper 2's 20 runs: one LMS151); another device_seed is another unit
/// off the line. The run's stream is unchanged by it (the constructor's
/// draw is still taken).
class LaserScannerUnit : public cosim::Unit {
 public:
  static constexpr const char* kTypeName = "laser_scanner";
  static constexpr int kSpotSamples = 5;

  /// `protective_field`: the polygon's corners [x, y] in the scanner frame
  /// (at least 3), or empty for none. Throws cosim::UnitError if beam_count
  /// < 1 or the polygon has 1 or 2 corners.
  /// `moving_cylinders` > 0 adds the input `moving_cylinders` (7 numbers per
  /// cylinder: [x, y, vx, vy, radius, z_bottom, z_top] in map, m and m/s:
  /// workers' legs and torsos, people::WorkerUnit's `cylinders`): each is
  /// seen at a beam's time where its velocity takes it from the inputs' time
  /// (RayScene::Cast), with no extra rays.
  LaserScannerUnit(std::string name, const models::Scene& scene, int beam_count,
                   std::vector<std::array<double, 2>> protective_field, std::uint64_t seed,
                   int moving_cylinders = 0, int moving_boxes = 0);

  std::vector<cosim::ParameterProblem> CheckParameters() const override;
  void Setup(cosim::TimeNs start, cosim::TimeNs stop) override;
  void Initialize() override;
  cosim::StepResult DoStep(cosim::TimeNs t, cosim::TimeNs dt) override;

  int beam_count() const { return beam_count_; }
  /// The per-device range bias (m; after Initialize): from device_seed when
  /// it is >= 0, else from the run's seed.
  double bias() const { return bias_; }
  /// Time of beam i after its scan's start (ns).
  cosim::TimeNs BeamOffset(int i) const { return beam_offset_ns_[static_cast<std::size_t>(i)]; }
  /// Whether the point (x, y) of the scanner frame is inside the field.
  bool InField(double x, double y) const;

  /// What an observer needs to draw the scans (replay/): the mount in
  /// base_link (x, y, yaw), the beams' angles in the scanner frame (first +
  /// i * step) and the range that means no echo; the parameters as the
  /// scenario set them.
  struct BeamGeometry {
    double mount_x_m, mount_y_m, mount_yaw_rad, first_beam_rad, beam_step_rad, no_return_m;
  };
  BeamGeometry beam_geometry() const {
    return {mount_x_, mount_y_, mount_yaw_, first_beam_angle_, angular_step_, no_return_value_};
  }
  /// The last complete scan (the outputs ranges, scan_time, scan_count).
  const std::vector<double>& ranges() const { return ranges_; }
  double scan_time_s() const { return scan_time_; }
  double scan_count() const { return scan_count_; }

 protected:
  void SaveInternal(cosim::UnitState& state) const override;
  void RestoreInternal(const cosim::UnitState& state) override;

 private:
  struct Sample {
    double range;  // +inf: no hit
    double energy;
    double cos_incidence;
  };
  void Derive();
  /// Casts beams [first, end) of the current scan, all inside the step
  /// starting at t (the inputs' time).
  void CastBeams(int first, int end, cosim::TimeNs t);
  /// Beam i's ray, s seconds after the step's start, into beam_rays_[i];
  /// stores its in-plane perpendicular. sn, vc: sin(w s), 1 - cos(w s).
  void BeamRay(int i, double s, double sn, double vc);
  /// The step's pose terms from the inputs (see the .cc).
  void PrepareStep();
  /// The edge between beams i - 1 and i: its four spot samples' rays
  /// (sub[0..4)), then their hits into the two beams' samples.
  void PrepareEdge(int i, Ray* sub) const;
  void ApplyEdge(int i, const RayHit* hit);
  /// The reported ranges of beams [first, end) into scan_ranges_.
  void Finalize(int first, int end);
  /// The first echo of a spot's samples: its range and best incidence cosine.
  void MixEcho(const std::array<Sample, kSpotSamples>& samples, double& r, double& cos_inc) const;
  void CompleteScan();
  double Normal();
  /// A standard normal from `rng` (the ziggurat of Normal()).
  static double NormalFrom(std::mt19937_64& rng);

  int beam_count_;
  bool has_field_;
  std::vector<std::array<double, 2>> field_;
  RayScene rays_;
  std::mt19937_64 rng_;

  // Parameters.
  double mount_x_ = 0, mount_y_ = 0, mount_z_ = 0, mount_roll_ = 0, mount_pitch_ = 0,
         mount_yaw_ = 0;
  double scan_period_, first_beam_angle_, angular_step_, range_min_, range_max_,
      range_resolution_, noise_sigma_, bias_sigma_ = 0.0, bias_max_ = 0.0, max_incidence_,
      spot_divergence_ = 0.0, spot_offset_ = 0.0, echo_separation_, no_return_value_;
  // A fault to inject: no echo for beams measured in [blackout_from, blackout_until) s.
  double blackout_from_ = 0.0, blackout_until_ = 0.0;
  std::int64_t multiple_sampling_ = 2;

  // Inputs.
  std::vector<double> position_, orientation_, velocity_, angular_velocity_, belt_travel_,
      belt_speed_, moving_, moving_boxes_;
  std::int64_t own_box_ = -1;
  // Outputs.
  std::vector<double> ranges_;
  double scan_time_ = 0.0, scan_count_ = 0.0, field_clear_ = 1.0;

  // Derived (Derive()).
  std::vector<cosim::TimeNs> beam_offset_ns_;
  std::vector<double> cos_a_, sin_a_;
  std::vector<double> field_reach_;  // per beam: no point of the field farther along it
  cosim::TimeNs period_ns_ = 0;
  // The scanner's x and y axes and its origin in base_link.
  std::array<std::array<double, 3>, 3> mount_in_base_{};
  double cos_max_incidence_ = 0.0;
  // PrepareStep(): |angular_velocity|, and per vector (scanner x, y axes,
  // mount offset) R0 v, R0 (k x v), R0 (k x (k x v)).
  double rate_ = 0.0;
  std::array<std::array<std::array<double, 3>, 3>, 3> frame_{};

  // State of the scan under way.
  cosim::TimeNs start_ = 0, scan_start_ = 0;
  int next_beam_ = 0;    // first beam not yet cast
  int finalized_ = 0;    // beams [0, finalized_) have their reported range
  double bias_draw_ = 0.0;  // N(0, 1), drawn in the constructor
  std::int64_t device_seed_ = -1;  // < 0: the device is the run's (bias_draw_)
  double bias_ = 0.0;       // bias_draw_ * bias_sigma clamped to +-bias_max
  std::int64_t infringing_scans_ = 0;  // consecutive
  // Per beam of the scan under way: its ray, the centre hit, the spot
  // samples, and the reported range being built.
  std::vector<Ray> beam_rays_;
  std::vector<RayHit> centre_;
  std::vector<std::array<Sample, kSpotSamples>> samples_;
  std::vector<double> scan_ranges_;
  // Per beam: the scan plane's direction of increasing beam angle (map).
  std::vector<std::array<double, 3>> beam_perp_;
  // Per beam of the step being cast: its time after the step's start (s),
  // sin and 1 - cos of the base's turn by then.
  std::vector<double> step_s_, step_sin_, step_vers_;
  // The step's edges: the beam after each, their samples' rays and hits
  // (cast in one batch).
  std::vector<int> edge_beam_;
  std::vector<Ray> edge_rays_;
  std::vector<RayHit> edge_hits_;
  cosim::TimeNs step_t_ = 0;  // the inputs' time of the step being cast
};

}  // namespace linesim::sensors
