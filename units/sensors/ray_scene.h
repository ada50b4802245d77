#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "models/scene.h"

// Embree's handles, without its header.
struct RTCDeviceTy;
struct RTCSceneTy;

namespace linesim::sensors {

/// One ray for RayScene::Cast: origin and unit direction in the map frame,
/// the longest range of interest, and when it is cast, as seconds after the
/// time at which the belts' travels passed to Cast hold (the carried objects
/// are placed where the belts have moved them by then).
struct Ray {
  std::array<double, 3> origin{};
  std::array<double, 3> direction{};
  double max_range = 0.0;
  double dt_s = 0.0;
};

/// What a ray meets first.
struct RayHit {
  /// Distance along the ray (m); +inf when it meets nothing within max_range.
  double range = 0.0;
  /// |cos| of the angle between the ray and the surface normal there.
  double cos_incidence = 0.0;
  /// Which scene object: RayScene::kFloor, then the obstacles, the terrain
  /// pieces and the carried objects in scene order (RayScene::ObjectOf*);
  /// -1 when nothing is met.
  int object = -1;
};

/// The geometry a range sensor sees, built once from a models::Scene.
///
/// Static geometry (the floor's rectangle at z = 0, obstacle boxes and
/// cylinders, terrain pieces) is one Embree user geometry, a primitive per
/// solid with its bounds padded: Embree only finds the candidates a ray may
/// meet (its BVH traversal, in single precision, with kernels it picks by CPU
/// at run time), and each candidate is intersected exactly in double by the
/// solid's own equation (IntersectOrientedBox, IntersectCylinder, the floor's
/// plane). The nearest exact hit wins, ties to the lower object index, and
/// Embree's far distance is only ever shortened to a value rounded up from
/// it. So a range does not depend on which kernels Embree chose (SSE2 to
/// AVX-512), on its BVH or on the order it visits candidates: the same bytes
/// on every x86-64 machine. Measured on BM_RayScene* (bench/laser_bench.cc).
///
/// Objects carried by belts move every step; re-committing Embree instance
/// transforms costs 10-15 us a frame, so they are not in the Embree scene:
/// each ray is intersected analytically with each carried box or cylinder in
/// its own frame at the ray's time (footprint moved along the belt's
/// direction by the belt's travel then; absent once the travel leaves
/// models::CarriedTravelRange, the object has been lifted off the line).
/// Per group of 16 rays (kCullGroup), the objects whose bounding sphere (swept over the
/// rays' times) lies off the cone holding the rays, or beyond their reach,
/// are skipped for the whole group (a conservative cull: exactness kept).
///
/// One RayScene per unit: it owns its Embree device (created single-threaded
/// with "threads=1"; `LINESIM_EMBREE_MAX_ISA`, e.g. sse2, caps Embree's
/// kernels, so that a test can show that they do not matter) and is not
/// shared between threads. Not copyable.
class RayScene {
 public:
  static constexpr int kFloor = 0;
  /// Rays culled together against the carried objects (two packets).
  static constexpr std::size_t kCullGroup = 16;

  explicit RayScene(const models::Scene& scene);
  ~RayScene();
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  /// The first hit of each ray (`hits` has room for rays.size()).
  /// `belt_travel` and `belt_speed` (m, m/s; one per scene belt) are the
  /// belts' travel at the rays' reference time and their speed: a carried
  /// object is at travel + speed * dt_s along its belt. No allocation.
  /// `moving` (7 numbers per cylinder: [x, y, vx, vy, radius, z_bottom,
  /// z_top], m and m/s, at the rays' reference time; empty for none): other
  /// moving things (workers' legs and torsos), each a vertical cylinder at
  /// (x + vx dt_s, y + vy dt_s) when a ray is cast, intersected exactly
  /// after the static and carried objects (no culling: a few cylinders).
  /// `moving_boxes` (models::MovingBox values: robots' bodies) the same,
  /// each a yawed box at its pose moved on by its velocity and yaw rate to
  /// the ray's time, except box `own_box` (the scanner's own robot; -1:
  /// none).
  void Cast(std::span<const Ray> rays, std::span<RayHit> hits, std::span<const double> belt_travel,
            std::span<const double> belt_speed, std::span<const double> moving = {},
            std::span<const double> moving_boxes = {}, int own_box = -1);

  int ObjectOfObstacle(int i) const { return 1 + i; }
  int ObjectOfTerrain(int i) const { return 1 + obstacle_count_ + i; }
  int ObjectOfCarried(int i) const { return 1 + obstacle_count_ + terrain_count_ + i; }
  /// Moving cylinder i of Cast's `moving`; its moving box j is
  /// ObjectOfMoving(cylinders + j).
  int ObjectOfMoving(int i) const {
    return 1 + obstacle_count_ + terrain_count_ + static_cast<int>(carried_.size()) + i;
  }
  static constexpr std::size_t kMovingValues = 7;

  /// A vertical cylinder (an obstacle, or a carried one where its belt puts it).
  struct Cylinder {
    double x, y, radius, z0, z1;
    int object;
  };
  /// A static solid: a primitive of the Embree user geometry.
  struct StaticSolid {
    enum class Kind { kFloor, kBox, kCylinder } kind;
    int object;
    /// kFloor: the rectangle [min_x, max_x] x [min_y, max_y] at z = 0.
    double floor_min_x, floor_max_x, floor_min_y, floor_max_y;
    /// kBox: centre, half sizes along its unit axes.
    std::array<double, 3> center, half;
    std::array<std::array<double, 3>, 3> axes;
    /// kCylinder.
    Cylinder cylinder;
    /// The padded bounds Embree tests (float, rounded outwards).
    std::array<float, 3> lower, upper;
  };
  /// The best exact hit of a lane of the packet being cast (for the callback).
  struct Lane {
    const Ray* ray;
    double t_max;  // just above the ray's max_range: a hit there counts
    RayHit best;
  };
  /// For the Embree callbacks: a static solid, and the exact intersection
  /// of a lane of the packet being cast with one (keeps the lane's nearest
  /// hit; shortens Embree's far distance `tfar` to it, rounded up).
  const StaticSolid& Solid(unsigned prim) const { return solids_[prim]; }
  void IntersectLaneOf(unsigned prim, unsigned lane, float& tfar);

