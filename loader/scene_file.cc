#include "loader/scene_file.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <optional>
#include <vector>

#include "cosim/closest_names.h"
#include "cosim/variable_table.h"
#include "loader/yaml_files.h"
#include "models/angle.h"

namespace linesim::loader {

namespace {

namespace fs = std::filesystem;

using models::kDegToRad;

// Positions on the floor: the same bound as robot scenarios' belts.
constexpr Range kCoordinate{-1e6, 1e6};
// Horizontal sizes: a hall is at most a few hundred metres; 1e4 m as for
// belts in robot scenarios.
constexpr Range kLength{0.0, 1e4, true};
// Heights of things standing in a hall, and how far above the floor they
// start (a car body on skids, a mezzanine).
constexpr Range kHeight{0.0, 100.0, true};
constexpr Range kBottom{0.0, 100.0};

const std::vector<std::string> kSceneKeys = {"name",  "description", "source",  "surfaces", "floor",
                                             "belts", "obstacles",   "carried", "terrain"};

// Reads the lists of named items with the names each list defines, so that
// references to them can be checked.
class SceneParser {
 public:
  SceneParser(YamlReader& r, models::Scene& scene) : r_(r), s_(scene) {}

  void Parse(const YAML::Node& root, const std::string& path, bool allow_model) {
    if (!r_.ExpectMap(root, path.empty() ? "(top)" : path)) return;
    std::vector<std::string> keys = kSceneKeys;
    if (allow_model) keys.insert(keys.begin(), "model");
    r_.CheckKeys(root, path, keys);
    s_.name = r_.String(root, path, "name", s_.name);
    s_.description = r_.String(root, path, "description", "");
    r_.String(root, path, "source", "");  // documentation only; must be text
    Surfaces(Child(root, "surfaces"), JoinPath(path, "surfaces"), root);
    FloorOf(Child(root, "floor"), JoinPath(path, "floor"), root);
    Belts(Child(root, "belts"), JoinPath(path, "belts"));
    Obstacles(Child(root, "obstacles"), JoinPath(path, "obstacles"));
    Carried(Child(root, "carried"), JoinPath(path, "carried"));
    Terrain(Child(root, "terrain"), JoinPath(path, "terrain"));
  }

 private:
  // The items of an optional list (none when absent or null).
  std::vector<std::pair<std::string, YAML::Node>> Items(const YAML::Node& list,
                                                        const std::string& path) {
    std::vector<std::pair<std::string, YAML::Node>> items;
    if (!list.IsDefined() || list.IsNull() || !r_.ExpectSequence(list, path)) return items;
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string item_path = JoinPath(path, std::to_string(i));
      if (r_.ExpectMap(list[i], item_path)) items.emplace_back(item_path, list[i]);
    }
    return items;
  }

  // The item's `name`, which must be new in `names`.
  std::string Name(const YAML::Node& item, const std::string& path,
                   std::vector<std::string>& names) {
    const std::string name = r_.String(item, path, "name", std::nullopt);
    if (name.empty()) return name;
    if (std::find(names.begin(), names.end(), name) != names.end()) {
      r_.Error(Child(item, "name"), JoinPath(path, "name"),
               "'" + name + "' is defined twice in this list: names must differ");
    }
    names.push_back(name);
    return name;
  }

  // Index of the item `key` names in `names`; an unknown name is reported
  // with the closest ones.
  int Reference(const YAML::Node& item, const std::string& path, const std::string& key,
                const std::vector<std::string>& names, const std::string& what) {
    const std::string name = r_.String(item, path, key, std::nullopt);
    if (name.empty()) return 0;
    const auto it = std::find(names.begin(), names.end(), name);
    if (it != names.end()) return static_cast<int>(it - names.begin());
    r_.Error(Child(item, key), JoinPath(path, key),
             "no " + what + " '" + name + "' in this scene" +
                 (names.empty()
                      ? " (it defines none)"
                      : ": expected one of " + JoinNames(names) + cosim::ClosestHint(name, names)));
    return 0;
  }

