#include "mcap/run_log.h"

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string_view>
#include <utility>

#include "mcap/foxglove_schemas.h"
#include "mcap/json_text.h"
#include "models/scene.h"

namespace linesim::mcap {

namespace {

using cosim::TimeNs;

struct Quat {
  double x = 0, y = 0, z = 0, w = 1;
};

// The quaternion of Rz(yaw) Ry(pitch) Rx(roll) (models/rotation.h's
// RollPitchYawMatrix).
Quat FromRollPitchYaw(double roll, double pitch, double yaw) {
  const double cr = std::cos(0.5 * roll), sr = std::sin(0.5 * roll);
  const double cp = std::cos(0.5 * pitch), sp = std::sin(0.5 * pitch);
  const double cy = std::cos(0.5 * yaw), sy = std::sin(0.5 * yaw);
  return {sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy,
          cr * cp * cy + sr * sp * sy};
}

struct Rgba {
  double r, g, b, a;
};

// A JSON object of numbers, {"k0":v0,"k1":v1,...}, in the given order.
void Fields(std::string& o, std::initializer_list<std::pair<const char*, double>> fields) {
  char separator = '{';
  for (const auto& [key, value] : fields) {
    o += separator;
    o += '"';
    o += key;
    o += "\":";
    json::Number(o, value);
    separator = ',';
  }
  o += '}';
}

void Xyz(std::string& o, double x, double y, double z) { Fields(o, {{"x", x}, {"y", y}, {"z", z}}); }

void Rotation(std::string& o, const Quat& q) {
  Fields(o, {{"x", q.x}, {"y", q.y}, {"z", q.z}, {"w", q.w}});
}

void Pose(std::string& o, double x, double y, double z, const Quat& q) {
  o += "{\"position\":";
  Xyz(o, x, y, z);
  o += ",\"orientation\":";
  Rotation(o, q);
  o += '}';
}

void Color(std::string& o, const Rgba& c) {
  Fields(o, {{"r", c.r}, {"g", c.g}, {"b", c.b}, {"a", c.a}});
}

// Primitives, each appended to a list's text (comma-separated).
void Separate(std::string& list) {
  if (!list.empty()) list += ',';
}

void Box(std::string& cubes, double x, double y, double z, const Quat& q, double sx, double sy,
         double sz, const Rgba& c) {
  Separate(cubes);
  cubes += "{\"pose\":";
  Pose(cubes, x, y, z, q);
  cubes += ",\"size\":";
  Xyz(cubes, sx, sy, sz);
  cubes += ",\"color\":";
  Color(cubes, c);
  cubes += '}';
}

void Ball(std::string& spheres, double x, double y, double z, double diameter, const Rgba& c) {
  Separate(spheres);
  spheres += "{\"pose\":";
  Pose(spheres, x, y, z, Quat{});
  spheres += ",\"size\":";
  Xyz(spheres, diameter, diameter, diameter);
  spheres += ",\"color\":";
  Color(spheres, c);
  spheres += '}';
}

void Cylinder(std::string& cylinders, double x, double y, double z, double diameter,
              double height, const Rgba& c) {
  Separate(cylinders);
  cylinders += "{\"pose\":";
  Pose(cylinders, x, y, z, Quat{});
  cylinders += ",\"size\":";
  Xyz(cylinders, diameter, diameter, height);
  cylinders += ",\"bottom_scale\":1,\"top_scale\":1,\"color\":";
  Color(cylinders, c);
  cylinders += '}';
}

struct Primitives {
  std::string cubes, spheres, cylinders, lines;
};

// A box or cylinder of the scene, moved by (dx, dy).
void AddSolid(Primitives& p, const models::Solid& s, double dx, double dy, const Rgba& c) {
  const double z = s.bottom_m + 0.5 * s.height_m;
  if (s.kind == models::Solid::Kind::kCylinder) {
    Cylinder(p.cylinders, s.x_m + dx, s.y_m + dy, z, 2.0 * s.radius_m, s.height_m, c);
  } else {
    Box(p.cubes, s.x_m + dx, s.y_m + dy, z, FromRollPitchYaw(0, 0, s.yaw_rad), s.length_m,
        s.width_m, s.height_m, c);
  }
}

// A SceneEntity with every field Foxglove's schema has.
void Entity(std::string& o, TimeNs t, std::string_view frame, std::string_view id,
            bool frame_locked, std::string_view kind, const Primitives& p) {
  Separate(o);
  o += "{\"timestamp\":";
  json::Time(o, t);
  o += ",\"frame_id\":";
  json::String(o, frame);
  o += ",\"id\":";
  json::String(o, id);
  o += ",\"lifetime\":{\"sec\":0,\"nsec\":0},\"frame_locked\":";
  o += frame_locked ? "true" : "false";
  o += ",\"metadata\":[";
  if (!kind.empty()) {
    o += "{\"key\":\"kind\",\"value\":";
    json::String(o, kind);
    o += '}';
  }
  o += "],\"arrows\":[],\"cubes\":[" + p.cubes + "],\"spheres\":[" + p.spheres +
       "],\"cylinders\":[" + p.cylinders + "],\"lines\":[" + p.lines +
       "],\"triangles\":[],\"texts\":[],\"models\":[]}";
}

Rgba ObstacleColor(const std::string& kind) {
  if (kind == "wall") return {0.62, 0.62, 0.6, 1.0};
  if (kind == "pillar") return {0.5, 0.5, 0.52, 1.0};
  if (kind == "cart") return {0.85, 0.55, 0.2, 1.0};
  if (kind == "rack") return {0.55, 0.42, 0.3, 1.0};
  if (kind == "vehicle") return {0.3, 0.5, 0.8, 1.0};
  if (kind == "beacon") return {1.0, 1.0, 1.0, 1.0};
  return {0.6, 0.6, 0.6, 1.0};
}

constexpr Rgba kFloor{0.78, 0.78, 0.76, 1.0};
constexpr Rgba kBeltOn{0.22, 0.42, 0.72, 1.0};
constexpr Rgba kBeltOff{0.55, 0.58, 0.66, 1.0};
constexpr Rgba kCarried{0.96, 0.83, 0.66, 1.0};
constexpr Rgba kTerrain{0.7, 0.68, 0.58, 1.0};
constexpr Rgba kBody{0.92, 0.5, 0.12, 0.85};
constexpr Rgba kWheel{0.15, 0.15, 0.15, 1.0};
constexpr Rgba kPath{0.1, 0.65, 0.2, 1.0};

// A floor larger than this (OpenFloor's 2e6 m) is not drawn: no viewer
// shows it usefully.
constexpr double kLargestFloorM = 1e4;

std::optional<double> Parameter(const cosim::Unit& unit, const char* name) {
  const cosim::VariableTable& v = unit.variables();
  const auto ref = v.Find(name);
  if (!ref || v.info(*ref).type != cosim::VarType::kReal) return std::nullopt;
  return v.GetReal(*ref);
}

std::vector<double> ArrayParameter(const cosim::Unit& unit, const char* name) {
  const cosim::VariableTable& v = unit.variables();
  const auto ref = v.Find(name);
  if (!ref || v.info(*ref).type != cosim::VarType::kRealArray) return {};
  const auto values = v.GetRealArray(*ref);
  return {values.begin(), values.end()};
}

std::optional<cosim::ValueRef> ArrayOutput(const cosim::Unit& unit, const char* name,
                                           std::size_t size) {
  const cosim::VariableTable& v = unit.variables();
  const auto ref = v.Find(name);
  if (!ref || v.info(*ref).type != cosim::VarType::kRealArray || v.info(*ref).size != size) {
    return std::nullopt;
  }
  return ref;
}

std::uint64_t LogTime(TimeNs t) { return static_cast<std::uint64_t>(std::max<TimeNs>(t, 0)); }

// The longest text of a JSON number (json::Number: a double's shortest
// round-trip form, "-2.2250738585072014e-308", or null), its comma included.
constexpr std::uint64_t kNumberBytes = 25;
constexpr double kHuge = 1e300;

// The longest text json::TenthMillimetres writes for a laser's range, its
// comma included: a measured range is at most range_max, plus the device's
// bias (at most bias_max, or some bias_sigma) and noise (some noise_sigma):
// twice range_max and ten sigmas are beyond any run; no echo is
// no_return_value.
std::uint64_t RangeBytes(const cosim::Unit& laser) {
  const auto real = [&](const char* name) { return Parameter(laser, name).value_or(0.0); };
  const double farthest = 2.0 * Parameter(laser, "range_max").value_or(kHuge) + real("bias_max") +
                          10.0 * (real("bias_sigma") + real("noise_sigma"));
  const auto text = [](double v) -> std::uint64_t {
    if (!(std::abs(v) < 9e14)) return kNumberBytes;
    std::uint64_t digits = 1;
    for (double d = std::ceil(std::abs(v)); d >= 10.0; d /= 10.0) ++digits;
    return 1 + digits + 5 + 1;  // sign, integer digits, ".dddd", comma
  };
  return std::max(text(farthest), text(Parameter(laser, "no_return_value").value_or(kHuge)));
}

// A text's longest JSON form: every byte as \u00XX, the quotes.
std::uint64_t QuotedBytes(std::string_view s) { return 6 * s.size() + 2; }

// The longest {"sec":S,"nsec":N}.
constexpr std::uint64_t kTimeBytes = 48;

// The most of a run's error message the log's end holds.
constexpr std::size_t kMaxOutcomeBytes = 4096;

// A message's record (opcode, length, channel, sequence, two times) and its
// entry in its chunk's message index.
constexpr std::uint64_t kMessageOverhead = 1 + 8 + 2 + 4 + 8 + 8 + 16;

}  // namespace

RunLog::RunLog(std::ostream& out, const loader::Scenario& scenario, RunLogOptions options)
    : writer_(out, options.writer),
      options_(std::move(options)),
      scenario_(scenario),
      probes_(scenario.recorded),
      record_interval_(scenario.record_interval) {
  const cosim::System& system = *scenario.system;
  const auto probe_of = [&](const std::string& label) -> std::optional<cosim::Probe> {
    if (label.empty()) return std::nullopt;
    for (const auto& p : probes_) {
      if (p.label == label) return p;
    }
    try {
      auto found = cosim::ResolveProbes(system, {label});
      if (found.size() == 1) return found[0];
    } catch (const std::exception&) {
    }
    return std::nullopt;
  };

  // The robot's pose: the columns its plots read, and its chassis's 3D
  // outputs when it has them (height, roll and pitch over terrain).
  if (scenario.robot) {
    const loader::RobotInfo& robot = *scenario.robot;
    x_ = probe_of(robot.x_column);
    y_ = probe_of(robot.y_column);
    yaw_ = probe_of(robot.yaw_column);
    has_robot_ = x_ && y_ && yaw_;
    if (has_robot_) {
      chassis_ = x_->where.unit;
      const cosim::Unit& chassis = system.unit(*chassis_);
      orientation_ = ArrayOutput(chassis, "orientation", 4);
      position_3d_ = ArrayOutput(chassis, "position_3d", 3);
    }
    for (const loader::RobotInfo& other : robot.fleet) {
      const auto chassis = system.FindUnit(other.name + ".chassis");
      if (!chassis) continue;
      const auto p3 = ArrayOutput(system.unit(*chassis), "position_3d", 3);
      const auto q = ArrayOutput(system.unit(*chassis), "orientation", 4);
      if (!p3 || !q) continue;
      others_.push_back({other.name, other.name + "/base_link", *chassis, *p3, *q,
                         other.body_length_m.value_or(0.0), other.body_width_m.value_or(0.0)});
    }
    for (std::size_t k = 0; k < scenario.scene.belts.size(); ++k) {
      Dynamic d;
      if (k < robot.belt_travel_columns.size()) d.travel = probe_of(robot.belt_travel_columns[k]);
      if (k < robot.belt_on_columns.size()) d.on = probe_of(robot.belt_on_columns[k]);
      belts_.push_back(d);
    }
  }
  belts_.resize(scenario.scene.belts.size());
  for (std::size_t k = 0; k < belts_.size(); ++k) belts_[k].frame = "belt/" + scenario.scene.belts[k].name;

  // Sensor frames: every unit mounted on the robot (mount_x, mount_y).
  for (std::size_t u = 0; u < system.unit_count(); ++u) {
    const cosim::Unit& unit = system.unit(u);
    const auto mx = Parameter(unit, "mount_x"), my = Parameter(unit, "mount_y");
    if (!mx || !my) continue;
    auto mz = Parameter(unit, "mount_z");
    if (!mz) mz = Parameter(unit, "mount_height");
    const Quat q = FromRollPitchYaw(Parameter(unit, "mount_roll").value_or(0.0),
                                    Parameter(unit, "mount_pitch").value_or(0.0),
                                    Parameter(unit, "mount_yaw").value_or(0.0));
    // A fleet's other robot's sensor hangs from its own base_link.
    std::string parent = "base_link";
    for (const OtherRobot& other : others_) {
      if (unit.name().starts_with(other.name + ".")) parent = other.frame;
    }
    Frame f;
    f.text = ",\"parent_frame_id\":";
    json::String(f.text, parent);
    f.text += ",\"child_frame_id\":";
    json::String(f.text, unit.name());
    f.text += ",\"translation\":";
    Xyz(f.text, *mx, *my, mz.value_or(0.0));
    f.text += ",\"rotation\":";
    Rotation(f.text, q);
    f.text += '}';
    frames_.push_back(std::move(f));
  }

  if (has_robot_ || !frames_.empty()) {
    const auto schema = writer_.AddSchema("foxglove.FrameTransforms", "jsonschema",
                                          FrameTransformsSchema());
    if (has_robot_) tf_channel_ = writer_.AddChannel(schema, "/tf", "json");
    if (!frames_.empty()) mounts_channel_ = writer_.AddChannel(schema, "/tf/mounts", "json");
  }
  {
    const auto schema =
        writer_.AddSchema("foxglove.SceneUpdate", "jsonschema", SceneUpdateSchema());
    static_channel_ = writer_.AddChannel(schema, "/scene/static", "json");
    if (!scenario.scene.belts.empty()) {
      scene_channel_ = writer_.AddChannel(schema, "/scene", "json");
    }
  }
  log_channel_ = writer_.AddChannel(writer_.AddSchema("foxglove.Log", "jsonschema", LogSchema()),
                                    "/log", "json");

  AddLasers(system);
  AddSignals(system);
}

void RunLog::AddLasers(const cosim::System& system) {
  // Lasers: every laser_scanner unit, its beams' bearings from its
  // parameters.
  std::uint16_t laser_schema = 0;
  for (std::size_t u = 0; u < system.unit_count(); ++u) {
    const cosim::Unit& unit = system.unit(u);
    if (unit.type_name() != "laser_scanner") continue;
    const cosim::VariableTable& v = unit.variables();
    const auto ranges = v.Find("ranges"), count = v.Find("scan_count"), time = v.Find("scan_time");
    const auto first = Parameter(unit, "first_beam_angle"), step = Parameter(unit, "angular_step");
    if (!ranges || !count || !time || !first || !step) continue;
    if (laser_schema == 0) {
      laser_schema = writer_.AddSchema("foxglove.LaserScan", "jsonschema", LaserScanSchema());
    }
    const std::size_t beams = v.info(*ranges).size;
    Laser l;
    l.beams = beams;
    l.range_bytes = RangeBytes(unit);
    l.unit = u;
    l.ranges = *ranges;
    l.scan_count = *count;
    l.scan_time = *time;
    l.channel = writer_.AddChannel(laser_schema, "/scan/" + unit.name(), "json");
    l.head = ",\"frame_id\":";
    json::String(l.head, unit.name());
    l.head += ",\"pose\":";
    Pose(l.head, 0, 0, 0, Quat{});
    l.head += ",\"start_angle\":";
    json::Number(l.head, *first);
    l.head += ",\"end_angle\":";
    json::Number(l.head, *first + static_cast<double>(beams > 0 ? beams - 1 : 0) * *step);
    l.head += ",\"intensities\":[],\"ranges\":[";
    lasers_.push_back(std::move(l));
  }
}

void RunLog::AddSignals(const cosim::System& system) {
  // Signals: one channel per unit with recorded variables, in the order
  // signals.csv has them.
  std::map<std::size_t, std::size_t> unit_slot;
  std::vector<std::size_t> slot_unit;
  for (std::size_t i = 0; i < probes_.size(); ++i) {
    const cosim::Probe& p = probes_[i];
    const std::size_t u = p.where.unit;
    auto [it, added] = unit_slot.emplace(u, signals_.size());
    if (added) {
      signals_.emplace_back();
      slot_unit.push_back(u);
    }
    Signals& s = signals_[it->second];
    const std::string& variable = system.unit(u).variables().info(p.where.ref).name;
    const bool element = p.where.index >= 0;
    auto f = std::find_if(s.fields.begin(), s.fields.end(),
                          [&](const auto& field) { return field.name == variable; });
    if (f == s.fields.end()) {
      s.fields.push_back({variable, element, {}});
      f = s.fields.end() - 1;
    }
    f->probes.push_back(i);
  }
  for (std::size_t slot = 0; slot < signals_.size(); ++slot) {
    Signals& s = signals_[slot];
    // An array field only for elements 0, 1, ... n-1 in order; other picks
    // of elements become fields NAME_i.
    std::vector<Signals::Field> fields;
    for (auto& f : s.fields) {
      bool in_order = f.array;
      for (std::size_t k = 0; in_order && k < f.probes.size(); ++k) {
        in_order = probes_[f.probes[k]].where.index == static_cast<std::ptrdiff_t>(k);
      }
      if (f.array && !in_order) {
        for (const std::size_t i : f.probes) {
          fields.push_back(
              {f.name + "_" + std::to_string(probes_[i].where.index), false, {i}});
        }
      } else {
        fields.push_back(std::move(f));
      }
    }
    s.fields = std::move(fields);
    const cosim::Unit& unit = system.unit(slot_unit[slot]);
    nlohmann::ordered_json schema;
    schema["title"] = "linesim.signals." + unit.name();
    schema["description"] = "recorded variables of unit '" + unit.name() + "' (" +
                            unit.type_name() + "), as in signals.csv";
    schema["type"] = "object";
    nlohmann::ordered_json props;
    props["timestamp"] = {{"type", "object"},
                          {"description", "simulation time"},
                          {"properties",
                           {{"sec", {{"type", "integer"}, {"minimum", 0}}},
                            {"nsec", {{"type", "integer"}, {"minimum", 0}}}}}};
    for (const auto& f : s.fields) {
      const cosim::VariableInfo& info =
          unit.variables().info(probes_[f.probes.front()].where.ref);
      std::string description = info.description;
      if (!info.unit.empty()) description += " (" + info.unit + ")";
      const nlohmann::ordered_json number = {{"type", {"number", "null"}}};
      if (f.array) {
        props[f.name] = {{"type", "array"}, {"items", number}, {"description", description}};
      } else {
        props[f.name] = {{"type", {"number", "null"}}, {"description", description}};
      }
    }
    schema["properties"] = props;
    const auto id =
        writer_.AddSchema("linesim.signals." + unit.name(), "jsonschema", schema.dump());
    s.channel = writer_.AddChannel(id, "/signals/" + unit.name(), "json");
  }
}

RunLog::~RunLog() = default;

void RunLog::OnStart(const cosim::Master& master) {
  start_ = master.options().start;
  if (record_interval_ <= 0) record_interval_ = master.options().base_step;
  next_scene_ = next_signals_ = start_;
  for (Laser& l : lasers_) l.next = start_;
}

std::string RunLog::StaticText(TimeNs now) const {
  const models::Scene& scene = scenario_.scene;
  const cosim::System& system = *scenario_.system;
  std::string o;
  const models::Floor& f = scene.floor;
  if (f.max_x_m - f.min_x_m <= kLargestFloorM && f.max_y_m - f.min_y_m <= kLargestFloorM) {
    Primitives p;
    // A slab whose top is the floor (z = 0).
    Box(p.cubes, 0.5 * (f.min_x_m + f.max_x_m), 0.5 * (f.min_y_m + f.max_y_m), -0.005, Quat{},
        f.max_x_m - f.min_x_m, f.max_y_m - f.min_y_m, 0.01, kFloor);
    Entity(o, now, "map", "floor", false, "floor", p);
  }
  for (const models::Obstacle& ob : scene.obstacles) {
    Primitives p;
    AddSolid(p, ob.solid, 0, 0, ObstacleColor(ob.kind));
    Entity(o, now, "map", "obstacle/" + ob.name, false, ob.kind, p);
  }
  for (const models::TerrainPiece& t : scene.terrain) {
    Primitives p;
    Box(p.cubes, t.center_x_m, t.center_y_m, t.center_z_m,
        FromRollPitchYaw(t.roll_rad, -t.pitch_rad, t.yaw_rad), t.length_m, t.width_m,
        t.thickness_m, kTerrain);
    Entity(o, now, "map", "terrain/" + t.name, false, "terrain", p);
  }
  if (scenario_.robot && !scenario_.robot->path.empty()) {
    Primitives p;
    const auto& path = scenario_.robot->path;
    if (path.size() == 1) {
      Cylinder(p.cylinders, path[0][0], path[0][1], 0.005, 0.05, 0.01, kPath);
    } else {
      p.lines = "{\"type\":0,\"pose\":";
      Pose(p.lines, 0, 0, 0, Quat{});
      p.lines += ",\"thickness\":0.02,\"scale_invariant\":false,\"points\":[";
      for (std::size_t k = 0; k < path.size(); ++k) {
        if (k) p.lines += ',';
        Xyz(p.lines, path[k][0], path[k][1], 0.01);
      }
      p.lines += "],\"color\":";
      Color(p.lines, kPath);
      p.lines += ",\"colors\":[],\"indices\":[]}";
    }
    Entity(o, now, "map", "path", false, "desired path", p);
  }
  if (has_robot_) {
    // The chassis's body box and its wheels' contact spheres, in base_link.
    const cosim::Unit& chassis = system.unit(*chassis_);
    Primitives p;
    const double length = scenario_.robot->body_length_m.value_or(0.0);
    const double width = scenario_.robot->body_width_m.value_or(0.0);
    const double height = Parameter(chassis, "body_height").value_or(0.0);
    const double middle = Parameter(chassis, "body_bottom").value_or(0.0) + 0.5 * height;
    if (length > 0 && width > 0 && height > 0) {
      Box(p.cubes, 0, 0, middle, Quat{}, length, width, height, kBody);
    }
    const auto wx = ArrayParameter(chassis, "wheel_x"), wy = ArrayParameter(chassis, "wheel_y"),
               wr = ArrayParameter(chassis, "wheel_radius");
    for (std::size_t k = 0; k < wx.size() && k < wy.size() && k < wr.size(); ++k) {
      Ball(p.spheres, wx[k], wy[k], wr[k], 2.0 * wr[k], kWheel);
    }
    Entity(o, now, "base_link", "robot", true, "robot", p);
  }
  for (const OtherRobot& other : others_) {
    const cosim::Unit& chassis = system.unit(other.chassis);
    const double height = Parameter(chassis, "body_height").value_or(0.0);
    const double middle = Parameter(chassis, "body_bottom").value_or(0.0) + 0.5 * height;
    if (other.length <= 0 || other.width <= 0 || height <= 0) continue;
    Primitives p;
    Box(p.cubes, 0, 0, middle, Quat{}, other.length, other.width, height, kBody);
    Entity(o, now, other.frame, "robot/" + other.name, true, other.name, p);
  }
  return "{\"deletions\":[],\"entities\":[" + o + "]}";
}

std::string RunLog::MountsText(TimeNs now) const {
  if (frames_.empty()) return "";
  std::string text = "{\"transforms\":[";
  for (std::size_t k = 0; k < frames_.size(); ++k) {
    if (k) text += ',';
    text += "{\"timestamp\":";
    json::Time(text, now);
    text += frames_[k].text;
  }
  return text + "]}";
}

void RunLog::WriteStatic(TimeNs now) {
  text_ = StaticText(now);
  writer_.WriteMessage(static_channel_, LogTime(now), LogTime(now), text_);
  if (!frames_.empty()) {
    text_ = MountsText(now);
    writer_.WriteMessage(mounts_channel_, LogTime(now), LogTime(now), text_);
  }
}

void RunLog::WriteScene(TimeNs t, const cosim::System& system) {
  const models::Scene& scene = scenario_.scene;
  // What the scene shows: each belt on or off, each object on its belt or
  // lifted off; a message only when that changed.
  std::string state;
  for (std::size_t k = 0; k < scene.belts.size(); ++k) {
    bool on = scene.belts[k].initially_on;
    if (belts_[k].on) on = cosim::ReadProbe(system, *belts_[k].on) > 0.5;
    state += on ? '1' : '0';
  }
  for (const models::CarriedObject& c : scene.carried) {
    const auto k = static_cast<std::size_t>(c.belt);
    if (k >= scene.belts.size()) continue;
    const double d = belts_[k].travel ? cosim::ReadProbe(system, *belts_[k].travel) : 0.0;
    const auto range = models::CarriedTravelRange(scene.belts[k].area, c.solid);
    state += d < range[0] || d > range[1] ? '0' : '1';
  }
  if (state == scene_state_) return;
  scene_state_ = state;
  text_ = SceneText(t, state);
  writer_.WriteMessage(scene_channel_, LogTime(t), LogTime(t), text_);
}

std::string RunLog::SceneText(TimeNs t, const std::string& state) const {
  const models::Scene& scene = scenario_.scene;
  std::string entities, deletions;
  std::size_t s = 0;
  for (std::size_t k = 0; k < scene.belts.size(); ++k) {
    const models::Belt& b = scene.belts[k];
    const bool on = state[s++] == '1';
    Primitives p;
    // Flush with the floor, drawn a millimetre above it to be seen.
    Box(p.cubes, b.area.center_x_m, b.area.center_y_m, 0.001,
        FromRollPitchYaw(0, 0, b.area.direction_rad), b.area.length_m, b.area.width_m, 0.002,
        on ? kBeltOn : kBeltOff);
    Entity(entities, t, "map", "belt/" + b.name, false, on ? "belt (on)" : "belt (off)", p);
  }
  for (const models::CarriedObject& c : scene.carried) {
    const auto k = static_cast<std::size_t>(c.belt);
    if (k >= scene.belts.size()) continue;
    const std::string id = "carried/" + c.name;
    if (state[s++] == '0') {  // lifted off the line
      Separate(deletions);
      deletions += "{\"timestamp\":";
      json::Time(deletions, t);
      deletions += ",\"type\":0,\"id\":";
      json::String(deletions, id);
      deletions += '}';
      continue;
    }
    // Where it was at time zero, in its belt's frame: it rides with it.
    Primitives p;
    AddSolid(p, c.solid, 0.0, 0.0, kCarried);
    Entity(entities, t, belts_[k].frame, id, true, "carried", p);
  }
  return "{\"deletions\":[" + deletions + "],\"entities\":[" + entities + "]}";
}

void RunLog::WriteTransforms(TimeNs t, const cosim::System& system) {
  std::string& o = text_;
  o = "{\"transforms\":[";
  {
    const double x = cosim::ReadProbe(system, *x_), y = cosim::ReadProbe(system, *y_);
    const cosim::VariableTable& v = system.unit(*chassis_).variables();
    double z = 0.0;
    if (position_3d_) z = v.GetRealArray(*position_3d_)[2];
    Quat q;
    if (orientation_) {
      const auto w = v.GetRealArray(*orientation_);  // w, x, y, z
      q = {w[1], w[2], w[3], w[0]};
    } else {
      q = FromRollPitchYaw(0, 0, cosim::ReadProbe(system, *yaw_));
    }
    o += "{\"timestamp\":";
    json::Time(o, t);
    o += ",\"parent_frame_id\":\"map\",\"child_frame_id\":\"base_link\",\"translation\":";
    Xyz(o, x, y, z);
    o += ",\"rotation\":";
    Rotation(o, q);
    o += '}';
  }
  for (const OtherRobot& other : others_) {
    const cosim::VariableTable& v = system.unit(other.chassis).variables();
    const auto p = v.GetRealArray(other.position_3d);
    const auto w = v.GetRealArray(other.orientation);  // w, x, y, z
    o += ",{\"timestamp\":";
    json::Time(o, t);
    o += ",\"parent_frame_id\":\"map\",\"child_frame_id\":";
    json::String(o, other.frame);
    o += ",\"translation\":";
    Xyz(o, p[0], p[1], p[2]);
    o += ",\"rotation\":";
    Rotation(o, Quat{w[1], w[2], w[3], w[0]});
    o += '}';
  }
  const models::Scene& scene = scenario_.scene;
  for (std::size_t k = 0; k < belts_.size(); ++k) {
    if (!belts_[k].travel) continue;
    const double d = cosim::ReadProbe(system, *belts_[k].travel);
    const double dir = scene.belts[k].area.direction_rad;
    o += ",{\"timestamp\":";
    json::Time(o, t);
    o += ",\"parent_frame_id\":\"map\",\"child_frame_id\":";
    json::String(o, belts_[k].frame);
    o += ",\"translation\":";
    Xyz(o, d * std::cos(dir), d * std::sin(dir), 0.0);
    o += ",\"rotation\":{\"x\":0,\"y\":0,\"z\":0,\"w\":1}}";
  }
  o += "]}";
  writer_.WriteMessage(tf_channel_, LogTime(t), LogTime(t), o);
}

void RunLog::WriteSignals(TimeNs t, const cosim::System& system) {
  for (const Signals& s : signals_) {
    std::string& o = text_;
    o = "{\"timestamp\":";
    json::Time(o, t);
    for (const auto& f : s.fields) {
      o += ",\"";
      o += f.name;  // variable names are identifiers: nothing to escape
      o += "\":";
      if (f.array) {
        o += '[';
        for (std::size_t k = 0; k < f.probes.size(); ++k) {
          if (k) o += ',';
          json::Number(o, cosim::ReadProbe(system, probes_[f.probes[k]]));
        }
        o += ']';
      } else {
        json::Number(o, cosim::ReadProbe(system, probes_[f.probes.front()]));
      }
    }
    o += '}';
    writer_.WriteMessage(s.channel, LogTime(t), LogTime(t), o);
  }
}

void RunLog::WriteScans(TimeNs t, const cosim::System& system) {
  for (Laser& l : lasers_) {
    const cosim::VariableTable& v = system.unit(l.unit).variables();
    const double count = v.GetReal(l.scan_count);
    if (count == l.last_count || count <= 0 || t < l.next) continue;
    l.last_count = count;
    while (l.next <= t) l.next += options_.scan_period;
    std::string& o = text_;
    o = "{\"timestamp\":";
    // The scan's own time (its start), not the time it is logged at.
    json::Time(o, std::max<TimeNs>(0, std::llround(v.GetReal(l.scan_time) * 1e9)));
    o += l.head;
    const auto ranges = v.GetRealArray(l.ranges);
    for (std::size_t k = 0; k < ranges.size(); ++k) {
      if (k) o += ',';
      json::TenthMillimetres(o, ranges[k]);
    }
    o += "]}";
    writer_.WriteMessage(l.channel, LogTime(t), LogTime(t), o);
  }
}

void RunLog::OnSample(TimeNs t, const cosim::System& system) {
  if (ended_) return;
  if (!started_) {
    WriteStatic(t);
    started_ = true;
  }
  if ((t - start_) % record_interval_ == 0 && t >= next_signals_) {
    if (has_robot_) WriteTransforms(t, system);
    WriteSignals(t, system);
    while (next_signals_ <= t) next_signals_ += options_.signal_period;
  }
  if (t >= next_scene_) {
    if (!scenario_.scene.belts.empty()) WriteScene(t, system);
    while (next_scene_ <= t) next_scene_ += options_.scene_period;
  }
  WriteScans(t, system);
}

void RunLog::OnEnd(cosim::TimeNs, bool) { ended_ = true; }

void RunLog::Close(const RunOutcome& outcome) {
  if (closed_) return;
  closed_ = ended_ = true;
  const std::string reached =
      cosim::FormatSeconds(outcome.end) + " s of " + cosim::FormatSeconds(outcome.stop) + " s";
  std::string headline;
  int level = 2;  // foxglove.LogLevel INFO
  if (outcome.status == "interrupted") {
    headline = "run INTERRUPTED at " + reached + ": the log ends there";
    level = 3;  // WARNING
  } else if (outcome.status != "ok") {
    headline = "run FAILED at " + reached;
    level = 4;  // ERROR
  } else {
    headline = "run ended: ok at " + reached;
  }
  // The message as the summary has it, cut to a length the size bound
  // allows for (summary.json keeps it whole), as UTF-8 (MCAP's strings are).
  const std::string why = json_text::ValidUtf8(outcome.message, kMaxOutcomeBytes);
  if (!why.empty()) headline += " (" + why + ")";
  const TimeNs t = std::max<TimeNs>(outcome.end, 0);
  text_ = "{\"timestamp\":";
  json::Time(text_, t);
  text_ += ",\"level\":" + std::to_string(level) + ",\"message\":";
  json::String(text_, headline);
  text_ += ",\"name\":\"linesim\",\"file\":\"\",\"line\":0}";
  writer_.WriteMessage(log_channel_, LogTime(t), LogTime(t), text_);
  writer_.AddMetadata("linesim.run", {{"status", outcome.status},
                                      {"end_time_s", cosim::FormatSeconds(outcome.end)},
                                      {"stop_time_s", cosim::FormatSeconds(outcome.stop)},
                                      {"message", why}});
  writer_.Close();
}

std::uint64_t RunLog::BytesBound(const loader::Scenario& scenario, const RunLogOptions& options) {
  std::ostream sink(nullptr);  // built only to measure: it writes nothing
  const RunLog log(sink, scenario, options);
  return log.Bound();
}

std::uint64_t RunLog::Bound() const {
  const cosim::MasterOptions& master = scenario_.master->options();
  const TimeNs span = std::max<TimeNs>(master.stop - master.start, 0);
  const auto count = [&](TimeNs period) {
    return static_cast<std::uint64_t>(span / std::max<TimeNs>(period, 1)) + 2;
  };
  const TimeNs row_period = std::max(options_.signal_period, record_interval_);
  std::uint64_t records = 0, largest = 0;
  const auto add = [&](std::uint64_t n, std::uint64_t bytes) {
    records += n * (bytes + kMessageOverhead);
    largest = std::max(largest, bytes + kMessageOverhead);
  };
  // /signals: per row one message per unit: its time, each field's key and
  // numbers.
  for (const Signals& sig : signals_) {
    std::uint64_t bytes = 16 + kTimeBytes;
    for (const auto& f : sig.fields) bytes += f.name.size() + 6 + f.probes.size() * kNumberBytes;
    add(count(row_period), bytes);
  }
  // /tf: the robot, the other robots, the belts with their travel.
  if (has_robot_) {
    std::uint64_t bytes = 32;
    const std::uint64_t transform = kTimeBytes + 100 + 7 * (kNumberBytes + 5);
    bytes += transform;
    for (const OtherRobot& other : others_) bytes += transform + QuotedBytes(other.frame);
    for (const Dynamic& belt : belts_) {
      if (belt.travel) bytes += transform + QuotedBytes(belt.frame);
    }
    add(count(row_period), bytes);
  }
  for (const Laser& l : lasers_) {
    add(count(options_.scan_period), 16 + kTimeBytes + l.head.size() + l.beams * l.range_bytes);
  }
  // Once: the static scene and the mounts; /scene at its start, at each
  // belt switch, and as each carried object joins or leaves its belt, at
  // most once per scene period; /log at the end.
  const TimeNs end = master.stop;
  add(1, StaticText(end).size());
  if (!frames_.empty()) add(1, MountsText(end).size());
  const models::Scene& scene = scenario_.scene;
  if (!scene.belts.empty()) {
    std::uint64_t changes = 1 + 2 * scene.carried.size();
    for (const models::Belt& b : scene.belts) changes += b.schedule.size();
    const std::string on(scene.belts.size() + scene.carried.size(), '1');
    std::string off = on;
    std::fill(off.begin(), off.begin() + static_cast<std::ptrdiff_t>(scene.belts.size()), '0');
    add(std::min(changes, count(options_.scene_period)),
        std::max(SceneText(end, on).size(), SceneText(end, off).size()));
  }
  add(1, 512 + QuotedBytes(std::string(kMaxOutcomeBytes, ' ')));  // /log
  // Schemas and channels: in the chunks before their first message, and
  // again in the summary.
  std::uint64_t definitions = 0;
  for (std::uint16_t id = 1; id <= writer_.schema_count(); ++id) {
    definitions += 9 + writer_.SchemaBytes(id);
  }
  for (std::uint16_t id = 0; id < writer_.channel_count(); ++id) {
    definitions += 9 + writer_.ChannelBytes(id);
  }
  records += definitions;
  // Chunks close once their records reach the chunk size: each holds at
  // least that much but the last, and at most that plus one message.
  const std::uint64_t chunks = records / options_.writer.chunk_size + 1;
  const std::uint64_t chunk_bytes = options_.writer.chunk_size + largest;
  const std::uint64_t per_chunk = 61 + CompressedBound(options_.writer.compression, chunk_bytes) -
                                  chunk_bytes + writer_.channel_count() * 15;
  std::uint64_t bytes = records + chunks * per_chunk;
  // The summary: definitions again, statistics, chunk indexes, metadata
  // and its index, summary offsets, footer, magic and header.
  bytes += definitions + 64 + 10 * static_cast<std::uint64_t>(writer_.channel_count()) +
           chunks * (80 + 10 * static_cast<std::uint64_t>(writer_.channel_count())) +
           2 * (256 + kMaxOutcomeBytes) + 8 * 32 + 64 + 2 * 8 + 64 +
           options_.writer.profile.size() + options_.writer.library.size();
  return bytes;
}

}  // namespace linesim::mcap
