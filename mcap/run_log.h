#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "cosim/master.h"
#include "cosim/observers.h"
#include "loader/scenario.h"
#include "mcap/writer.h"

/// A linesim run as an MCAP log for Foxglove and PlotJuggler (run.mcap):
/// the mapping of a run onto Foxglove's channels, gathered during the run
/// by an observer on the master. JSON messages on Foxglove's JSON schemas:
///   /tf            foxglove.FrameTransforms at recorded rows (at most every
///                  signal_period): map -> base_link, the robot's pose as
///                  recorded; map -> belt/NAME, each belt's travel along it
///   /tf/mounts     once at the start: base_link -> every sensor unit's
///                  mount (units with mount_x, mount_y), frames named after
///                  the units
///   /scan/UNIT     foxglove.LaserScan of every laser_scanner unit: its last
///                  complete scan, at most one per scan_period, ranges to
///                  0.1 mm (coarser than any scanner's reporting step)
///   /scene/static  foxglove.SceneUpdate once at the start: floor, obstacles,
///                  terrain, the desired path, the robot (body and wheels, in
///                  base_link, following it)
///   /scene         foxglove.SceneUpdate at the start and when a belt starts
///                  or stops or an object leaves its belt (looked at every
///                  scene_period): the belts (colour by on state) and the
///                  objects on them, in their belt's frame (riding with it)
/// What is written once is on a topic of its own: a viewer that seeks shows
/// the last message of each topic before the new time.
///   /log           foxglove.Log once, at the end: how the run ended (ok,
///                  failed or interrupted, at what time of its stop time,
///                  and why); the same as metadata "linesim.run" (status,
///                  end_time_s, stop_time_s, message) in the summary
///   /signals/UNIT  one message per recorded row of signals.csv (at most
///                  every signal_period): the unit's
///                  recorded variables as fields (an array for elements
///                  0..n-1 of a Real array, else NAME_i), the same numbers
/// Times are simulation times (log_time = publish_time = t in ns): the same
/// scenario and seed give the same bytes.
namespace linesim::mcap {

struct RunLogOptions {
  /// /tf and /signals: every recorded row at most this often (25 Hz:
  /// every fourth row of a 100 Hz signals.csv); signals.csv keeps them all.
  cosim::TimeNs signal_period = 40'000'000;
  /// The lasers' messages: a new complete scan at most this often (5 Hz:
  /// every fifth scan of a 25 Hz LMS151 or S300).
  cosim::TimeNs scan_period = 200'000'000;
  /// How often the belts' on state and the carried objects' being on their
  /// belt are looked at (10 Hz).
  cosim::TimeNs scene_period = 100'000'000;
  WriterOptions writer;
};

/// How a run ended, as the log's last message and its metadata say it.
struct RunOutcome {
  std::string status = "ok";  // ok, failed or interrupted
  cosim::TimeNs end = 0;      // the time reached
  cosim::TimeNs stop = 0;     // the time the run was to reach
  std::string message;        // why, when not ok (or ended early)
};

class RunLog : public cosim::Observer {
 public:
  /// Reads what it needs of `scenario` (scene, robot, recorded probes,
  /// units); `out` receives the file and must outlive the log.
  RunLog(std::ostream& out, const loader::Scenario& scenario, RunLogOptions options = {});
  ~RunLog() override;

  /// The most bytes run.mcap of `scenario` can take (built, not yet run):
  /// every message at its longest (numbers at 24 characters, ranges up to
  /// twice the laser's range_max plus its bias and ten sigmas of its
  /// noise) at the most the rates allow over the
  /// scenario's duration, /scene at most once per belt switch and twice
  /// per carried object (a belt's travel runs one way: its speed varies by
  /// at most 50 %), the records' and indexes' overhead, the compressor's
  /// worst case (incompressible chunks) and the summary. Known before the
  /// run (RunIntoFolder checks it against --max-output-mb).
  static std::uint64_t BytesBound(const loader::Scenario& scenario,
                                  const RunLogOptions& options = {});