  void Surfaces(const YAML::Node& list, const std::string& path, const YAML::Node& root) {
    if (!list.IsDefined() || list.IsNull()) {
      r_.Error(root, path,
               "missing required key: a list of surfaces {name, friction, "
               "texture_contrast, illumination_lux}");
      return;
    }
    const auto items = Items(list, path);
    if (list.IsSequence() && list.size() == 0)
      r_.Error(list, path, "expected at least one surface");
    for (const auto& [p, item] : items) {
      r_.CheckKeys(item, p,
                   {"name", "friction", "texture_contrast", "illumination_lux", "flicker_hz",
                    "flicker_depth", "roughness_m", "roughness_length_m", "texture_period_m",
                    "texture_periodic_share", "tread_friction", "unevenness"});
      models::Surface surface;
      surface.name = Name(item, p, surface_names_);
      // Rubber or polyurethane on floors and belts is 0.5-1.0; 3 leaves
      // room for studies without admitting nonsense.
      surface.friction = r_.Real(item, p, "friction", std::nullopt, {0.0, 3.0});
      // Per tread material (a robot's treads name theirs): {rubber: 0.75}.
      if (const YAML::Node pairs = Child(item, "tread_friction"); pairs.IsDefined()) {
        const std::string pp = JoinPath(p, "tread_friction");
        if (r_.ExpectMap(pairs, pp)) {
          for (const auto& kv : pairs) {
            const std::string material = kv.first.Scalar();
            surface.tread_friction[material] =
                r_.Real(pairs, pp, material, std::nullopt, {0.0, 3.0});
          }
        }
      }
      surface.texture_contrast = r_.Real(item, p, "texture_contrast", std::nullopt, {0.0, 1.0});
      // Direct sunlight is about 1e5 lx.
      surface.illumination_lux = r_.Real(item, p, "illumination_lux", std::nullopt, {0.0, 1e5});
      // Optional (the optic-flow sensor's disturbances; see models/scene.h).
      surface.flicker_hz = r_.Real(item, p, "flicker_hz", 0.0, {0.0, 1000.0});
      surface.flicker_depth = r_.Real(item, p, "flicker_depth", 0.0, {0.0, 1.0});
      surface.roughness_m = r_.Real(item, p, "roughness_m", 0.0, {0.0, 0.05});
      surface.roughness_length_m = r_.Real(item, p, "roughness_length_m", 0.01, {1e-4, 10.0});
      surface.texture_period_m = r_.Real(item, p, "texture_period_m", 0.0, {0.0, 1.0});
      surface.texture_periodic_share = r_.Real(item, p, "texture_periodic_share", 0.0, {0.0, 1.0});
      if (const YAML::Node u = Child(item, "unevenness"); u.IsDefined()) {
        surface.unevenness = Unevenness(u, JoinPath(p, "unevenness"));
      }
      s_.surfaces.push_back(surface);
    }
  }

