#include <cmath>
#include <string>

#include "cosim/time.h"
#include "loader/assembly/concerns.h"

namespace linesim::loader::assembly {

namespace {

// Raw optic flow against the belt's ground truth (paper 1 Fig. 4), when
// both are there.
void AddFlowError(SystemBuilder& b, Signals& s, RobotInfo& info) {
  std::vector<const models::SensorMount*> flows;
  for (const auto& sensor : s.sensors) {
    if (sensor.kind == "px4flow") flows.push_back(&sensor);
  }
  if (!flows.empty() && !s.belt_ground_truth.empty()) {
    b.Unit(kFlowError, "surface_velocity_error");
    Parameters& p = b.Params(kFlowError);
    p["sensors"] = static_cast<int>(flows.size());
    p["belt"] = s.belt_ground_truth_belt;
    if (!s.surface_estimate.empty()) p["estimated"] = true;
    std::vector<double> x, y, yaw;
    for (std::size_t k = 0; k < flows.size(); ++k) {
      x.push_back(flows[k]->x_m);
      y.push_back(flows[k]->y_m);
      yaw.push_back(flows[k]->yaw_rad);
      for (std::size_t i = 0; i < 2; ++i) {
        b.Connect(Element(flows[k]->name, "velocity", i),
                  Element(kFlowError, "measured", 2 * k + i));
      }
    }
    p["mount_x"] = x;
    p["mount_y"] = y;
    p["mount_yaw"] = yaw;
    b.Connect(s.true_position, Signal(kFlowError, "position"));
    b.Connect(s.true_yaw, Signal(kFlowError, "yaw"));
    b.Connect(Signal(kChassis, "linear_velocity"), Signal(kFlowError, "linear_velocity"));
    b.Connect(Signal(kChassis, "yaw_rate"), Signal(kFlowError, "yaw_rate"));
    b.Connect(s.belt_ground_truth, Signal(kFlowError, "reference"));
    s.recorded.push_back(Signal(kFlowError, "reading"));
    s.recorded.push_back(Signal(kFlowError, "true_reading"));
    b.Metric("surface_velocity_rmse_raw_mps", Signal(kFlowError, "rmse"), cosim::Reduction::kFinal);
    b.Metric("surface_velocity_plateau_rmse_raw_mps", Signal(kFlowError, "rmse_plateau"),
             cosim::Reduction::kFinal);
    b.Metric("surface_velocity_on_rmse_raw_mps", Signal(kFlowError, "rmse_plateau_on"),
             cosim::Reduction::kFinal);
    if (!s.surface_estimate.empty()) {
      // The surface estimator's filtered value per sensor, the same order.
      b.Connect(s.surface_estimate, Signal(kFlowError, "estimated"));
      s.recorded.push_back(Signal(kFlowError, "estimated_speed"));
      b.Metric("surface_velocity_rmse_filtered_mps", Signal(kFlowError, "rmse_estimated"),
               cosim::Reduction::kFinal);
      b.Metric("surface_velocity_plateau_rmse_filtered_mps",
               Signal(kFlowError, "rmse_plateau_estimated"), cosim::Reduction::kFinal);
      b.Metric("surface_velocity_on_rmse_filtered_mps",
               Signal(kFlowError, "rmse_plateau_on_estimated"), cosim::Reduction::kFinal);
      b.Metric("surface_velocity_settling_time_s", Signal(kFlowError, "settling_time"),
               cosim::Reduction::kFinal);
    }
    // The first sensor's quality (0..255, OPTICAL_FLOW_RAD's mean over its
    // publishing interval), over the run.
    b.Metric("optic_flow_quality_mean", Signal(flows.front()->name, "quality"),
             cosim::Reduction::kMean);
    for (std::size_t k = 0; k < flows.size(); ++k) {
      info.flow_columns.push_back(Element(kFlowError, "reading", k).Name());
      info.flow_truth_columns.push_back(Element(kFlowError, "true_reading", k).Name());
      info.flow_sensor_names.push_back(flows[k]->name);
      if (!s.surface_estimate.empty()) {
        info.flow_filtered_columns.push_back(Element(kFlowError, "estimated_speed", k).Name());
      }
    }
    info.flow_reference_column = s.belt_ground_truth.Name();
  }
}

// The final approach's demand on the drives: the peak absolute current of
// any drive motor over the path's last 2 m (a sticking skid-steer winds its
// currents up there; steady motion needs the rolling resistance's and the
// stop's share).
void AddEndCurrent(SystemBuilder& b, const Signals& s) {
  if (s.drive_motor_element.empty()) return;
  b.Unit(kEndCurrent, "end_peak");
  Parameters& p = b.Params(kEndCurrent);
  p["count"] = static_cast<int>(s.drive_motor_element.size());
  p["window"] = 2.0;
  for (std::size_t k = 0; k < s.drive_motor_element.size(); ++k) {
    b.Connect(Element(kMotors, "current", s.drive_motor_element[k]),
              Element(kEndCurrent, "values", k));
  }
  b.Connect(Signal(kDeviation, "remaining"), Signal(kEndCurrent, "remaining"));
  b.Metric("peak_drive_current_last_2m_a", Signal(kEndCurrent, "peak"), cosim::Reduction::kFinal);
}

}  // namespace

void AddEvaluation(SystemBuilder& b, const models::RobotDescription& robot, Signals& s,
                   RobotInfo& info) {
  // The deviation is measured on the ground truth, whatever the robot
  // believes.
  b.Unit(kDeviation, "path_deviation");
  b.Params(kDeviation)["path"] = info.path;
  b.Connect(s.true_position, Signal(kDeviation, "position"));
  s.recorded.push_back(Signal(kDeviation, "deviation"));

  // The scenario's own metrics first.
  ReadMetrics(Child(b.root(), "metrics"), b.reader(), b.spec());
  const auto add = [&](const std::string& name, const Port& of, cosim::Reduction reduce) {
    b.Metric(name, of, reduce);
  };
  const Port deviation = Signal(kDeviation, "deviation");
  if (info.task != "hold") {  // a path or a route
    add("max_path_deviation_m", deviation, cosim::Reduction::kMax);
    add("final_path_deviation_m", deviation, cosim::Reduction::kFinal);
    add("final_progress_m", Signal(kDeviation, "progress"), cosim::Reduction::kFinal);
    // Paper 1's criterion for its crossing (path_deviation.h): within 4 cm
    // all the way, and across (not for a route: paper 2 has its own).
    if (info.task == "path") {
      add("crossing_success", Signal(kDeviation, "success"), cosim::Reduction::kFinal);
    }
    AddEndCurrent(b, s);
  } else {
    add("max_position_drift_m", deviation, cosim::Reduction::kMax);
    add("final_position_drift_m", deviation, cosim::Reduction::kFinal);
    add("hold_success", Signal(kDeviation, "success"), cosim::Reduction::kFinal);
  }
  add("final_yaw_rad", s.true_yaw, cosim::Reduction::kFinal);

  // Clearance of the robot's body from everything in the scene (FCL).
  const models::BodyDescription& body = robot.body;
  b.Unit(kClearance, "clearance");
  Parameters& c = b.Params(kClearance);
  c["body_length"] = body.length_m;
  c["body_width"] = body.width_m;
  c["body_height"] = body.height_m;
  // The body box where the robot file puts it (the chassis's).
  c["body_bottom"] = body.bottom_m;
  b.Connect(Signal(kChassis, "position_3d"), Signal(kClearance, "position_3d"));
  b.Connect(Signal(kChassis, "orientation"), Signal(kClearance, "orientation"));
  if (s.belt_count > 0) b.Connect(Signal(kBelt, "travel"), Signal(kClearance, "belt_travel"));
  s.recorded.push_back(Signal(kClearance, "clearance"));
  add("min_clearance_m", Signal(kClearance, "min_clearance"), cosim::Reduction::kFinal);
  add("collisions", Signal(kClearance, "collisions"), cosim::Reduction::kFinal);

  // Paper 2 Table 1: the final pose against the route's end (the work
  // pose), from the truth and from the beacons.
  if (!s.route_end.empty()) {
    b.Unit(kFinalPose, "final_pose_error");
    Parameters& f = b.Params(kFinalPose);
    f["target_x"] = s.route_end[0];
    f["target_y"] = s.route_end[1];
    f["target_yaw"] = s.route_end[2];
    f["beacons"] = !s.beacon_unit.empty();
    b.Connect(s.true_position, Signal(kFinalPose, "position"));
    b.Connect(s.true_yaw, Signal(kFinalPose, "yaw"));
    b.Connect(s.route_done, Signal(kFinalPose, "done"));
    add("final_error_x_m", Signal(kFinalPose, "error_x"), cosim::Reduction::kFinal);
    add("final_error_y_m", Signal(kFinalPose, "error_y"), cosim::Reduction::kFinal);
    add("final_error_yaw_deg", Signal(kFinalPose, "error_yaw"), cosim::Reduction::kFinal);
    if (!s.beacon_unit.empty()) {
      b.Connect(Signal(s.beacon_unit, "position"), Signal(kFinalPose, "beacon_position"));
      b.Connect(Signal(s.beacon_unit, "yaw"), Signal(kFinalPose, "beacon_yaw"));
      b.Connect(Signal(s.beacon_unit, "valid"), Signal(kFinalPose, "beacon_valid"));
      add("beacon_error_x_m", Signal(kFinalPose, "beacon_error_x"), cosim::Reduction::kFinal);
      add("beacon_error_y_m", Signal(kFinalPose, "beacon_error_y"), cosim::Reduction::kFinal);
      add("beacon_error_yaw_deg", Signal(kFinalPose, "beacon_error_yaw"), cosim::Reduction::kFinal);
      add("beacon_self_error_position_m", Signal(kFinalPose, "beacon_self_error_position"),
          cosim::Reduction::kFinal);
      add("beacon_self_error_yaw_deg", Signal(kFinalPose, "beacon_self_error_yaw"),
          cosim::Reduction::kFinal);
    }
  }

  // The localization the controllers use against the truth, when it is not
  // the truth itself.
  if (s.position != s.true_position) {
    b.Unit(kLocalizationError, "pose_error");
    b.Connect(s.true_position, Signal(kLocalizationError, "true_position"));
    b.Connect(s.true_yaw, Signal(kLocalizationError, "true_yaw"));
    b.Connect(s.position, Signal(kLocalizationError, "estimated_position"));
    b.Connect(s.yaw, Signal(kLocalizationError, "estimated_yaw"));
    s.recorded.push_back(Signal(kLocalizationError, "position_error"));
    s.recorded.push_back(Signal(kLocalizationError, "yaw_error"));
    add("localization_error_max_m", Signal(kLocalizationError, "max_position_error"),
        cosim::Reduction::kFinal);
    add("localization_error_rms_m", Signal(kLocalizationError, "rms_position_error"),
        cosim::Reduction::kFinal);
    add("localization_yaw_error_max_rad", Signal(kLocalizationError, "max_yaw_error"),
        cosim::Reduction::kFinal);
    add("localization_yaw_error_rms_rad", Signal(kLocalizationError, "rms_yaw_error"),
        cosim::Reduction::kFinal);
    // The error while the robot is on each slope of the scene (a terrain
    // piece with a pitch or a roll: paper 2's ramp): the truth's base_link
    // inside the piece's footprint.
    for (const models::TerrainPiece& t : b.spec().scene.terrain) {
      if (t.pitch_rad == 0.0 && t.roll_rad == 0.0) continue;
      const std::string unit = "localization_error_on_" + t.name;
      b.Unit(unit, "pose_error");
      Parameters& r = b.Params(unit);
      const auto axes = models::TerrainAxes(t);
      const double h = 0.5 * t.thickness_m;
      r["region_x"] = t.center_x_m + h * axes[2][0];
      r["region_y"] = t.center_y_m + h * axes[2][1];
      r["region_yaw"] = t.yaw_rad;
      r["region_length"] = t.length_m * std::cos(t.pitch_rad);
      r["region_width"] = t.width_m * std::cos(t.roll_rad);
      b.Connect(s.true_position, Signal(unit, "true_position"));
      b.Connect(s.true_yaw, Signal(unit, "true_yaw"));
      b.Connect(s.position, Signal(unit, "estimated_position"));
      b.Connect(s.yaw, Signal(unit, "estimated_yaw"));
      add(unit + "_max_m", Signal(unit, "max_position_error"), cosim::Reduction::kFinal);
      add(unit + "_rms_m", Signal(unit, "rms_position_error"), cosim::Reduction::kFinal);
    }
    // The share of the run the localization spent on its fallback (source 1).
    for (const Port& source : s.localization_sources) {
      add(source.unit + "_fallback_fraction", source, cosim::Reduction::kMean);
    }
  }

  AddFlowError(b, s, info);
  info.error_column = deviation.Name();
}

void AddRecording(SystemBuilder& b, const Signals& s, RobotInfo& info) {
  // The columns the plots read, as the recorder names them.
  info.x_column = Element(kChassis, "position", 0).Name();
  info.y_column = Element(kChassis, "position", 1).Name();
  info.yaw_column = Signal(kChassis, "yaw").Name();
  if (s.terrain) info.z_column = Element(kChassis, "position_3d", 2).Name();
  for (std::size_t w = 0; w < static_cast<std::size_t>(info.wheel_count); ++w) {
    info.wheel_columns.emplace_back(Element(kChassis, "wheel_contact", 2 * w).Name(),
                                    Element(kChassis, "wheel_contact", 2 * w + 1).Name());
  }
  info.wheel_surface_column = Signal(kChassis, "wheel_surface").Name();
  info.motor_current_column = Signal(kMotors, "current").Name();
  info.scan_unit = s.scan_unit;
  info.scan_time_s = s.scan_time_s;
  info.scan_geometry = s.scan_geometry;
  for (std::size_t k = 0; k < s.belt_count; ++k) {
    info.belt_speed_columns.push_back(Element(kBelt, "speed", k).Name());
    info.belt_on_columns.push_back(Element(kBelt, "on", k).Name());
    info.belt_travel_columns.push_back(Element(kBelt, "travel", k).Name());
  }
  std::vector<std::string> recorded;
  for (const Port& p : s.recorded) recorded.push_back(p.Name());
  AddRecordingSection(b, recorded);
}

void AddRecordingSection(SystemBuilder& b, const std::vector<std::string>& recorded) {
  SystemSpec& spec = b.spec();
  const YAML::Node own = Child(b.root(), "recording");
  if (own.IsDefined()) {
    // The scenario's recording, with the columns the plots read added to a
    // list it gives (a column is recorded once); without a list it records
    // everything anyway.
    ReadRecording(own, b.reader(), spec);
    if (spec.recording && spec.recording->variables) {
      for (const auto& v : recorded) spec.recording->variables->push_back({v, YAML::Node()});
    }
    return;
  }
  RecordingSpec& rec = spec.recording.emplace();
  rec.variables.emplace();
  for (const auto& v : recorded) rec.variables->push_back({v, YAML::Node()});
  // About 100 Hz is enough for the plots and keeps signals.csv small; it
  // must be a whole number of master steps (the master refuses bad steps).
  constexpr cosim::TimeNs kInterval = cosim::kNsPerSecond / 100;
  const cosim::TimeNs step = b.MasterStep();
  rec.interval = step < kInterval ? (kInterval + step - 1) / step * step : step;
}

}  // namespace linesim::loader::assembly