  void OnStart(const cosim::Master& master) override;
  void OnSample(cosim::TimeNs t, const cosim::System& system) override;
  /// Stops logging (nothing after the run's end).
  void OnEnd(cosim::TimeNs t, bool ok) override;
  /// Writes how the run ended (/log and the metadata) and closes the file
  /// (summary, footer). Without it the destructor closes the file, saying
  /// nothing of the end.
  void Close(const RunOutcome& outcome);

  std::uint64_t bytes() const { return writer_.bytes_written(); }
  std::uint64_t messages() const { return writer_.message_count(); }

 private:
  struct Signals {  // one channel per unit
    std::uint16_t channel = 0;
    struct Field {
      std::string name;
      bool array = false;
      std::vector<std::size_t> probes;  // indices into probes_
    };
    std::vector<Field> fields;
  };
  struct Laser {
    std::uint16_t channel = 0;
    std::size_t unit = 0;
    cosim::ValueRef ranges{}, scan_count{}, scan_time{};
    std::string head;  // the message's text from "frame_id" to "ranges":[
    std::size_t beams = 0;
    std::uint64_t range_bytes = 0;  // the longest text of a range, its comma included
    double last_count = 0;
    cosim::TimeNs next = 0;
  };
  struct Frame {  // a sensor's fixed mount in base_link, as JSON text
    std::string text;  // ,"parent_frame_id":...}  (after the timestamp)
  };
  struct Dynamic {  // a belt's travel and on state
    std::optional<cosim::Probe> travel, on;
    std::string frame;  // "belt/NAME": moved by the travel along the belt
  };

  /// The constructor's parts: a channel per laser scanner, and per unit
  /// with recorded variables.
  void AddLasers(const cosim::System& system);
  void AddSignals(const cosim::System& system);
  std::uint64_t Bound() const;
  /// The texts of /scene/static and /tf/mounts at time t ("" for none).
  std::string StaticText(cosim::TimeNs t) const;
  std::string MountsText(cosim::TimeNs t) const;
  /// The /scene message for `state` (each belt on, then each carried object
  /// on its belt: '1' or '0').
  std::string SceneText(cosim::TimeNs t, const std::string& state) const;
  void WriteStatic(cosim::TimeNs t);
  void WriteScene(cosim::TimeNs t, const cosim::System& system);
  void WriteTransforms(cosim::TimeNs t, const cosim::System& system);
  void WriteSignals(cosim::TimeNs t, const cosim::System& system);
  void WriteScans(cosim::TimeNs t, const cosim::System& system);

  Writer writer_;
  RunLogOptions options_;
  const loader::Scenario& scenario_;
  std::vector<cosim::Probe> probes_;
  cosim::TimeNs record_interval_ = 0;
  cosim::TimeNs start_ = 0;
  std::vector<Signals> signals_;
  std::vector<Laser> lasers_;
  std::vector<Frame> frames_;
  std::vector<Dynamic> belts_;
  // The robot: its recorded pose columns, and its chassis's 3D outputs.
  bool has_robot_ = false;
  std::optional<cosim::Probe> x_, y_, yaw_;
  std::optional<std::size_t> chassis_;
  std::optional<cosim::ValueRef> orientation_, position_3d_;
  // A fleet's other robots: frame NAME/base_link, moved by their chassis.
  struct OtherRobot {
    std::string name, frame;
    std::size_t chassis = 0;
    cosim::ValueRef position_3d = 0, orientation = 0;
    double length = 0.0, width = 0.0;
  };
  std::vector<OtherRobot> others_;
  std::uint16_t tf_channel_ = 0, mounts_channel_ = 0, static_channel_ = 0, scene_channel_ = 0,
                log_channel_ = 0;
  bool started_ = false;
  std::string scene_state_;  // belts on and objects on their belts, at the last /scene
  cosim::TimeNs next_scene_ = 0, next_signals_ = 0;
  std::string text_;  // a message being written
  bool ended_ = false, closed_ = false;
};

}  // namespace linesim::mcap
