#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "cosim/master.h"
#include "cosim/observers.h"
#include "models/scene.h"
#include "replay/replay_data.h"

namespace linesim::loader {
struct Scenario;
}
namespace linesim::sensors {
class LaserScannerUnit;
}

/// The replay of a robot run: one self-contained HTML page (replay.html)
/// that plays the run's top view in a browser, beside its main plots.
namespace linesim::replay {

/// How densely the replay samples the run. The page interpolates nothing:
/// it shows the last sample at or before the slider's time.
struct ReplayRates {
  /// Robot pose, wheels, belts and plotted signals: 50 Hz (every 20 ms),
  /// ten samples over the 0.2 s a robot at 0.3 m/s needs to travel 6 cm.
  cosim::TimeNs frame_interval = cosim::kNsPerSecond / 50;
  /// Laser scans: every scan completed at least this long after the last
  /// kept one: 10 Hz, a quarter of the S300's 25 scans/s.
  cosim::TimeNs scan_interval = cosim::kNsPerSecond / 10;
};

/// What the replay shows, as probes into the running system and the
/// scene; ReplaySpecFor builds it from a loaded robot scenario.
struct ReplaySpec {
  std::string title, description;
  std::string task;  // path, hold or route
  models::Scene scene;
  std::vector<std::array<double, 2>> path;
  double body_length_m = 0.0, body_width_m = 0.0;
  cosim::Probe x, y, yaw;
  /// Per wheel: contact point x, y (map) and the surface code under it.
  std::vector<std::array<cosim::Probe, 2>> wheels;
  std::vector<cosim::Probe> wheel_surface;
  /// Per scene belt: travel (m) and on state.
  std::vector<cosim::Probe> belt_travel, belt_on;
  /// A plot of the page: a title, its unit, an optional bound (drawn as a
  /// dashed line at +bound), and its curves.
  struct Curve {
    std::string label;
    cosim::Probe probe;
  };
  struct Plot {
    std::string title;
    std::string unit;
    double bound = 0.0;
    std::string bound_label;
    std::vector<Curve> curves;
  };
  std::vector<Plot> plots;
  struct Laser {
    std::string name;
    const sensors::LaserScannerUnit* unit = nullptr;
    /// Its beams and the farthest range it can report (for the page's size
    /// bound: twice range_max, plus its bias and ten sigmas of its noise).
    std::size_t beams = 0;
    double farthest_m = 0.0;
  };
  std::vector<Laser> lasers;
  /// What else moves on the floor: a fleet's other robots (a box, with
  /// yaw) and the workers (a circle of `radius_m`), drawn at their poses.
  struct Mover {
    std::string name;
    bool robot = false;
    cosim::Probe x, y, yaw;  // yaw: robots only
    double length_m = 0.0, width_m = 0.0, radius_m = 0.0;
  };
  std::vector<Mover> movers;
  ReplayRates rates;
};

/// The replay of `s` (a robot scenario, built, not yet started): the scene,
/// the robot's body and wheels, every laser scanner unit of the system, and
/// the plots of its deviation (with `bound_m`, `bound_label`), surface
/// velocity (raw, filtered, truth, when recorded) and motor currents.
/// Throws cosim::ConfigError if a column the robot expansion names does
/// not resolve.
ReplaySpec ReplaySpecFor(const loader::Scenario& s, double bound_m, const std::string& bound_label);

/// The most bytes replay.html of `spec` can take for a run from `start` to
/// `stop`: the template, every text escaped at its longest (6 bytes a
/// byte), one frame every frame interval and one scan per laser every scan
/// interval with every number at kMaxNumberBytes, a range at the laser's
/// farthest (Laser::farthest_m). Known before the run (RunIntoFolder checks it
/// against --max-output-mb).
std::uint64_t ReplayBytesBound(const ReplaySpec& spec, cosim::TimeNs start, cosim::TimeNs stop);

/// Samples the run for the replay (an observer of the master) into a
/// ReplayData and writes the page. Sampling reads a few variables per base
/// step and copies a scan's ranges at the scan rate; everything else
/// happens in Write.
class ReplayRecorder : public cosim::Observer {
 public:
  explicit ReplayRecorder(ReplaySpec spec);
  void OnStart(const cosim::Master& master) override;
  void OnSample(cosim::TimeNs t, const cosim::System& system) override;

  /// How the run ended (the page shows a banner unless ok).
  void SetOutcome(ReplayData::Outcome outcome) { data_.outcome = std::move(outcome); }
  const ReplayData& data() const { return data_; }
  /// The page's data as JSON text (DataJson).
  std::string DataJson() const { return replay::DataJson(data_); }
  /// The whole page (PageHtml).
  std::string Html() const { return PageHtml(data_); }
  /// Writes Html() to `path` (atomically); throws std::runtime_error when it
  /// cannot be written.
  void Write(const std::string& path) const;
  std::int64_t frames() const { return static_cast<std::int64_t>(data_.t.size()); }

 private:
  struct Pose {
    cosim::TimeNs t;
    double x, y, yaw;
  };
  ReplaySpec spec_;
  ReplayData data_;
  cosim::TimeNs next_frame_ = 0;
  // Lasers: their last seen scan count and the time after which a scan is
  // kept.
  std::vector<double> last_count_;
  std::vector<cosim::TimeNs> next_scan_;
  // The robot's pose over the last base steps (a ring): a scan is drawn
  // from the pose at its start, up to a scan period back.
  std::array<Pose, 64> history_{};
  std::size_t history_count_ = 0;
};

}  // namespace linesim::replay
