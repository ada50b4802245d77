#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "models/surface_profile.h"

/// The typed description of a scene (models/scenes/*.yaml): the floor and
/// its surfaces, the belts of the line, static obstacles, objects the belts
/// carry, and 3D terrain pieces. Read once by the loader (loader/scene_file.h)
/// and handed to every unit that needs geometry (chassis, belt, sensors,
/// plots), which builds its own structures from it. All in the map frame
/// (x, y on the floor, z up), SI units.
namespace linesim::models {

/// A floor covering. The optical numbers are what an optic-flow sensor
/// looking down at it sees.
struct Surface {
  std::string name;
  /// Coulomb coefficient of a robot wheel's tread on it (dimensionless),
  /// for a tread material without a pair of its own (tread_friction).
  double friction = 0.0;
  /// Texture contrast (dimensionless, 0..1): the standard deviation of the
  /// surface's reflectance over its mean, at the scale of a few millimetres
  /// that a downward camera 0.1-0.2 m above it resolves. 0 is a featureless
  /// surface (no flow can be measured); 0.3 a strongly textured one.
  double texture_contrast = 0.0;
  /// Ambient illumination on the surface (lux), before any light the robot
  /// adds. Factory halls are lit at 300-750 lx (EN 12464-1 gives 300 lx
  /// for rough assembly, 500 lx for medium work).
  double illumination_lux = 0.0;
  /// Flicker of the ambient light (not of a robot's own light): lamps on
  /// AC mains flicker at twice the mains frequency (100 Hz at 50 Hz mains,
  /// 120 Hz at 60 Hz); 0: steady light.
  double flicker_hz = 0.0;
  /// Its modulation depth (max - min) / (max + min) of the illuminance
  /// (IEEE 1789-2015 "percent flicker" / 100): about 0.1 incandescent,
  /// 0.3-0.4 fluorescent on magnetic ballasts, up to 1 for some LED drivers.
  double flicker_depth = 0.0;
  /// Standard deviation (m) of the surface's height profile under a rolling
  /// wheel (joints of slats, the weave of a belt, floor unevenness): what
  /// shakes a robot that rolls over it. 0: perfectly flat.
  double roughness_m = 0.0;
  /// Correlation length (m) of that profile along the path (the slat pitch
  /// or the size of the bumps).
  double roughness_length_m = 0.01;
  /// Period (m) of a periodic part of the texture along the belt's
  /// direction (slats, a weave); 0: none.
  double texture_period_m = 0.0;
  /// Share (0..1) of the texture's contrast that is periodic.
  double texture_periodic_share = 0.0;
  /// The height profile wheels ride on where this surface is the floor or a
  /// terrain piece's top (belts stay level): ISO 8608's spectrum over a
  /// band of wavelengths (models/surface_profile.h). Flat by default.
  Unevenness unevenness = {};
  /// Coulomb coefficient per tread material (models::TreadDescription's
  /// material: rubber, polyurethane, ...): friction per pair of materials.
  std::map<std::string, double> tread_friction = {};
  /// The friction of a tread of `material` on it.
  double FrictionFor(const std::string& material) const {
    const auto it = tread_friction.find(material);
    return it == tread_friction.end() ? friction : it->second;
  }
};

/// A rectangle on the floor: centre, size, and the direction of its length
/// axis (counter-clockwise from map x).
struct Rect {
  double center_x_m = 0.0;
  double center_y_m = 0.0;
  double length_m = 0.0;  // along direction_rad
  double width_m = 0.0;   // across it
  double direction_rad = 0.0;
};

/// A switch of a belt's drive at a time.
struct BeltSwitch {
  std::int64_t time_ns = 0;
  bool on = false;
};

/// A conveyor belt of the line: a moving patch of the floor, flush with it.
struct Belt {
  std::string name;
  Rect area;
  /// Index into Scene::surfaces of its top (its friction and optics).
  int surface = 0;
  /// The open gap between the belt's edges and the floor around it (m): a
  /// wheel's contact patch over it carries nothing.
  double edge_gap_m = 0.0;
  double nominal_speed_mps = 0.0;
  /// Relative amplitude of the slow speed variation (0.1: +-10 %).
  double speed_variation = 0.0;
  double variation_period_s = 1.0;
  /// Acceleration when it starts or stops.
  double acceleration_mps2 = 1.0;
  bool initially_on = true;
  /// Later switches, in increasing time, all after time zero.
  std::vector<BeltSwitch> schedule;
};

/// A solid shape standing on something: a box or a vertical cylinder.
struct Solid {
  enum class Kind { kBox, kCylinder };
  Kind kind = Kind::kBox;
  /// Centre of the footprint in map, and its heading (boxes).
  double x_m = 0.0;
  double y_m = 0.0;
  double yaw_rad = 0.0;
  /// Box: size along its heading and across it. Cylinder: radius.
  double length_m = 0.0;
  double width_m = 0.0;
  double radius_m = 0.0;
  /// Bottom and top above the floor (a car body on skids starts above it).
  double bottom_m = 0.0;
  double height_m = 0.0;  // top = bottom + height
};

/// A box footprint centred at (x, y), `length` along heading `yaw`.
inline Solid BoxSolid(double x_m, double y_m, double yaw_rad, double length_m, double width_m,
                      double height_m, double bottom_m = 0.0) {
  Solid s;
  s.kind = Solid::Kind::kBox;
  s.x_m = x_m;
  s.y_m = y_m;
  s.yaw_rad = yaw_rad;
  s.length_m = length_m;
  s.width_m = width_m;
  s.height_m = height_m;
  s.bottom_m = bottom_m;
  return s;
}

/// A vertical cylinder on the footprint centre (x, y).
inline Solid CylinderSolid(double x_m, double y_m, double radius_m, double height_m,
                           double bottom_m = 0.0) {
  Solid s;
  s.kind = Solid::Kind::kCylinder;
  s.x_m = x_m;
  s.y_m = y_m;
  s.radius_m = radius_m;
  s.height_m = height_m;
  s.bottom_m = bottom_m;
  return s;
}

/// A static obstacle: a wall, a pillar, a part cart, a rack.
struct Obstacle {
  std::string name;
  std::string kind;  // wall, pillar, cart, rack, vehicle (a van), beacon (a reflector)
  Solid solid;
};

/// An object a belt carries (a car body): at time zero where `solid` says;
/// later moved along the belt's direction by the belt's travelled distance.
struct CarriedObject {
  std::string name;
  int belt = 0;  // index into Scene::belts
  Solid solid;
};

/// A rigid 3D terrain piece: a box placed and tilted (a ramp, a raised
/// floor). Its top face is what a wheel drives on.
struct TerrainPiece {
  std::string name;
  double center_x_m = 0.0, center_y_m = 0.0, center_z_m = 0.0;
  double length_m = 0.0, width_m = 0.0, thickness_m = 0.0;
  /// Heading of its length axis, then the tilt about its own width axis
  /// (+ raises the far end) and about its length axis.
  double yaw_rad = 0.0, pitch_rad = 0.0, roll_rad = 0.0;
  int surface = 0;  // index into Scene::surfaces
};

/// The axes of terrain piece `t` in map: the columns of R = Rz(yaw)
/// Ry(-pitch) Rx(roll) (+ pitch raises the far, + length, end): along its
/// length, across its width, and along its thickness (the top face's
/// outward normal).
inline std::array<std::array<double, 3>, 3> TerrainAxes(const TerrainPiece& t) {
  const double cy = std::cos(t.yaw_rad), sy = std::sin(t.yaw_rad);
  const double cp = std::cos(-t.pitch_rad), sp = std::sin(-t.pitch_rad);
  const double cr = std::cos(t.roll_rad), sr = std::sin(t.roll_rad);
  return {{{cy * cp, sy * cp, -sp},
           {cy * sp * sr - sy * cr, sy * sp * sr + cy * cr, cp * sr},
           {cy * sp * cr + sy * sr, sy * sp * cr - cy * sr, cp * cr}}};
}

/// Height of terrain piece `t`'s top face over map point (x, y), or nothing
/// when the vertical through it misses the top face.
inline std::optional<double> TerrainTopAt(const TerrainPiece& t, double x, double y) {
  const auto axes = TerrainAxes(t);
  const auto& n = axes[2];
  if (n[2] <= 0.0) return std::nullopt;  // tilts are within +-89 degrees
  const double h = 0.5 * t.thickness_m;
  const double px = t.center_x_m + h * n[0], py = t.center_y_m + h * n[1],
               pz = t.center_z_m + h * n[2];
  const double z = pz - (n[0] * (x - px) + n[1] * (y - py)) / n[2];
  const double dx = x - px, dy = y - py, dz = z - pz;
  const double along = axes[0][0] * dx + axes[0][1] * dy + axes[0][2] * dz;
  const double across = axes[1][0] * dx + axes[1][1] * dy + axes[1][2] * dz;
  if (std::abs(along) > 0.5 * t.length_m || std::abs(across) > 0.5 * t.width_m) {
    return std::nullopt;
  }
  return z;
}

/// The hall: the floor's extent and its covering.
struct Floor {
  double min_x_m = 0.0, max_x_m = 0.0, min_y_m = 0.0, max_y_m = 0.0;
  int surface = 0;  // index into Scene::surfaces
};

struct Scene {
  std::string name;
  std::string description;
  /// The file it was read from (for messages); empty for a scene built in code.
  std::string file;
  std::vector<Surface> surfaces;
  Floor floor;
  std::vector<Belt> belts;
  std::vector<Obstacle> obstacles;
  std::vector<CarriedObject> carried;
  std::vector<TerrainPiece> terrain;

