#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <optional>

#include "loader/assembly/providers.h"
#include "loader/yaml_files.h"

namespace linesim::loader::assembly {

namespace {

// The providers of each role, filled by the ProviderRegistrars at start.
std::map<std::string, Provider>& Registry(ProviderRole role) {
  static std::map<std::string, Provider> surface_velocity, localization;
  return role == ProviderRole::kSurfaceVelocity ? surface_velocity : localization;
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

const std::map<std::string, Provider>& Providers(ProviderRole role) { return Registry(role); }

ProviderRegistrar::ProviderRegistrar(ProviderRole role, std::string name, Provider provider) {
  if (!Registry(role).emplace(name, std::move(provider)).second) {
    std::fprintf(stderr, "linesim: provider '%s' is registered twice\n", name.c_str());
    std::abort();
  }
}

std::vector<const models::SensorMount*> Mounts(const Signals& s, const std::string& kind) {
  std::vector<const models::SensorMount*> out;
  for (const auto& m : s.sensors) {
    if (m.kind == kind) out.push_back(&m);
  }
  return out;
}

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

void SetInitialPose(Parameters& p, const StartPose& start) {
  p["initial_x"] = start.x_m;
  p["initial_y"] = start.y_m;
  p["initial_yaw"] = start.yaw_rad;
}

DeviceNumbers::DeviceNumbers(SystemBuilder& b, const ProviderContext& c,
                             const models::SensorMount& m)
    : b_(b), c_(c), m_(m), params_(b.Params(m.name).ToYaml()) {
  const YAML::Node model_name = Child(params_, "model");
  if (model_name.IsDefined() && model_name.IsScalar()) {
    model_ = LoadModel(b.reader(), c.at, c.path, "sensor model", model_name.Scalar(), "sensors",
                       c.file.robot.file);
  }
}

std::optional<double> DeviceNumbers::Get(const std::string& key) const {
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

double DeviceNumbers::Required(const std::string& key) const {
  const YAML::Node value = Find(key);
  if (value.IsDefined() && !value.IsNull()) return Get(key).value_or(0.0);
  b_.reader().Error(c_.at, c_.path,
                    "sensor '" + m_.name + "' has no " + key + " (its model file or sensors." +
                        m_.name + ".parameters." + key + "), which the localization needs");
  return 0.0;
}

YAML::Node DeviceNumbers::Find(const std::string& key) const {
  const YAML::Node own = Child(params_, key);
  return own.IsDefined() ? own : Child(model_, key);
}

void WireLasers(SystemBuilder& b, const ProviderContext& c, const Signals& s, const char* unit,
                bool with_z, const std::function<void(const DeviceNumbers&)>& more) {
  const auto lasers = Mounts(s, "laser_scanner");
  std::vector<int> beams;
  std::vector<double> x, y, z, yaw, first, step, period;
  for (std::size_t k = 0; k < lasers.size(); ++k) {
    const models::SensorMount& m = *lasers[k];
    const DeviceNumbers device(b, c, m);
    beams.push_back(device.BeamCount());
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
  Parameters& p = b.Params(unit);
  p["beam_counts"] = IntList(beams);
  p["mount_x"] = x;
  p["mount_y"] = y;
  if (with_z) p["mount_z"] = z;
  p["mount_yaw"] = yaw;
  p["first_beam_angle"] = first;
  p["angular_step"] = step;
  p["scan_period"] = period;
}

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
  Parameters& p = b.Params(kLaserLocalization);
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

void ConnectOdometryToMatcher(SystemBuilder& b, const char* matcher) {
  b.Connect(Signal(kOdometry, "body_velocity"), Signal(matcher, "odometry_velocity"));
  b.Connect(Signal(kOdometry, "yaw_rate"), Signal(matcher, "odometry_yaw_rate"));
}

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

void AddOdometry(SystemBuilder& b, const ProviderContext& c, Signals& s) {
  const models::RobotDescription& robot = c.file.robot;
  const models::SensorMount& encoders = *Mounts(s, "wheel_encoder").front();
  const Parameters& enc = b.Params(encoders.name);
  const std::size_t steer = s.steer_motor_element.size();
  b.Unit(kOdometry, "wheel_odometry");
  Parameters& p = b.Params(kOdometry);
  const bool swerve = robot.controller == models::ControllerKind::kSwerve;
  p["kind"] = swerve ? "swerve" : "differential";
  p["wheels"] = static_cast<int>(robot.wheels.size());
  SetWheelPositions(p, robot);
  p["wheel_radius"] = robot.wheels.front().radius_m;
  const ParameterValue* cpr_value = enc.Find("counts_per_revolution");
  const YAML::Node cpr = cpr_value ? cpr_value->ToYaml() : YAML::Node();
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
    if (track.IsDefined()) p["effective_track"] = ParameterValue(track);
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
    p["counts_per_revolution"] = counts;
    // A problem with them is reported where the encoder's came from.
    const auto& origins = b.spec().origins;
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

void ConnectFlowSensors(SystemBuilder& b, const std::vector<const models::SensorMount*>& flows,
                        const models::RobotDescription& robot, const std::string& unit,
                        Parameters& p) {
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
  p["sensor_x"] = sx;
  p["sensor_y"] = sy;
  p["sensor_yaw"] = syaw;
}

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
  Parameters& p = b.Params(kBeacons);
  p["beam_count"] = device.BeamCount();
  p["mount_x"] = m.x_m;
  p["mount_y"] = m.y_m;
  p["mount_yaw"] = m.yaw_rad;
  p["first_beam_angle"] = device.Required("first_beam_angle");
  p["angular_step"] = device.Required("angular_step");
  // The laser's own figures: its nearest range, its statistical error and
  // its per-device systematic error.
  if (const auto v = device.Get("range_min")) p["range_min"] = *v;
  if (const auto v = device.Get("noise_sigma")) p["range_sigma"] = *v;
  if (const auto v = device.Get("bias_sigma")) p["systematic_sigma"] = *v;
  // Which way the robot faces, for the symmetric beacon layouts: the
  // route's last node (only a half turn away would mislead it).
  if (!s.route_end.empty()) p["heading_hint"] = s.route_end[2];
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

void SetWheelPositions(Parameters& params, const models::RobotDescription& robot) {
  std::vector<double> x, y;
  for (const auto& w : robot.wheels) {
    x.push_back(w.x_m);
    y.push_back(w.y_m);
  }
  params["wheel_x"] = x;
  params["wheel_y"] = y;
}

bool RobotHas(const models::RobotDescription& robot, const std::string& kind) {
  for (const auto& m : robot.sensor_mounts) {
    if (m.kind == kind) return true;
  }
  return false;
}

void AddSensing(SystemBuilder& b, const RobotFile& file, const StartPose& start,
                const models::Scene& scene, Signals& s) {
  const auto& surface_providers = Providers(ProviderRole::kSurfaceVelocity);
  const auto& localization_providers = Providers(ProviderRole::kLocalization);
  const auto [surface, surface_node] = Choose(b, "sensing", "surface_velocity", surface_providers);
  const auto [localization, localization_node] =
      Choose(b, "localization", "source", localization_providers, {"map", "maps"});
  // The pose and velocity first: the surface velocity (Eq. 2) needs the
  // robot's velocity; the odometry's rectification (Eq. 3) then takes the
  // surface velocity, whoever provides it. Neither depends directly on the
  // other's outputs, so the loop has a step's delay, not an algebraic loop.
  if (const auto it = localization_providers.find(localization);
      it != localization_providers.end()) {
    it->second(b, {file, start, scene, localization_node, "localization.source"}, s);
  }
  if (const auto it = surface_providers.find(surface); it != surface_providers.end()) {
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
    Parameters& f = b.Params(kPoseFusion);
    f["offset_random_walk"] = 0;
    f["initial_offset_sigma"] = 0;
  }
  // The geometry of the laser whose scan the plots draw, from the
  // description: its mount and its device's numbers.
  for (const auto& m : s.sensors) {
    if (m.name != s.scan_unit) continue;
    const ProviderContext c{file, start, scene, Child(b.root(), "sensors"),
                            JoinPath("sensors", m.name)};
    const DeviceNumbers device(b, c, m);
    const auto first = device.Get("first_beam_angle"), step = device.Get("angular_step"),
               no_return = device.Get("no_return_value");
    const auto beam_count = device.Get("beam_count");
    const int beams = beam_count ? DeviceNumbers::WholeBeams(*beam_count) : 0;
    if (first && step && no_return && beams >= 1) {
      s.scan_geometry =
          RobotInfo::ScanGeometry{m.x_m, m.y_m, m.yaw_rad, *first, *step, *no_return, beams};
    }
  }
}

}  // namespace linesim::loader::assembly