  /// A carried object with its belt: footprint at zero travel.
  struct Carried {
    models::Solid solid;
    int belt;
    double ux, uy;                 // the belt's direction
    double travel_min, travel_max;  // models::CarriedTravelRange
    double cos_yaw, sin_yaw;
    int object;
    double bound_radius2;  // squared radius of the footprint's bounding circle
    double center_z;       // the middle of its height
    double sphere_radius;  // its bounding sphere's radius (about (x, y, center_z))
  };

 private:
  void AddBox(const std::array<double, 3>& center, const std::array<double, 3>& half,
              const std::array<std::array<double, 3>, 3>& axes, int object);
  /// A solid's bounds for Embree, padded (its float traversal never misses it).
  static void SetBounds(StaticSolid& s, std::array<double, 3> lo, std::array<double, 3> hi);
  /// The carried objects (of `candidates`, indices into carried_) met
  /// before `best` (updated in place).
  void CastCarried(const Ray& ray, std::span<const int> candidates,
                   std::span<const double> belt_travel, std::span<const double> belt_speed,
                   RayHit& best) const;
  /// The moving cylinders met before `best` (updated in place).
  void CastMoving(const Ray& ray, std::span<const double> moving, RayHit& best) const;
  /// The moving boxes of `candidates` (indices into `boxes`) met before
  /// `best` (updated in place); box i is object ObjectOfMoving(first_object + i).
  void CastMovingBoxes(const Ray& ray, std::span<const double> boxes,
                       std::span<const int> candidates, int first_object, RayHit& best) const;
  /// A group of rays as a cone (CullCarried, CullMovingBoxes): apex a,
  /// unit axis ax, half angle th, origins within rho of a, times
  /// s_mid +- s_half, reach t_far, heights [z_lo, z_hi] within the reach.
  struct Bundle {
    double a[3] = {0, 0, 0}, ax[3] = {0, 0, 0};
    double cos_th = -1.0, sin_th = 0.0, rho = 0.0, t_far = 0.0, s_mid = 0.0, s_half = 0.0;
    double z_lo = std::numeric_limits<double>::infinity();
    double z_hi = -std::numeric_limits<double>::infinity();
    double z_pad = 0.0;
    static Bundle Of(std::span<const Ray> rays);
    /// Whether a sphere of `radius` about (cx, cy, cz), of a solid spanning
    /// the heights [z_bottom, z_top], may meet a ray of the bundle
    /// (conservative).
    bool MayMeet(double cx, double cy, double cz, double radius, double z_bottom,
                 double z_top) const;
  };
  /// What the culls and the exact tests need of each moving box, worked
  /// out once per Cast call (into prepared_) instead of once per group.
  void PrepareMovingBoxes(std::span<const double> boxes, int own_box);
  /// The moving boxes a bundle may meet (into box_candidates_, their spheres
  /// swept over the bundle's times); returns the count.
  int CullMovingBoxes(const Bundle& bundle, std::span<const double> boxes);
  /// The carried objects a bundle of rays may meet (into candidates_):
  /// their bounding spheres, where their belts put them over the rays'
  /// times, against the bundle's cone. Returns the count.
  int CullCarried(const Bundle& bundle, std::span<const double> belt_travel,
                  std::span<const double> belt_speed);

  RTCDeviceTy* device_ = nullptr;
  RTCSceneTy* scene_ = nullptr;
  int obstacle_count_ = 0, terrain_count_ = 0;
  std::vector<StaticSolid> solids_;
  std::array<Lane, 16> lanes_{};  // the packet being cast
  std::vector<Carried> carried_;
  std::vector<int> candidates_;      // CullCarried's answer (carried_.size() long)
  std::vector<int> box_candidates_;  // CullMovingBoxes' answer
  struct PreparedBox {
    bool present;   // sized, and not the scanner's own robot
    double radius;  // its bounding sphere's radius
    double padded;  // the same, padded for rounding (the exact test decides)
    double speed;   // of its centre
    double cos_yaw, sin_yaw;
  };
  std::vector<PreparedBox> prepared_;
};

/// Exact first intersection (t > 1e-9, t < t_max) of a ray with a vertical
/// cylinder (side and caps): t, and the unit normal in `normal`; +inf when
/// none. Used by RayScene and its tests.
double IntersectCylinder(const RayScene::Cylinder& c, const double* o, const double* d,
                         double t_max, double* normal);
/// The same for a box given by its centre, its half sizes along its unit axes
/// (rows of `axes`).
double IntersectOrientedBox(const std::array<double, 3>& center, const std::array<double, 3>& half,
                            const std::array<std::array<double, 3>, 3>& axes, const double* o,
                            const double* d, double t_max, double* normal);
/// The same for a box given by its centre, half sizes along its yaw-rotated
/// x, y and the vertical, and cos / sin of its yaw.
double IntersectYawedBox(double cx, double cy, double cz, double hx, double hy, double hz,
                         double cos_yaw, double sin_yaw, const double* o, const double* d,
                         double t_max, double* normal);

}  // namespace linesim::sensors
