#include <cmath>
#include <functional>
#include <map>
#include <optional>

#include "loader/assembly/concerns.h"
#include "loader/yaml_files.h"

namespace linesim::loader::assembly {

namespace {

// What a provider needs besides the builder: the robot, its start pose,
// and where the scenario chose it (for errors).
struct ProviderContext {
  const RobotFile& file;
  const StartPose& start;
  const models::Scene& scene;
  YAML::Node at;     // the section the choice is in
  std::string path;  // its key path
};

using Provider = std::function<void(SystemBuilder&, const ProviderContext&, Signals&)>;

// The mounts of one kind the scenario left on.
std::vector<const models::SensorMount*> Mounts(const Signals& s, const std::string& kind) {
  std::vector<const models::SensorMount*> out;
  for (const auto& m : s.sensors) {
    if (m.kind == kind) out.push_back(&m);
  }
  return out;
}

// A provider that needs a kind of sensor the scenario turned off (or the
// robot does not carry) says so at the key that chose it.
bool Require(SystemBuilder& b, const ProviderContext& c, const Signals& s, const std::string& kind,
             const std::string& choice) {
  if (!Mounts(s, kind).empty()) return true;
  b.reader().Error(c.at, c.path,
                   "'" + choice + "' needs the robot's " + kind + " sensors, but " +
                       (RobotHas(c.file.robot, kind) ? "the scenario's sensors: section turns "
                                                       "them off"
                                                     : c.file.robot.file + " mounts none"));
  return false;
}

void SetStep(SystemBuilder& b, const std::string& unit) {
  b.SetStep(unit, b.ControlPeriod());
  b.Derived(JoinPath(JoinPath("units", unit), "step_s"), Child(b.root(), "control"), "control",
            "period_s");
}

void SetInitialPose(YAML::Node p, const StartPose& start) {
  p["initial_x"] = Num(start.x_m);
  p["initial_y"] = Num(start.y_m);
  p["initial_yaw"] = Num(start.yaw_rad);
}

// The numbers of one sensor unit's parameters as the unit will get them:
// the scenario's or the robot's setting if the expansion has one, else the
// device's model file (the mount's or the scenario's `model`, read once).
class DeviceNumbers {
 public:
  DeviceNumbers(SystemBuilder& b, const ProviderContext& c, const models::SensorMount& m)
      : b_(b), c_(c), m_(m), params_(b.Params(m.name)) {
    const YAML::Node model_name = Child(params_, "model");
    if (model_name.IsDefined() && model_name.IsScalar()) {
      model_ = LoadModel(b.reader(), c.at, c.path, "sensor model", model_name.Scalar(), "sensors",
                         c.file.robot.file);
    }
  }

  // nullopt when neither gives it, or (reported) when it is not a number.
  std::optional<double> Get(const std::string& key) const {
    const YAML::Node value = Find(key);
    if (!value.IsDefined() || value.IsNull()) return std::nullopt;
    double x = 0.0;
    if (!value.IsScalar() || !YAML::convert<double>::decode(value, x) || !std::isfinite(x)) {
      b_.reader().Error(c_.at, c_.path,
                        "sensor '" + m_.name + "': its parameter " + key +
                            " is not a number (sensors." + m_.name + ".parameters." + key +
                            " or its model file)");
      return std::nullopt;
    }
    return x;
  }

  // A number the estimator cannot do without.
  double Required(const std::string& key) const {
    const YAML::Node value = Find(key);
    if (value.IsDefined() && !value.IsNull()) return Get(key).value_or(0.0);
    b_.reader().Error(c_.at, c_.path,
                      "sensor '" + m_.name + "' has no " + key + " (its model file or sensors." +
                          m_.name + ".parameters." + key + "), which the localization needs");
    return 0.0;
  }

 private:
  YAML::Node Find(const std::string& key) const {
    const YAML::Node own = Child(params_, key);
    return own.IsDefined() ? own : Child(model_, key);
  }