  // A surface's height profile (models/surface_profile.h): an ISO 8608
  // class letter or its G_d(n0), the band and the seed.
  models::Unevenness Unevenness(const YAML::Node& node, const std::string& path) {
    models::Unevenness u;
    if (!r_.ExpectMap(node, path)) return u;
    r_.CheckKeys(node, path,
                 {"iso8608_class", "psd_n0_m3", "waviness", "min_wavelength_m", "max_wavelength_m",
                  "components", "seed"});
    const bool by_class = Child(node, "iso8608_class").IsDefined();
    if (by_class == Child(node, "psd_n0_m3").IsDefined()) {
      r_.Error(node, path,
               "expected one of iso8608_class (A to H) or psd_n0_m3 (G_d at 0.1 cycles/m)");
      return u;
    }
    if (by_class) {
      const std::string letter = r_.String(node, path, "iso8608_class", std::nullopt,
                                           {"A", "B", "C", "D", "E", "F", "G", "H"});
      if (letter.size() == 1) u.psd_n0_m3 = models::Iso8608ClassPsd(letter[0]);
    } else {
      // Class H's upper limit is 262144e-6 m^3 (ISO 8608).
      u.psd_n0_m3 = r_.Real(node, path, "psd_n0_m3", std::nullopt, {0.0, 0.5});
    }
    u.waviness = r_.Real(node, path, "waviness", 2.0, {1.0, 4.0});
    u.min_wavelength_m = r_.Real(node, path, "min_wavelength_m", 0.05, {1e-3, 100.0, true});
    u.max_wavelength_m = r_.Real(node, path, "max_wavelength_m", 10.0, {1e-3, 1e3, true});
    if (!(u.max_wavelength_m > u.min_wavelength_m)) {
      r_.Error(
          Child(node, "max_wavelength_m").IsDefined() ? Child(node, "max_wavelength_m") : node,
          JoinPath(path, "max_wavelength_m"),
          "expected more than min_wavelength_m (" + YAML::Node(u.min_wavelength_m).Scalar() + ")");
    }
    u.components = static_cast<int>(r_.Integer(node, path, "components", 32, 1, 256));
    u.seed = static_cast<std::uint64_t>(r_.Integer(node, path, "seed", 1, 0, 1'000'000'000));
    return u;
  }

  void FloorOf(const YAML::Node& floor, const std::string& path, const YAML::Node& root) {
    if (!floor.IsDefined() || floor.IsNull()) {
      r_.Error(root, path,
               "missing required key: a map {min_x_m, max_x_m, min_y_m, max_y_m, surface}");
      return;
    }
    if (!r_.ExpectMap(floor, path)) return;
    r_.CheckKeys(floor, path, {"min_x_m", "max_x_m", "min_y_m", "max_y_m", "surface"});
    models::Floor& f = s_.floor;
    f.min_x_m = r_.Real(floor, path, "min_x_m", std::nullopt, kCoordinate);
    f.max_x_m = r_.Real(floor, path, "max_x_m", std::nullopt, kCoordinate);
    f.min_y_m = r_.Real(floor, path, "min_y_m", std::nullopt, kCoordinate);
    f.max_y_m = r_.Real(floor, path, "max_y_m", std::nullopt, kCoordinate);
    for (const char* axis : {"x", "y"}) {
      const double lo = axis[0] == 'x' ? f.min_x_m : f.min_y_m;
      const double hi = axis[0] == 'x' ? f.max_x_m : f.max_y_m;
      const std::string min_key = std::string("min_") + axis + "_m";
      const std::string max_key = std::string("max_") + axis + "_m";
      if (!Child(floor, min_key).IsDefined() || !Child(floor, max_key).IsDefined() || hi > lo) {
        continue;
      }
      // At the key the user changed (--set min_x_m), else at the max.
      const std::string key = r_.ConflictKey(path, min_key, max_key);
      const bool at_min = key == min_key;
      r_.Error(Child(floor, key), JoinPath(path, key),
               at_min ? "expected less than " + max_key + " (" + YAML::Node(hi).Scalar() + ")"
                      : "expected more than " + min_key + " (" + YAML::Node(lo).Scalar() + ")");
    }
    f.surface = Reference(floor, path, "surface", surface_names_, "surface");
  }

  void Belts(const YAML::Node& list, const std::string& path) {
    for (const auto& [p, b] : Items(list, path)) {
      r_.CheckKeys(b, p,
                   {"name", "surface", "center_x_m", "center_y_m", "length_m", "width_m",
                    "direction_deg", "speed_mps", "speed_variation", "variation_period_s",
                    "acceleration_mps2", "schedule", "edge_gap_m"});
      models::Belt belt;
      // A belt without a name is "belt_<index>"; without a surface its top
      // is the floor's covering.
      belt.name = Child(b, "name").IsDefined() ? Name(b, p, belt_names_)
                                               : "belt_" + std::to_string(s_.belts.size());
      belt.surface = Child(b, "surface").IsDefined()
                         ? Reference(b, p, "surface", surface_names_, "surface")
                         : s_.floor.surface;
      // Keys, defaults and ranges as robot scenarios' line.belts items.
      belt.area.center_x_m = r_.Real(b, p, "center_x_m", std::nullopt, kCoordinate);
      belt.area.center_y_m = r_.Real(b, p, "center_y_m", std::nullopt, kCoordinate);
      belt.area.length_m = r_.Real(b, p, "length_m", std::nullopt, kLength);
      belt.area.width_m = r_.Real(b, p, "width_m", std::nullopt, {0.0, 1e3, true});
      belt.area.direction_rad = r_.Real(b, p, "direction_deg", 0.0, {-360, 360}) * kDegToRad;
      // Paper 1: lines run below 0.2 m/s; 2 m/s leaves room for studies.
      belt.nominal_speed_mps = r_.Real(b, p, "speed_mps", std::nullopt, {0.0, 2.0, true});
      // Paper 1: "almost constant velocity (+-10 % variation)".
      belt.speed_variation = r_.Real(b, p, "speed_variation", 0.1, {0.0, 0.5});
      belt.variation_period_s = r_.Real(b, p, "variation_period_s", 20.0, {0.0, 1e6, true});
      belt.acceleration_mps2 = r_.Real(b, p, "acceleration_mps2", 0.5, {0.0, 100.0, true});
      // Flush with the floor and no gap unless the scene says. The wheels
      // ride over it (a gap takes friction from the patch over it; the
      // ground stays a plane), so it is meant for gaps of a few mm.
      belt.edge_gap_m = r_.Real(b, p, "edge_gap_m", 0.0, {0.0, 0.05});
      Schedule(Child(b, "schedule"), JoinPath(p, "schedule"), belt);
      OnTheFloor(b, p, belt);
      s_.belts.push_back(belt);
    }
  }

  // A belt lies on the floor: every corner of its area within the floor's
  // bounds (the robot, the maps and the plots live there; a belt beyond
  // them would fail when the run starts, or never be reached). Reported at
  // the belt's key the command line changed, else at its centre.
  void OnTheFloor(const YAML::Node& b, const std::string& path, const models::Belt& belt) {
    const models::Floor& f = s_.floor;
    if (!(f.max_x_m > f.min_x_m && f.max_y_m > f.min_y_m)) return;  // reported with the floor
    const models::Rect& a = belt.area;
    const double c = std::cos(a.direction_rad), s = std::sin(a.direction_rad);
    // Rounding of the rotation: a belt whose edge is the floor's is on it.
    const double slack =
        1e-9 * (1.0 + std::abs(a.center_x_m) + std::abs(a.center_y_m) + a.length_m);
    for (const double u : {-0.5, 0.5}) {
      for (const double v : {-0.5, 0.5}) {
        const double x = a.center_x_m + c * u * a.length_m - s * v * a.width_m;
        const double y = a.center_y_m + s * u * a.length_m + c * v * a.width_m;
        if (x >= f.min_x_m - slack && x <= f.max_x_m + slack && y >= f.min_y_m - slack &&
            y <= f.max_y_m + slack) {
          continue;
        }
        std::string key = "center_x_m";
        for (const char* k : {"center_y_m", "length_m", "width_m", "direction_deg"}) {
          if (r_.FromCommandLine(JoinPath(path, k))) key = k;
        }
        if (r_.FromCommandLine(JoinPath(path, "center_x_m"))) key = "center_x_m";
        r_.Error(Child(b, key).IsDefined() ? Child(b, key) : b, JoinPath(path, key),
                 "belt '" + belt.name + "' lies off the floor: its corner (" +
                     cosim::FormatValue(x) + ", " + cosim::FormatValue(y) +
                     ") m is outside the floor's x " + cosim::FormatValue(f.min_x_m) + " to " +
                     cosim::FormatValue(f.max_x_m) + " m, y " + cosim::FormatValue(f.min_y_m) +
                     " to " + cosim::FormatValue(f.max_y_m) + " m: expected a belt within them");
        return;
      }
    }
  }

  // [{time_s, on}] in increasing time; on at t = 0 unless an entry at 0
  // says otherwise.
  void Schedule(const YAML::Node& list, const std::string& path, models::Belt& belt) {
    belt.initially_on = true;
    cosim::TimeNs last = -1;
    for (const auto& [p, item] : Items(list, path)) {
      r_.CheckKeys(item, p, {"time_s", "on"});
      const cosim::TimeNs t = r_.Time(item, p, "time_s", std::nullopt, {0.0, 1e7});
      const bool on = r_.Boolean(item, p, "on", std::nullopt);
      if (t <= last) {
        r_.Error(Child(item, "time_s"), JoinPath(p, "time_s"), "switching times must increase");
      }
      last = t;
      if (t == 0) {
        belt.initially_on = on;
      } else {
        belt.schedule.push_back({t, on});
      }
    }
  }

  // A `box` or a `cylinder` (exactly one of them) of `item`.
  std::optional<models::Solid> Shape(const YAML::Node& item, const std::string& path,
                                     bool cylinder_allowed) {
    const YAML::Node box = Child(item, "box");
    const YAML::Node cylinder = cylinder_allowed ? Child(item, "cylinder") : YAML::Node();
    const bool has_box = box.IsDefined() && !box.IsNull();
    const bool has_cylinder = cylinder.IsDefined() && !cylinder.IsNull();
    const std::string wanted = cylinder_allowed ? "box or cylinder" : "box";
    if (has_box == has_cylinder) {
      if (has_box) {
        r_.Error(cylinder, JoinPath(path, "cylinder"), "expected either box or cylinder, not both");
      } else {
        r_.Error(item, JoinPath(path, "box"), "missing required key: the shape (" + wanted + ")");
      }
      return std::nullopt;
    }
    models::Solid solid;
    const std::string p = JoinPath(path, has_box ? "box" : "cylinder");
    const YAML::Node m = has_box ? box : cylinder;
    if (!r_.ExpectMap(m, p)) return std::nullopt;
    if (has_box) {
      r_.CheckKeys(m, p, {"x_m", "y_m", "yaw_deg", "length_m", "width_m", "height_m", "bottom_m"});
      solid.kind = models::Solid::Kind::kBox;
      solid.yaw_rad = r_.Real(m, p, "yaw_deg", 0.0, {-360, 360}) * kDegToRad;
      solid.length_m = r_.Real(m, p, "length_m", std::nullopt, kLength);
      solid.width_m = r_.Real(m, p, "width_m", std::nullopt, kLength);
    } else {
      r_.CheckKeys(m, p, {"x_m", "y_m", "radius_m", "height_m", "bottom_m"});
      solid.kind = models::Solid::Kind::kCylinder;
      solid.radius_m = r_.Real(m, p, "radius_m", std::nullopt, {0.0, 1e3, true});
    }
    solid.x_m = r_.Real(m, p, "x_m", std::nullopt, kCoordinate);
    solid.y_m = r_.Real(m, p, "y_m", std::nullopt, kCoordinate);
    solid.height_m = r_.Real(m, p, "height_m", std::nullopt, kHeight);
    solid.bottom_m = r_.Real(m, p, "bottom_m", 0.0, kBottom);
    return solid;
  }

  void Obstacles(const YAML::Node& list, const std::string& path) {
    std::vector<std::string> names;
    for (const auto& [p, item] : Items(list, path)) {
      r_.CheckKeys(item, p, {"name", "kind", "box", "cylinder"});
      models::Obstacle o;
      o.name = Name(item, p, names);
      o.kind = r_.String(item, p, "kind", std::nullopt,
                         {"wall", "pillar", "cart", "rack", "vehicle", "beacon"});
      if (auto solid = Shape(item, p, true)) o.solid = *solid;
      s_.obstacles.push_back(o);
    }
  }

  // A carried box, optionally on skids (runners under it, from the floor
  // to its underside: what a scanner near the floor sees of a car body)
  // and repeated upstream along its belt (a line of bodies, one key to
  // sweep how many).
  void Carried(const YAML::Node& list, const std::string& path) {
    std::vector<std::string> names;
    for (const auto& [p, item] : Items(list, path)) {
      r_.CheckKeys(item, p, {"name", "belt", "box", "skids", "copies"});
      models::CarriedObject c;
      c.name = Name(item, p, names);
      c.belt = Reference(item, p, "belt", belt_names_, "belt");
      const auto solid = Shape(item, p, false);
      if (solid) c.solid = *solid;
      std::vector<models::CarriedObject> group = {c};
      const YAML::Node skids = Child(item, "skids");
      const std::string sp = JoinPath(p, "skids");
      if (skids.IsDefined() && !skids.IsNull() && r_.ExpectMap(skids, sp) && solid) {
        r_.CheckKeys(skids, sp, {"count", "width_m", "gauge_m", "length_m"});
        const auto n = r_.Integer(skids, sp, "count", 2, 1, 16);
        const double width = r_.Real(skids, sp, "width_m", std::nullopt, {0.0, 1e2, true});
        const double gauge = r_.Real(skids, sp, "gauge_m",
                                     n > 1 ? std::nullopt : std::optional<double>(0.0), {0.0, 1e2});
        const double length = r_.Real(skids, sp, "length_m", solid->length_m, {0.0, 1e3, true});
        if (solid->bottom_m <= 0.0) {
          r_.Error(skids, sp, "a box on skids needs bottom_m > 0 (the skids' height)");
        }
        if (gauge + width > solid->width_m) {
          r_.Error(Child(skids, "gauge_m"), JoinPath(sp, "gauge_m"),
                   "the skids must fit under the box: gauge_m + width_m at most its width " +
                       cosim::FormatValue(solid->width_m) + " m");
        }
        if (length > solid->length_m) {
          r_.Error(Child(skids, "length_m"), JoinPath(sp, "length_m"),
                   "the skids must fit under the box: at most its length " +
                       cosim::FormatValue(solid->length_m) + " m");
        }
        const double cy = std::cos(solid->yaw_rad), sy = std::sin(solid->yaw_rad);
        for (std::int64_t i = 0; i < n; ++i) {
          // Evenly across the body, the outer ones gauge_m apart.
          const double across =
              n > 1 ? gauge * (static_cast<double>(i) / static_cast<double>(n - 1) - 0.5) : 0.0;
          models::CarriedObject skid = c;
          skid.name = c.name + "_skid_" + std::to_string(i + 1);
          skid.solid = models::BoxSolid(solid->x_m - sy * across, solid->y_m + cy * across,
                                        solid->yaw_rad, length, width, solid->bottom_m);
          group.push_back(skid);
        }
      }
      const YAML::Node copies = Child(item, "copies");
      const std::string cp = JoinPath(p, "copies");
      std::int64_t count = 1;
      double pitch = 0.0;
      if (copies.IsDefined() && !copies.IsNull() && r_.ExpectMap(copies, cp)) {
        r_.CheckKeys(copies, cp, {"count", "pitch_m"});
        count = r_.Integer(copies, cp, "count", 1, 0, 100);
        pitch = r_.Real(copies, cp, "pitch_m",
                        count > 1 ? std::nullopt : std::optional<double>(0.0), {0.0, 1e4});
        // Copies must not overlap: the pitch at least the box's extent
        // along its belt.
        if (count > 1 && solid && c.belt >= 0 &&
            static_cast<std::size_t>(c.belt) < s_.belts.size()) {
          const double d =
              solid->yaw_rad - s_.belts[static_cast<std::size_t>(c.belt)].area.direction_rad;
          const double extent =
              solid->length_m * std::abs(std::cos(d)) + solid->width_m * std::abs(std::sin(d));
          if (pitch < extent) {
            r_.Error(copies, JoinPath(cp, "pitch_m"),
                     "copies " + cosim::FormatValue(pitch) + " m apart overlap: the box is " +
                         cosim::FormatValue(extent) + " m long along its belt");
          }
        }
      }
      if (c.belt < 0 || static_cast<std::size_t>(c.belt) >= s_.belts.size()) count = 0;
      // Copy k sits k pitches upstream of the first, so they pass in turn.
      const double dir =
          count > 0 ? s_.belts[static_cast<std::size_t>(c.belt)].area.direction_rad : 0.0;
      for (std::int64_t k = 0; k < count; ++k) {
        for (models::CarriedObject o : group) {
          if (k > 0) o.name += "_" + std::to_string(k + 1);
          // A generated name must not be one the file gives another object.
          if (o.name != c.name) {
            if (std::find(names.begin(), names.end(), o.name) != names.end()) {
              r_.Error(item, p,
                       "the copy or skid it makes, '" + o.name +
                           "', has the name of another carried object");
            }
            names.push_back(o.name);
          }
          o.solid.x_m -= static_cast<double>(k) * pitch * std::cos(dir);
          o.solid.y_m -= static_cast<double>(k) * pitch * std::sin(dir);
          s_.carried.push_back(o);
        }
      }
    }
  }

  // A list of exactly three numbers, each in its range.
  std::array<double, 3> Triple(const YAML::Node& item, const std::string& path,
                               const std::string& key, const std::string& meaning,
                               const std::array<Range, 3>& ranges) {
    std::array<double, 3> out{};
    const YAML::Node node = Child(item, key);
    const std::string p = JoinPath(path, key);
    if (!node.IsDefined() || node.IsNull()) {
      r_.Error(item, p, "missing required key: " + meaning);
    } else if (!node.IsSequence() || node.size() != 3) {
      r_.Error(node, p,
               "expected " + meaning + ", got " + Describe(node) +
                   (node.IsSequence() ? " of " + std::to_string(node.size()) : ""));
    } else {
      for (std::size_t i = 0; i < 3; ++i) {
        out[i] = r_.AsReal(node[i], JoinPath(p, std::to_string(i)), ranges[i]).value_or(0.0);
      }
    }
    return out;
  }

  void Terrain(const YAML::Node& list, const std::string& path) {
    std::vector<std::string> names;
    for (const auto& [p, item] : Items(list, path)) {
      r_.CheckKeys(item, p,
                   {"name", "center_m", "size_m", "yaw_deg", "pitch_deg", "roll_deg", "surface"});
      models::TerrainPiece t;
      t.name = Name(item, p, names);
      const auto c = Triple(item, p, "center_m", "[x, y, z] (m)",
                            {kCoordinate, kCoordinate, Range{-100.0, 100.0}});
      t.center_x_m = c[0];
      t.center_y_m = c[1];
      t.center_z_m = c[2];
      const auto size = Triple(item, p, "size_m", "[length, width, thickness] (m)",
                               {kLength, kLength, Range{0.0, 100.0, true}});
      t.length_m = size[0];
      t.width_m = size[1];
      t.thickness_m = size[2];
      t.yaw_rad = r_.Real(item, p, "yaw_deg", 0.0, {-360, 360}) * kDegToRad;
      // A tilt of 90 degrees or more is a wall, not something driven on.
      t.pitch_rad = r_.Real(item, p, "pitch_deg", 0.0, {-89.0, 89.0}) * kDegToRad;
      t.roll_rad = r_.Real(item, p, "roll_deg", 0.0, {-89.0, 89.0}) * kDegToRad;
      t.surface = Reference(item, p, "surface", surface_names_, "surface");
      s_.terrain.push_back(t);
    }
  }

  YamlReader& r_;
  models::Scene& s_;
  std::vector<std::string> surface_names_, belt_names_;
};

// Where a key path of the merged tree came from in the scenario: the
// scenario's key node (for unknown keys) and value node.
struct ScenarioSource {
  YAML::Node key, value;
};

YAML::Node Record(const YAML::Node& node, const std::string& path,
                  std::map<std::string, ScenarioSource>& sources);

// An empty list the scenario writes over a list with items: merged by
// index it would remove nothing and leave the items as they were.
struct EmptyListOver {
  std::string path;
  YAML::Node node;
  std::size_t items = 0;  // of the list it would merge onto
};

// `over` merged onto `base` (the scene file's tree, which is never
// modified): maps by key, lists by index; anything else replaces. Every
// path `over` writes is recorded in `sources` (relative to the scene), and
// every empty list over a list with items, at any depth, in `empty`.
YAML::Node Merge(const YAML::Node& base, const YAML::Node& over, const std::string& path,
                 std::map<std::string, ScenarioSource>& sources,
                 std::vector<EmptyListOver>& empty) {
  if (base.IsSequence() && base.size() > 0 && over.IsSequence() && over.size() == 0) {
    empty.push_back({path, over, base.size()});
  }
  if (base.IsMap() && over.IsMap()) {
    YAML::Node out(YAML::NodeType::Map);
    for (const auto& kv : base) out[kv.first.Scalar()] = kv.second;
    for (const auto& kv : over) {
      const std::string key = kv.first.Scalar();
      if (path == "scene" && key == "model") continue;
      const std::string p = JoinPath(path, key);
      sources[p] = {kv.first, kv.second};
      const YAML::Node b = Child(base, key);
      out[key] =
          b.IsDefined() ? Merge(b, kv.second, p, sources, empty) : Record(kv.second, p, sources);
    }
    return out;
  }
  if (base.IsSequence() && over.IsSequence()) {
    YAML::Node out(YAML::NodeType::Sequence);
    for (std::size_t i = 0; i < std::max(base.size(), over.size()); ++i) {
      const std::string p = JoinPath(path, std::to_string(i));
      if (i < over.size()) sources[p] = {over[i], over[i]};
      if (i < base.size() && i < over.size()) {
        out.push_back(Merge(base[i], over[i], p, sources, empty));
      } else if (i < base.size()) {
        out.push_back(base[i]);
      } else {
        out.push_back(Record(over[i], p, sources));
      }
    }
    return out;
  }
  return Record(over, path, sources);
}

// Records every path under `node` as the scenario's; returns `node`.
YAML::Node Record(const YAML::Node& node, const std::string& path,
                  std::map<std::string, ScenarioSource>& sources) {
  if (node.IsMap()) {
    for (const auto& kv : node) {
      const std::string p = JoinPath(path, kv.first.Scalar());
      sources[p] = {kv.first, kv.second};
      Record(kv.second, p, sources);
    }
  } else if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i) {
      const std::string p = JoinPath(path, std::to_string(i));
      sources[p] = {node[i], node[i]};
      Record(node[i], p, sources);
    }
  }
  return node;
}

// Lists merge item by item, at every depth (scene.obstacles, a belt's
// schedule): an empty one would silently remove nothing, so it is refused at
// its key (through the reader's origins, at the key the user wrote, e.g.
// line.belts.0.schedule).
void RefuseEmptyLists(YamlReader& r, const std::vector<EmptyListOver>& empty,
                      const std::string& whose) {
  for (const EmptyListOver& e : empty) {
    const bool top = std::count(e.path.begin(), e.path.end(), '.') == 1;
    r.Error(e.node, e.path,
            "an empty list removes nothing: lists merge item by item onto " + whose + " " +
                std::to_string(e.items) + " items" +
                (top && whose == "the scene file's"
                     ? "; to leave them out, write the scene without model"
                     : ", which stay as they are; write the items wanted instead"));
  }
}

}  // namespace