  /// Index of the surface called `name`, if any.
  std::optional<int> FindSurface(const std::string& name) const {
    for (std::size_t i = 0; i < surfaces.size(); ++i) {
      if (surfaces[i].name == name) return static_cast<int>(i);
    }
    return std::nullopt;
  }
};

/// Whether map point (x, y) lies in the rotated rectangle `r` (edges count
/// as inside); `cos_dir`, `sin_dir`: cosine and sine of r.direction_rad, which
/// callers testing many points cache.
inline bool InsideRect(const Rect& r, double cos_dir, double sin_dir, double x, double y) {
  const double dx = x - r.center_x_m, dy = y - r.center_y_m;
  const double along = dx * cos_dir + dy * sin_dir, across = -dx * sin_dir + dy * cos_dir;
  return std::abs(along) <= 0.5 * r.length_m && std::abs(across) <= 0.5 * r.width_m;
}

/// Which belt of a scene a map point lies on, with each belt's direction
/// cached (estimators ask this for every wheel and sensor every step).
class BeltMap {
 public:
  BeltMap() = default;
  explicit BeltMap(const std::vector<Belt>& belts) {
    for (const Belt& b : belts) {
      areas_.push_back({b.area, std::cos(b.area.direction_rad), std::sin(b.area.direction_rad)});
    }
  }
  std::size_t size() const { return areas_.size(); }
  /// 0 over the floor, k + 1 over belt k (the first that holds the point).
  int At(double x, double y) const {
    for (std::size_t k = 0; k < areas_.size(); ++k) {
      const Area& a = areas_[k];
      if (InsideRect(a.rect, a.cos_dir, a.sin_dir, x, y)) return static_cast<int>(k) + 1;
    }
    return 0;
  }