  SystemBuilder& b_;
  const ProviderContext& c_;
  const models::SensorMount& m_;
  YAML::Node params_, model_;
};

// The robot's lasers into a scan matcher `unit` (laser_localization or
// perfect_match_localization): per laser its mount (with mount_z when
// `with_z`) and beam geometry from its device numbers, and its ranges,
// scan count and scan time as the unit's inputs _0, _1, ...; `more` reads
// further numbers of each laser's device (its model file read once).
void WireLasers(SystemBuilder& b, const ProviderContext& c, const Signals& s, const char* unit,
                bool with_z, const std::function<void(const DeviceNumbers&)>& more = {}) {
  const auto lasers = Mounts(s, "laser_scanner");
  std::vector<int> beams;
  std::vector<double> x, y, z, yaw, first, step, period;
  for (std::size_t k = 0; k < lasers.size(); ++k) {
    const models::SensorMount& m = *lasers[k];
    const DeviceNumbers device(b, c, m);
    beams.push_back(static_cast<int>(device.Required("beam_count")));
    x.push_back(m.x_m);
    y.push_back(m.y_m);
    z.push_back(m.z_m);
    yaw.push_back(m.yaw_rad);
    first.push_back(device.Required("first_beam_angle"));
    step.push_back(device.Required("angular_step"));
    period.push_back(device.Required("scan_period"));
    if (more) more(device);
    const std::string suffix = "_" + std::to_string(k);
    b.Connect(Signal(m.name, "ranges"), Signal(unit, "ranges" + suffix));
    b.Connect(Signal(m.name, "scan_count"), Signal(unit, "scan_count" + suffix));
    b.Connect(Signal(m.name, "scan_time"), Signal(unit, "scan_time" + suffix));
  }
  YAML::Node p = b.Params(unit);
  p["beam_counts"] = IntList(beams);
  p["mount_x"] = List(x);
  p["mount_y"] = List(y);
  if (with_z) p["mount_z"] = List(z);
  p["mount_yaw"] = List(yaw);
  p["first_beam_angle"] = List(first);
  p["angular_step"] = List(step);
  p["scan_period"] = List(period);
}

// hector_mapping on the robot's lasers (paper 1 Sec. IV-B): one
// laser_localization unit matching every laser's scans against the scene.
void AddLaserLocalization(SystemBuilder& b, const ProviderContext& c, Signals& s) {
  // The map is a grid over the scene's floor: an unbounded floor (no scene)
  // has nothing to match against and no grid to hold it.
  const models::Floor& f = c.scene.floor;
  constexpr double kMaxFloorSide = 1000.0;  // m: 40,000 cells of 0.025 m a side
  if (!(f.max_x_m - f.min_x_m <= kMaxFloorSide && f.max_y_m - f.min_y_m <= kMaxFloorSide)) {
    b.reader().Error(c.at, c.path,
                     "laser localization matches scans against the scene's map: it needs a "
                     "scene (scene: {model: ...}) whose floor is at most 1000 m a side");
    return;
  }
  b.Unit(kLaserLocalization, "laser_localization");
  YAML::Node p = b.Params(kLaserLocalization);
  WireLasers(b, c, s, kLaserLocalization, true);
  // localization.map: the scene's map (default) or one learned while
  // driving, as hector_mapping does.
  const YAML::Node map = Child(c.at, "map");
  if (map.IsDefined()) {
    p["map"] = b.reader().String(c.at, "localization", "map", "scene", {"scene", "mapping"});
    b.Derived(JoinPath(JoinPath(JoinPath("units", kLaserLocalization), "parameters"), "map"), c.at,
              "localization", "map");
  }
  SetInitialPose(p, c.start);
  SetStep(b, kLaserLocalization);
  s.recorded.push_back(Signal(kLaserLocalization, "source"));
  s.recorded.push_back(Signal(kLaserLocalization, "laser_status"));
  s.localization_sources.push_back(Signal(kLaserLocalization, "source"));
}

// Perfect Match (paper 2 Sec. 4, after Lauer, Lange and Riedmiller 2005)
// on the robot's lasers against maps sliced from the scene at the scan
// height: `localization.maps` lists them ({name, floor_m, region, cell_m});
// a route's graph chooses one per segment (ConnectMapSwitch). Without the
// key, one map of the whole scene on the floor.
void AddPerfectMatch(SystemBuilder& b, const ProviderContext& c, Signals& s) {
  YamlReader& r = b.reader();
  const auto lasers = Mounts(s, "laser_scanner");
  b.Unit(kPerfectMatch, "perfect_match_localization");
  YAML::Node p = b.Params(kPerfectMatch);
  // The nearest usable range of all lasers, and the largest per-device
  // range bias (the LMS151's systematic error) for the match covariance.
  std::optional<double> range_min, bias_sigma;
  WireLasers(b, c, s, kPerfectMatch, false, [&](const DeviceNumbers& device) {
    if (const auto v = device.Get("range_min")) range_min = std::max(range_min.value_or(0.0), *v);
    if (const auto v = device.Get("bias_sigma")) bias_sigma = std::max(bias_sigma.value_or(0.0), *v);
  });
  // The maps a laser built by SLAM (source: own_laser) carry its device's
  // range bias.
  for (std::size_t k = 0; k < lasers.size(); ++k) {
    b.Connect(Signal(lasers[k]->name, "range_bias"),
              Signal(kPerfectMatch, "mapping_range_bias_" + std::to_string(k)));
  }
  if (range_min) p["range_min"] = Num(*range_min);
  if (bias_sigma) p["range_bias_sigma"] = Num(*bias_sigma);
  // 3 DoF as paper 2's matcher: every map is a slice at the first laser's
  // height above the map's floor.
  const double scan_z = lasers.empty() ? 0.0 : lasers.front()->z_m;
  YAML::Node maps(YAML::NodeType::Sequence);
  const YAML::Node given = Child(c.at, "maps");
  if (!given.IsDefined()) {
    YAML::Node one;
    one["name"] = "scene";
    one["height_m"] = Num(scan_z);
    maps.push_back(one);
    s.localization_maps = {"scene"};
  } else if (r.ExpectSequence(given, "localization.maps")) {
    if (given.size() == 0) r.Error(given, "localization.maps", "expected at least one map");
    for (std::size_t i = 0; i < given.size(); ++i) {
      const std::string path = JoinPath("localization.maps", std::to_string(i));
      if (!r.ExpectMap(given[i], path)) continue;
      r.CheckKeys(given[i], path, {"name", "floor_m", "region", "cell_m", "source"});
      YAML::Node one;
      const std::string name = r.String(given[i], path, "name", std::nullopt);
      one["name"] = name;
      one["height_m"] = Num(r.Real(given[i], path, "floor_m", 0.0, {-10.0, 100.0}) + scan_z);
      for (const char* key : {"region", "cell_m", "source"}) {
        if (Child(given[i], key).IsDefined()) one[key] = Child(given[i], key);
      }
      maps.push_back(one);
      s.localization_maps.push_back(name);
    }
  }
  p["maps"] = maps;
  b.Origin(JoinPath(JoinPath(JoinPath("units", kPerfectMatch), "parameters"), "maps"),
           {given.IsDefined() ? given : c.at, given.IsDefined() ? "localization.maps"
                                                                : c.path,
            r.file()});
  s.map_index_input = Signal(kPerfectMatch, "map_index");
  SetInitialPose(p, c.start);
  SetStep(b, kPerfectMatch);
  s.recorded.push_back(Signal(kPerfectMatch, "source"));
  s.recorded.push_back(Signal(kPerfectMatch, "laser_status"));
  s.recorded.push_back(Signal(kPerfectMatch, "map_in_use"));
  s.recorded.push_back(Signal(kPerfectMatch, "match_error"));
  s.localization_sources.push_back(Signal(kPerfectMatch, "source"));
}

// The odometry's twist into a matcher (for motion_prediction: odometry).
void ConnectOdometryToMatcher(SystemBuilder& b, const char* matcher = kLaserLocalization) {
  b.Connect(Signal(kOdometry, "body_velocity"), Signal(matcher, "odometry_velocity"));
  b.Connect(Signal(kOdometry, "yaw_rate"), Signal(matcher, "odometry_yaw_rate"));
}

// The EKF of odometry and a matcher's poses (delayed to their scan's time).
void AddPoseFusion(SystemBuilder& b, const ProviderContext& c, Signals& s, const char* matcher) {
  b.Unit(kPoseFusion, "pose_fusion");
  SetInitialPose(b.Params(kPoseFusion), c.start);
  b.Connect(Signal(kOdometry, "body_velocity"), Signal(kPoseFusion, "odometry_velocity"));
  b.Connect(Signal(kOdometry, "yaw_rate"), Signal(kPoseFusion, "odometry_yaw_rate"));
  b.Connect(Signal(matcher, "position"), Signal(kPoseFusion, "match_position"));
  b.Connect(Signal(matcher, "yaw"), Signal(kPoseFusion, "match_yaw"));
  b.Connect(Signal(matcher, "covariance"), Signal(kPoseFusion, "match_covariance"));
  b.Connect(Signal(matcher, "match_time"), Signal(kPoseFusion, "match_time"));
  b.Connect(Signal(matcher, "match_count"), Signal(kPoseFusion, "match_count"));
  SetStep(b, kPoseFusion);
  s.position = Signal(kPoseFusion, "position");
  s.yaw = Signal(kPoseFusion, "yaw");
  s.velocity = Signal(kPoseFusion, "velocity");
  s.yaw_rate = Signal(kPoseFusion, "yaw_rate");
  s.recorded.push_back(Signal(kPoseFusion, "source"));
  s.localization_sources.push_back(Signal(kPoseFusion, "source"));
}

// Dead reckoning from the wheel encoders (swerve: the module kinematics;
// differential: skid-steer with the controller's effective track), with
// paper 1's Eq. 3 rectification by the surface velocity under each wheel.
void AddOdometry(SystemBuilder& b, const ProviderContext& c, Signals& s) {
  const models::RobotDescription& robot = c.file.robot;
  const models::SensorMount& encoders = *Mounts(s, "wheel_encoder").front();
  const YAML::Node enc = b.Params(encoders.name);
  const std::size_t steer = s.steer_motor_element.size();
  b.Unit(kOdometry, "wheel_odometry");
  YAML::Node p = b.Params(kOdometry);
  const bool swerve = robot.controller == models::ControllerKind::kSwerve;
  p["kind"] = swerve ? "swerve" : "differential";
  p["wheels"] = static_cast<int>(robot.wheels.size());
  SetWheelPositions(p, robot);
  p["wheel_radius"] = Num(robot.wheels.front().radius_m);
  const YAML::Node cpr = Child(enc, "counts_per_revolution");
  // The odometry's channels in its order: swerve, each wheel's steering
  // joint then each wheel's drive joint; differential, the left side's
  // drive joint then the right side's. The encoder counts every steering
  // joint, then every drive joint.
  std::vector<std::size_t> channels;
  if (swerve) {
    for (int j : s.wheel_steer_joint) channels.push_back(static_cast<std::size_t>(j));
    for (int j : s.wheel_drive_joint) channels.push_back(steer + static_cast<std::size_t>(j));
  } else {
    int left = -1, right = -1;
    for (std::size_t i = 0; i < robot.wheels.size(); ++i) {
      (robot.wheels[i].y_m > 0.0 ? left : right) = s.wheel_drive_joint[i];
    }
    if (left < 0 || right < 0) {
      b.reader().Error(c.at, c.path,
                       "differential odometry needs a driven wheel on each side of " + robot.file +
                           " (wheels with y_m > 0 and y_m < 0)");
      return;
    }
    channels = {steer + static_cast<std::size_t>(left), steer + static_cast<std::size_t>(right)};
    const YAML::Node track = Child(c.file.controller_settings, "effective_track");
    if (track.IsDefined()) p["effective_track"] = track;
    b.Origin(JoinPath(JoinPath(JoinPath("units", kOdometry), "parameters"), "effective_track"),
             {YAML::Node(), "controller.effective_track", robot.file});
  }
  // The encoder's counts per revolution, one number for every channel or
  // one per channel (the encoder unit checks them at its own key).
  std::vector<double> counts;
  for (std::size_t k = 0; k < channels.size(); ++k) {
    const YAML::Node one = cpr.IsSequence() && channels[k] < cpr.size() ? cpr[channels[k]] : cpr;
    double x = 0.0;
    if (one.IsScalar() && YAML::convert<double>::decode(one, x)) counts.push_back(x);
    b.Connect(Element(encoders.name, "counts", channels[k]), Element(kOdometry, "counts", k));
  }
  if (counts.size() == channels.size()) {
    p["counts_per_revolution"] = List(counts);
    // A problem with them is reported where the encoder's came from.
    const auto& origins = b.origins();
    const auto from = origins.find(JoinPath(
        JoinPath(JoinPath("units", encoders.name), "parameters"), "counts_per_revolution"));
    if (from != origins.end()) {
      b.Origin(
          JoinPath(JoinPath(JoinPath("units", kOdometry), "parameters"), "counts_per_revolution"),
          from->second);
    }
  }
  SetInitialPose(p, c.start);
  SetStep(b, kOdometry);
  s.odometry = kOdometry;
}

// The PX4Flow units' messages into a surface unit's sensor inputs (both
// surface providers read them alike), their mounts and the wheel count
// into its parameters `p`.
void ConnectFlowSensors(SystemBuilder& b, const std::vector<const models::SensorMount*>& flows,
                        const models::RobotDescription& robot, const std::string& unit,
                        YAML::Node& p) {
  p["sensors"] = static_cast<int>(flows.size());
  p["wheels"] = static_cast<int>(robot.wheels.size());
  std::vector<double> sx, sy, syaw;
  for (std::size_t k = 0; k < flows.size(); ++k) {
    const models::SensorMount& m = *flows[k];
    sx.push_back(m.x_m);
    sy.push_back(m.y_m);
    syaw.push_back(m.yaw_rad);
    for (std::size_t i = 0; i < 2; ++i) {
      b.Connect(Element(m.name, "velocity", i), Element(unit, "sensor_velocity", 2 * k + i));
    }
    b.Connect(Signal(m.name, "valid"), Element(unit, "sensor_valid", k));
    b.Connect(Signal(m.name, "quality"), Element(unit, "sensor_quality", k));
    b.Connect(Signal(m.name, "message_count"), Element(unit, "sensor_message_count", k));
  }
  p["sensor_x"] = List(sx);
  p["sensor_y"] = List(sy);
  p["sensor_yaw"] = List(syaw);
}

// Who measures the velocity of the surface under each wheel (base_link).
const std::map<std::string, Provider>& SurfaceVelocityProviders() {
  static const std::map<std::string, Provider> providers = {
      {"ground_truth", [](SystemBuilder&, const ProviderContext&,
                          Signals& s) { s.surface_velocity = s.true_surface_velocity; }},
      // Paper 1's nominal system (Fig. 6): no knowledge of the surface. The
      // controllers and the odometry's rectification (Eq. 3) get none, as
      // if every floor were still; AddSensing holds the pose fusion's
      // surface offset at 0.
      {"none", [](SystemBuilder&, const ProviderContext&, Signals&) {}},
      // Paper 1 Sec. IV-A: the PX4Flow at the corners, made absolute with
      // the localization's velocity (Eq. 2), filtered by the steady-state
      // Kalman filter, assigned to the wheels the line map puts on a belt.
      {"px4flow", [](SystemBuilder& b, const ProviderContext& c, Signals& s) {
         if (!Require(b, c, s, "px4flow", "px4flow")) return;
         const auto flows = Mounts(s, "px4flow");
         const models::RobotDescription& robot = c.file.robot;
         b.Unit(kSurfaceEstimator, "surface_velocity_estimator");
         YAML::Node p = b.Params(kSurfaceEstimator);
         ConnectFlowSensors(b, flows, robot, kSurfaceEstimator, p);
         // The filter's sample is the sensors' message period, when their
         // settings or model file say (else both units' default, 10 Hz).
         std::optional<double> rate;
         for (const auto* m : flows) {
           const auto r = DeviceNumbers(b, c, *m).Get("publish_rate");
           if (!r) continue;
           if (rate && *rate != *r) {
             b.reader().Error(c.at, c.path,
                              "the PX4Flow publish at different rates (" + Num(*rate).Scalar() +
                                  " and " + Num(*r).Scalar() +
                                  " Hz): the surface estimator needs one message period");
           }
           rate = r;
         }
         if (rate && *rate > 0.0) p["sample_period"] = Num(1.0 / *rate);
         SetWheelPositions(p, robot);
         // The encoders' check of each message (a dark image passes the
         // firmware's quality test with noise matches): with the wheel
         // encoders on, their wheel velocities, and a gate of 3 measurement
         // sigmas (0.09 m/s with paper 1's 3 cm/s). The wheels' encoder
         // velocities: those over the sensor's surface say how the robot
         // moves relative to it.
         if (s.odometry.empty() && !Mounts(s, "wheel_encoder").empty()) AddOdometry(b, c, s);
         if (!s.odometry.empty()) {
           b.Connect(Signal(s.odometry, "wheel_velocity"),
                     Signal(kSurfaceEstimator, "odometry_wheel_velocity"));
           p["odometry_gate"] = 3;
           s.recorded.push_back(Signal(kSurfaceEstimator, "implausible_count"));
         }
         b.Connect(s.position, Signal(kSurfaceEstimator, "position"));
         b.Connect(s.yaw, Signal(kSurfaceEstimator, "yaw"));
         b.Connect(s.velocity, Signal(kSurfaceEstimator, "velocity"));
         b.Connect(s.yaw_rate, Signal(kSurfaceEstimator, "yaw_rate"));
         SetStep(b, kSurfaceEstimator);
         s.surface_velocity = Signal(kSurfaceEstimator, "wheel_surface_velocity");
         s.surface_estimate = Signal(kSurfaceEstimator, "filtered_surface_velocity");
         s.recorded.push_back(Signal(kSurfaceEstimator, "wheel_source"));
         s.recorded.push_back(Signal(kSurfaceEstimator, "sensor_status"));
         s.recorded.push_back(Signal(kSurfaceEstimator, "switch_count"));
       }},
      // Paper 1's future work (Sec. VI-D): each belt's velocity from the
      // laser localization's velocity minus the wheel encoders, and the
      // PX4Flow with the encoders as the robot's motion, in one Kalman
      // filter per belt (units/estimation/surface_fusion_unit.h).
      {"fused_flow", [](SystemBuilder& b, const ProviderContext& c, Signals& s) {
         constexpr const char* kFusion = "surface_fusion";
         const bool flows_on = Require(b, c, s, "px4flow", "fused_flow");
         const bool encoders_on = Require(b, c, s, "wheel_encoder", "fused_flow");
         if (!flows_on || !encoders_on) return;
         if (!b.HasUnit(kLaserLocalization)) {
           b.reader().Error(c.at, c.path,
                            "'fused_flow' needs the laser localization's velocity: "
                            "localization.source laser or fused");
           return;
         }
         const auto flows = Mounts(s, "px4flow");
         const models::RobotDescription& robot = c.file.robot;
         b.Unit(kFusion, "surface_fusion");
         YAML::Node p = b.Params(kFusion);
         ConnectFlowSensors(b, flows, robot, kFusion, p);
         SetWheelPositions(p, robot);
         if (s.odometry.empty()) AddOdometry(b, c, s);
         b.Connect(Signal(s.odometry, "wheel_velocity"), Signal(kFusion, "wheel_velocity"));
         b.Connect(Signal(kLaserLocalization, "position"), Signal(kFusion, "laser_position"));
         b.Connect(Signal(kLaserLocalization, "match_time"), Signal(kFusion, "match_time"));
         b.Connect(Signal(kLaserLocalization, "match_count"), Signal(kFusion, "match_count"));
         b.Connect(s.position, Signal(kFusion, "position"));
         b.Connect(s.yaw, Signal(kFusion, "yaw"));
         SetStep(b, kFusion);
         // The accelerometer feels the belt carry the robot at once
         // (surface_fusion_unit.h): the first IMU, at its rate.
         if (const auto imus = Mounts(s, "imu"); !imus.empty()) {
           const std::string& imu = imus.front()->name;
           p["imu"] = true;
           p["imu_yaw"] = Num(imus.front()->yaw_rad);
           b.Connect(Signal(imu, "linear_acceleration"), Signal(kFusion, "imu_acceleration"));
           const YAML::Node step = b.out()["units"][imu]["step_s"];
           if (step.IsDefined() && step.IsScalar()) b.out()["units"][kFusion]["step_s"] = step;
         }
         s.surface_velocity = Signal(kFusion, "wheel_surface_velocity");
         s.surface_estimate = Signal(kFusion, "sensor_surface_velocity");
         s.recorded.push_back(Signal(kFusion, "belt_velocity"));
         s.recorded.push_back(Signal(kFusion, "switch_count"));
       }}};
  return providers;
}

// Who tells the controllers where the robot is and how fast it moves.
const std::map<std::string, Provider>& LocalizationProviders() {
  static const std::map<std::string, Provider> providers = {
      {"ground_truth",
       [](SystemBuilder&, const ProviderContext&, Signals& s) {
         s.position = s.true_position;
         s.yaw = s.true_yaw;
         s.velocity = Signal(kChassis, "linear_velocity");
         s.yaw_rate = Signal(kChassis, "yaw_rate");
       }},
      // hector_mapping alone: the pose of the last match, its velocity
      // from successive matches.
      {"laser",
       [](SystemBuilder& b, const ProviderContext& c, Signals& s) {
         if (!Require(b, c, s, "laser_scanner", "laser")) return;
         AddLaserLocalization(b, c, s);
         // hector alone starts each match from the last pose; with the
         // wheel encoders on, their odometry is wired for the option
         // motion_prediction: odometry (off unless the scenario sets it).
         if (!Mounts(s, "wheel_encoder").empty()) {
           AddOdometry(b, c, s);
           ConnectOdometryToMatcher(b);
         }
         s.position = Signal(kLaserLocalization, "position");
         s.yaw = Signal(kLaserLocalization, "yaw");
         s.velocity = Signal(kLaserLocalization, "velocity");
         s.yaw_rate = Signal(kLaserLocalization, "yaw_rate");
       }},
      // Dead reckoning alone (rectified by Eq. 3).
      {"odometry",
       [](SystemBuilder& b, const ProviderContext& c, Signals& s) {
         if (!Require(b, c, s, "wheel_encoder", "odometry")) return;
         AddOdometry(b, c, s);
         s.position = Signal(kOdometry, "position");
         s.yaw = Signal(kOdometry, "yaw");
         s.velocity = Signal(kOdometry, "velocity");
         s.yaw_rate = Signal(kOdometry, "yaw_rate");
       }},
      // Odometry between scans, scan matches as corrections (an EKF).
      {"fused", [](SystemBuilder& b, const ProviderContext& c, Signals& s) {
         const bool lasers = Require(b, c, s, "laser_scanner", "fused");
         const bool encoders = Require(b, c, s, "wheel_encoder", "fused");
         if (!lasers || !encoders) return;
         AddLaserLocalization(b, c, s);
         AddOdometry(b, c, s);
         // The matcher starts each match from its last pose moved by the
         // odometry since then (hector alone has no motion model): through
         // a blackout of both lasers it follows the odometry, so the first
         // scans after it are within the matcher's reach.
         b.Params(kLaserLocalization)["motion_prediction"] = "odometry";
         ConnectOdometryToMatcher(b);
         AddPoseFusion(b, c, s, kLaserLocalization);
       }},
      // Paper 2 Sec. 4: Perfect Match on the laser fused with the (skid-steer)
      // odometry in an EKF of the pose alone: off a belt the odometry has no
      // surface offset to learn, so the fusion's offset states are held at 0.
      {"perfect_match", [](SystemBuilder& b, const ProviderContext& c, Signals& s) {
         const bool lasers = Require(b, c, s, "laser_scanner", "perfect_match");
         const bool encoders = Require(b, c, s, "wheel_encoder", "perfect_match");
         if (!lasers || !encoders) return;
         AddPerfectMatch(b, c, s);
         AddOdometry(b, c, s);
         b.Params(kPerfectMatch)["motion_prediction"] = "odometry";
         ConnectOdometryToMatcher(b, kPerfectMatch);
         AddPoseFusion(b, c, s, kPerfectMatch);
         YAML::Node f = b.Params(kPoseFusion);
         f["offset_random_walk"] = 0;
         f["initial_offset_sigma"] = 0;
       }}};
  return providers;
}

std::vector<std::string> Names(const std::map<std::string, Provider>& providers) {
  std::vector<std::string> names;
  for (const auto& [name, provider] : providers) names.push_back(name);
  return names;
}

// The provider `section.key` chooses, and where it was chosen.
std::pair<std::string, YAML::Node> Choose(SystemBuilder& b, const std::string& section,
                                          const std::string& key,
                                          const std::map<std::string, Provider>& providers,
                                          const std::vector<std::string>& other_keys = {}) {
  std::vector<std::string> keys = {key};
  keys.insert(keys.end(), other_keys.begin(), other_keys.end());
  const YAML::Node node = b.Section(b.root(), "", section, keys);
  return {b.reader().String(node, section, key, "ground_truth", Names(providers)), node};
}

}  // namespace

void AddBeaconGroundTruth(SystemBuilder& b, const RobotFile& file, const StartPose& start,
                          const models::Scene& scene, Signals& s) {
  int beacons = 0;
  for (const auto& o : scene.obstacles) beacons += o.kind == "beacon";
  const auto lasers = Mounts(s, "laser_scanner");
  if (beacons < 3 || lasers.empty() || s.route_done.empty()) return;
  const models::SensorMount& m = *lasers.front();
  const ProviderContext c{file, start, scene, Child(b.root(), "sensors"), "sensors"};
  const DeviceNumbers device(b, c, m);
  b.Unit(kBeacons, "beacon_localization");
  YAML::Node p = b.Params(kBeacons);
  p["beam_count"] = static_cast<int>(device.Required("beam_count"));
  p["mount_x"] = Num(m.x_m);
  p["mount_y"] = Num(m.y_m);
  p["mount_yaw"] = Num(m.yaw_rad);
  p["first_beam_angle"] = Num(device.Required("first_beam_angle"));
  p["angular_step"] = Num(device.Required("angular_step"));
  // The laser's own figures: its nearest range, its statistical error and
  // its per-device systematic error.
  if (const auto v = device.Get("range_min")) p["range_min"] = Num(*v);
  if (const auto v = device.Get("noise_sigma")) p["range_sigma"] = Num(*v);
  if (const auto v = device.Get("bias_sigma")) p["systematic_sigma"] = Num(*v);
  // Which way the robot faces, for the symmetric beacon layouts: the
  // route's last node (only a half turn away would mislead it).
  if (!s.route_end.empty()) p["heading_hint"] = Num(s.route_end[2]);
  b.Connect(Signal(m.name, "ranges"), Signal(kBeacons, "ranges"));
  b.Connect(Signal(m.name, "scan_count"), Signal(kBeacons, "scan_count"));
  b.Connect(Signal(m.name, "scan_time"), Signal(kBeacons, "scan_time"));
  // Paper 2 Sec. 6.1: the beacons are uncovered once the robot is in place.
  b.Connect(s.route_done, Signal(kBeacons, "active"));
  SetStep(b, kBeacons);
  for (const char* v : {"position", "yaw", "valid", "beacons_seen"}) {
    s.recorded.push_back(Signal(kBeacons, v));
  }
  s.beacon_unit = kBeacons;
}

void ConnectMapSwitch(SystemBuilder& b, const Signals& s) {
  if (s.map_index_input.empty()) return;
  const YAML::Node localization = Child(b.root(), "localization");
  const YAML::Node at = Child(localization, "maps");
  if (s.map_index_output.empty()) {
    if (s.localization_maps.size() > 1) {
      b.reader().Error(at, "localization.maps",
                       "several maps need a route (task.type route) whose graph says which map "
                       "each segment uses; without one only the first is used");
    }
    return;
  }
  if (s.route_maps != s.localization_maps) {
    b.reader().Error(at.IsDefined() ? at : localization, "localization.maps",
                     "the route graph's maps are [" + config::JoinNames(s.route_maps) +
                         "]: localization.maps must name the same maps in the same order "
                         "(the follower's map index counts in the graph's list), got [" +
                         config::JoinNames(s.localization_maps) + "]");
    return;
  }
  b.Connect(s.map_index_output, s.map_index_input);
}

void SetWheelPositions(YAML::Node params, const models::RobotDescription& robot) {
  std::vector<double> x, y;
  for (const auto& w : robot.wheels) {
    x.push_back(w.x_m);
    y.push_back(w.y_m);
  }
  params["wheel_x"] = List(x);
  params["wheel_y"] = List(y);
}

bool RobotHas(const models::RobotDescription& robot, const std::string& kind) {
  for (const auto& m : robot.sensor_mounts) {
    if (m.kind == kind) return true;
  }
  return false;
}

void AddSensing(SystemBuilder& b, const RobotFile& file, const StartPose& start,
                const models::Scene& scene, Signals& s) {
  const auto [surface, surface_node] =
      Choose(b, "sensing", "surface_velocity", SurfaceVelocityProviders());
  const auto [localization, localization_node] =
      Choose(b, "localization", "source", LocalizationProviders(), {"map", "maps"});
  // The pose and velocity first: the surface velocity (Eq. 2) needs the
  // robot's velocity; the odometry's rectification (Eq. 3) then takes the
  // surface velocity, whoever provides it. Neither depends directly on the
  // other's outputs, so the loop has a step's delay, not an algebraic loop.
  if (const auto it = LocalizationProviders().find(localization);
      it != LocalizationProviders().end()) {
    it->second(b, {file, start, scene, localization_node, "localization.source"}, s);
  }
  if (const auto it = SurfaceVelocityProviders().find(surface);
      it != SurfaceVelocityProviders().end()) {
    it->second(b, {file, start, scene, surface_node, "sensing.surface_velocity"}, s);
  }
  if (Child(localization_node, "map").IsDefined() && !b.HasUnit(kLaserLocalization)) {
    b.reader().Error(Child(localization_node, "map"), "localization.map",
                     "a map is matched against only with localization.source laser or fused");
  }
  if (Child(localization_node, "maps").IsDefined() && !b.HasUnit(kPerfectMatch)) {
    b.reader().Error(Child(localization_node, "maps"), "localization.maps",
                     "maps are switched only with localization.source perfect_match");
  }
  if (!s.odometry.empty() && !s.surface_velocity.empty()) {
    b.Connect(s.surface_velocity, Signal(s.odometry, "surface_velocity"));
  }
  // Without surface knowledge the fusion is the nominal EKF of x, y, yaw:
  // its velocity offset (what the odometry misses while a surface moves
  // under it) would be surface knowledge learnt on the way. A scenario's
  // units.pose_fusion.parameters still override this.
  if (surface == "none" && b.HasUnit(kPoseFusion)) {
    YAML::Node f = b.Params(kPoseFusion);
    f["offset_random_walk"] = 0;
    f["initial_offset_sigma"] = 0;
  }
}

}  // namespace linesim::loader::assembly