models::Scene ReadScene(YamlReader& r, const YAML::Node& root, const std::string& path,
                        const std::string& name, const std::string& file) {
  models::Scene scene;
  scene.name = name;
  scene.file = file;
  SceneParser(r, scene).Parse(root, path, false);
  return scene;
}

models::Scene LoadSceneFile(const std::string& file) {
  const YAML::Node root = LoadYamlOrThrow(file, "scene");
  YamlReader r(file);
  models::Scene scene = ReadScene(r, root, "", fs::path(file).stem().string(), file);
  if (!r.ok()) throw ScenarioError(r.issues());
  return scene;
}

// models::OpenFloor() as a scene file would write it.
YAML::Node OpenFloorTree() {
  const models::Scene open = models::OpenFloor();
  YAML::Node tree(YAML::NodeType::Map);
  for (const models::Surface& surface : open.surfaces) {
    YAML::Node item;
    item["name"] = surface.name;
    item["friction"] = surface.friction;
    item["texture_contrast"] = surface.texture_contrast;
    item["illumination_lux"] = surface.illumination_lux;
    tree["surfaces"].push_back(item);
  }
  tree["floor"]["min_x_m"] = open.floor.min_x_m;
  tree["floor"]["max_x_m"] = open.floor.max_x_m;
  tree["floor"]["min_y_m"] = open.floor.min_y_m;
  tree["floor"]["max_y_m"] = open.floor.max_y_m;
  tree["floor"]["surface"] = open.surfaces[static_cast<std::size_t>(open.floor.surface)].name;
  return tree;
}