 private:
  struct Area {
    Rect rect;
    double cos_dir, sin_dir;
  };
  std::vector<Area> areas_;
};

/// The belt travel over which an object a belt carries (its footprint at
/// zero travel: `solid`) lies along the belt's length (`belt_area`): its
/// footprint's extent along the belt axis within the belt's two ends.
/// {min, max}; min > 0 or max < 0 when it does not lie on the belt at zero
/// travel. Outside the range the object has been lifted off the line.
inline std::array<double, 2> CarriedTravelRange(const Rect& belt_area, const Solid& solid) {
  const double ax = std::cos(belt_area.direction_rad), ay = std::sin(belt_area.direction_rad);
  // Half the footprint's extent along the belt axis.
  double half = solid.radius_m;
  if (solid.kind == Solid::Kind::kBox) {
    const double d = solid.yaw_rad - belt_area.direction_rad;
    half = 0.5 * (solid.length_m * std::abs(std::cos(d)) + solid.width_m * std::abs(std::sin(d)));
  }
  const double along =
      (solid.x_m - belt_area.center_x_m) * ax + (solid.y_m - belt_area.center_y_m) * ay;
  return {-0.5 * belt_area.length_m + half - along, 0.5 * belt_area.length_m - half - along};
}

/// The scene of a scenario that names none: an unbounded floor of one
/// surface, sealed concrete under a polyurethane tread (friction 0.8, the
/// middle of the 0.6-0.9 usual for such a pair), moderately textured, in a
/// hall lit at 500 lx (EN 12464-1, medium assembly work). No belts, no
/// obstacles.
inline Scene OpenFloor() {
  Scene s;
  s.name = "open_floor";
  s.description = "an unbounded concrete floor";
  s.surfaces.push_back({"concrete", 0.8, 0.2, 500.0});
  s.floor = {-1e6, 1e6, -1e6, 1e6, 0};
  return s;
}

}  // namespace linesim::models