models::Scene ReadScenarioScene(YamlReader& r, const YAML::Node& scene,
                                const std::string& scenario_file) {
  if (!scene.IsDefined() || scene.IsNull()) return models::OpenFloor();
  if (!r.ExpectMap(scene, "scene")) return models::OpenFloor();
  const YAML::Node model_node = Child(scene, "model");
  if (!model_node.IsDefined()) {
    // No file: the open floor, with what the scenario writes added to it or
    // overriding it.
    std::map<std::string, ScenarioSource> sources;
    std::vector<EmptyListOver> empty;
    const YAML::Node merged = Merge(OpenFloorTree(), scene, "scene", sources, empty);
    RefuseEmptyLists(r, empty, "the open floor's");
    models::Scene out;
    out.name = fs::path(scenario_file).stem().string();
    out.file = scenario_file;
    SceneParser(r, out).Parse(merged, "scene", true);
    return out;
  }
  const auto model_name = r.AsString(model_node, "scene.model");
  if (!model_name) return models::OpenFloor();
  std::string file;
  const YAML::Node model =
      LoadModel(r, model_node, "scene.model", "scene", *model_name, "scenes", scenario_file, &file);
  if (!model.IsDefined()) {
    // Without the file there is nothing to merge onto; its keys can still
    // be checked.
    std::vector<std::string> keys = kSceneKeys;
    keys.insert(keys.begin(), "model");
    r.CheckKeys(scene, "scene", keys);
    return models::OpenFloor();
  }
  const std::string name = fs::path(file).stem().string();

  // The scene file alone first: its problems are its own, at its lines.
  {
    const std::size_t before = r.issues().size();
    const YamlReader::InFile in_scene(r, file);
    models::Scene alone = ReadScene(r, model, "", name, file);
    if (r.issues().size() != before) return models::OpenFloor();
    if (scene.size() == 1) return alone;  // only `model`
  }

  // Then the scenario's keys on top. What goes wrong now is the scenario's
  // doing: each problem is reported at the scenario's key path under
  // `scene`, at the line of the nearest node the scenario writes.
  std::map<std::string, ScenarioSource> sources;
  std::vector<EmptyListOver> empty;
  const YAML::Node merged = Merge(model, scene, "scene", sources, empty);
  RefuseEmptyLists(r, empty, "the scene file's");
  YamlReader merged_reader(file);
  // A contradiction is reported at the key the command line set.
  merged_reader.ShareCommandLine(r);
  models::Scene out = ReadScene(merged_reader, merged, "scene", name, file);
  for (const Issue& issue : merged_reader.issues()) {
    std::string p = issue.key_path;
    auto it = sources.find(p);
    while (it == sources.end() && p.find('.') != std::string::npos) {
      p = p.substr(0, p.rfind('.'));
      it = sources.find(p);
    }
    const bool exact = it != sources.end() && p == issue.key_path;
    const YAML::Node at = it == sources.end()
                              ? scene
                              : (exact && issue.unknown_path ? it->second.key : it->second.value);
    const std::string& key_path = issue.key_path;
    if (issue.unknown_path) {
      r.UnknownPath(at, key_path, issue.message);
    } else {
      r.Error(at, key_path, issue.message);
    }
  }
  return out;
}

void ExposeSceneModelToOverrides(YAML::Node& root, const std::vector<Override>& overrides,
                                 const std::string& scenario_file) {
  YAML::Node scene = Child(root, "scene");
  const YAML::Node model = Child(scene, "model");
  if (!scene.IsMap() || !model.IsScalar()) return;
  std::optional<YAML::Node> file_scene;
  for (const Override& o : overrides) {
    const std::string prefix = "scene.";
    if (!o.path.starts_with(prefix)) continue;
    const std::string rest = o.path.substr(prefix.size());
    const std::string key = rest.substr(0, rest.find('.'));
    // A whole top-level value set at once needs nothing from the file.
    if (key.empty() || key == rest || Child(scene, key).IsDefined()) continue;
    if (!file_scene) {
      YamlReader quiet(scenario_file);
      file_scene =
          LoadModel(quiet, model, "scene.model", "scene", model.Scalar(), "scenes", scenario_file);
    }
    if (const YAML::Node value = Child(*file_scene, key); value.IsDefined()) {
      scene[key] = YAML::Clone(value);
    }
  }
}

}  // namespace linesim::loader
