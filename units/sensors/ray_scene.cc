#include "units/sensors/ray_scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>

#include "models/moving_solids.h"
#include "platform/provenance.h"

namespace linesim::sensors {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kTMin = 1e-9;

// The Embree user geometry's callbacks: bounds and exact intersection.
void SolidBounds(const RTCBoundsFunctionArguments* args) {
  const auto* scene = static_cast<const RayScene*>(args->geometryUserPtr);
  const RayScene::StaticSolid& sd = scene->Solid(args->primID);
  RTCBounds* b = args->bounds_o;
  b->lower_x = sd.lower[0];
  b->lower_y = sd.lower[1];
  b->lower_z = sd.lower[2];
  b->upper_x = sd.upper[0];
  b->upper_y = sd.upper[1];
  b->upper_z = sd.upper[2];
}

void SolidIntersect(const RTCIntersectFunctionNArguments* args) {
  auto* scene = static_cast<RayScene*>(args->geometryUserPtr);
  RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, args->N);
  for (unsigned i = 0; i < args->N; ++i) {
    if (!args->valid[i]) continue;
    scene->IntersectLaneOf(args->primID, RTCRayN_id(ray, args->N, i),
                           RTCRayN_tfar(ray, args->N, i));
  }
}

// Rays per Embree packet; the lane index travels as the ray's id.
template <class Packet, std::size_t N>
void IntersectPacket(std::span<const Ray> rays, RTCScene scene, RTCIntersectContext* context) {
  alignas(64) Packet packet;
  alignas(64) int valid[N];
  const std::size_t count = rays.size();
  for (std::size_t k = 0; k < N; ++k) {
    valid[k] = k < count ? -1 : 0;
    const Ray& r = rays[std::min(k, count - 1)];
    packet.ray.org_x[k] = static_cast<float>(r.origin[0]);
    packet.ray.org_y[k] = static_cast<float>(r.origin[1]);
    packet.ray.org_z[k] = static_cast<float>(r.origin[2]);
    packet.ray.dir_x[k] = static_cast<float>(r.direction[0]);
    packet.ray.dir_y[k] = static_cast<float>(r.direction[1]);
    packet.ray.dir_z[k] = static_cast<float>(r.direction[2]);
    packet.ray.tnear[k] = 0.0f;
    // Beyond max_range by a margin: the exact distance is decided in double.
    packet.ray.tfar[k] = static_cast<float>(r.max_range * (1.0 + 1e-5) + 1e-4);
    packet.ray.time[k] = 0.0f;
    packet.ray.mask[k] = ~0u;
    packet.ray.id[k] = static_cast<unsigned>(std::min(k, count - 1));
    packet.ray.flags[k] = 0;
    packet.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
    packet.hit.primID[k] = RTC_INVALID_GEOMETRY_ID;
    packet.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
  }
  if constexpr (N == 16) {
    rtcIntersect16(valid, scene, context, &packet);
  } else {
    rtcIntersect8(valid, scene, context, &packet);
  }
}

// What Embree's dispatch picks on this CPU (its rule: the widest kernels the
// CPU and the build have), capped by LINESIM_EMBREE_MAX_ISA: for provenance.
std::string KernelIsa(const char* max_isa) {
  __builtin_cpu_init();
  const bool avx512 = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512cd") &&
                      __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw") &&
                      __builtin_cpu_supports("avx512vl");
  const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
                    __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2");
  const char* order[] = {"avx512", "avx2", "avx", "sse4.2", "sse2"};
  const bool have[] = {avx512, avx2, __builtin_cpu_supports("avx") != 0,
                       __builtin_cpu_supports("sse4.2") != 0, true};
  bool capped = max_isa != nullptr;
  for (std::size_t i = 0; i < 5; ++i) {
    if (capped && std::string(max_isa) != order[i]) continue;
    capped = false;
    if (have[i]) return order[i];
  }
  return "sse2";
}

}  // namespace

double IntersectCylinder(const RayScene::Cylinder& c, const double* o, const double* d,
                         double t_max, double* normal) {
  double best = kInf;
  const double px = o[0] - c.x, py = o[1] - c.y;
  // Side: |p_xy + t d_xy| = r.
  const double a = d[0] * d[0] + d[1] * d[1];
  if (a > 0.0) {
    const double b = px * d[0] + py * d[1];  // half of the linear coefficient
    const double cc = px * px + py * py - c.radius * c.radius;
    const double disc = b * b - a * cc;
    if (disc >= 0.0) {
      const double s = std::sqrt(disc);
      // Entry first; from inside (cc < 0) the exit, the inner wall.
      // The root formula without cancellation: t1 t2 = cc / a.
      const double q = -(b + std::copysign(s, b));
      double t1 = q / a, t2 = q != 0.0 ? cc / q : t1;
      if (t1 > t2) std::swap(t1, t2);
      for (double t : {t1, t2}) {
        if (t <= kTMin || t >= t_max || t >= best) continue;
        const double z = o[2] + t * d[2];
        if (z < c.z0 || z > c.z1) continue;
        best = t;
        normal[0] = (px + t * d[0]) / c.radius;
        normal[1] = (py + t * d[1]) / c.radius;
        normal[2] = 0.0;
        break;
      }
    }
  }
  // Caps.
  if (d[2] != 0.0) {
    for (double z : {c.z0, c.z1}) {
      const double t = (z - o[2]) / d[2];
      if (t <= kTMin || t >= t_max || t >= best) continue;
      const double x = px + t * d[0], y = py + t * d[1];
      if (x * x + y * y > c.radius * c.radius) continue;
      best = t;
      normal[0] = 0.0;
      normal[1] = 0.0;
      normal[2] = z == c.z1 ? 1.0 : -1.0;
    }
  }
  return best;
}

double IntersectOrientedBox(const std::array<double, 3>& center, const std::array<double, 3>& half,
                            const std::array<std::array<double, 3>, 3>& axes, const double* o,
                            const double* d, double t_max, double* normal) {
  const double p[3] = {o[0] - center[0], o[1] - center[1], o[2] - center[2]};
  double t_in = -kInf, t_out = kInf;
  int axis = -1;
  double sign = 0.0;
  for (std::size_t k = 0; k < 3; ++k) {
    const auto& a = axes[k];
    const double lo = a[0] * p[0] + a[1] * p[1] + a[2] * p[2];
    const double ld = a[0] * d[0] + a[1] * d[1] + a[2] * d[2];
    if (ld == 0.0) {
      if (lo < -half[k] || lo > half[k]) return kInf;
      continue;
    }
    const double inv = 1.0 / ld;
    double t0 = (-half[k] - lo) * inv, t1 = (half[k] - lo) * inv;
    double s = -1.0;  // the face entered: -half when moving +
    if (t0 > t1) {
      std::swap(t0, t1);
      s = 1.0;
    }
    if (t0 > t_in) {
      t_in = t0;
      axis = static_cast<int>(k);
      sign = s;
    }
    t_out = std::min(t_out, t1);
  }
  // A ray starting inside sees nothing of it (a sensor is never inside).
  if (axis < 0 || t_in > t_out || t_in <= kTMin || t_in >= t_max) return kInf;
  const auto& n = axes[static_cast<std::size_t>(axis)];
  normal[0] = sign * n[0];
  normal[1] = sign * n[1];
  normal[2] = sign * n[2];
  return t_in;
}

double IntersectYawedBox(double cx, double cy, double cz, double hx, double hy, double hz,
                         double cos_yaw, double sin_yaw, const double* o, const double* d,
                         double t_max, double* normal) {
  return IntersectOrientedBox({cx, cy, cz}, {hx, hy, hz},
                              {{{cos_yaw, sin_yaw, 0.0}, {-sin_yaw, cos_yaw, 0.0}, {0.0, 0.0, 1.0}}},
                              o, d, t_max, normal);
}

RayScene::RayScene(const models::Scene& scene)
    : obstacle_count_(static_cast<int>(scene.obstacles.size())),
      terrain_count_(static_cast<int>(scene.terrain.size())) {
  // Single-threaded: without "threads=1" Embree starts a worker per core.
  // The kernels Embree picks do not change a range (see the class comment);
  // LINESIM_EMBREE_MAX_ISA caps them to show it.
  const char* max_isa = std::getenv("LINESIM_EMBREE_MAX_ISA");
  std::string config = "threads=1";
  if (max_isa != nullptr && *max_isa != '\0') config += std::string(",max_isa=") + max_isa;
  device_ = rtcNewDevice(config.c_str());
  if (!device_) {
    throw std::runtime_error("Embree: cannot create a device with \"" + config + "\" (error " +
                             std::to_string(static_cast<int>(rtcGetDeviceError(nullptr))) + ")");
  }
  platform::RecordDispatch(
      "embree", KernelIsa(max_isa != nullptr && *max_isa != '\0' ? max_isa : nullptr) +
                    " kernels (ranges independent of them: exact intersection in double)");
  scene_ = rtcNewScene(device_);
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);

  const models::Floor& f = scene.floor;
  {
    StaticSolid floor{};
    floor.kind = StaticSolid::Kind::kFloor;
    floor.object = kFloor;
    floor.floor_min_x = f.min_x_m;
    floor.floor_max_x = f.max_x_m;
    floor.floor_min_y = f.min_y_m;
    floor.floor_max_y = f.max_y_m;
    SetBounds(floor, {f.min_x_m, f.min_y_m, 0.0}, {f.max_x_m, f.max_y_m, 0.0});
    solids_.push_back(floor);
  }
  for (int i = 0; i < obstacle_count_; ++i) {
    const models::Solid& s = scene.obstacles[static_cast<std::size_t>(i)].solid;
    if (s.kind == models::Solid::Kind::kCylinder) {
      StaticSolid cyl{};
      cyl.kind = StaticSolid::Kind::kCylinder;
      cyl.object = ObjectOfObstacle(i);
      cyl.cylinder = {s.x_m, s.y_m, s.radius_m, s.bottom_m, s.bottom_m + s.height_m, cyl.object};
      SetBounds(cyl, {s.x_m - s.radius_m, s.y_m - s.radius_m, s.bottom_m},
                {s.x_m + s.radius_m, s.y_m + s.radius_m, s.bottom_m + s.height_m});
      solids_.push_back(cyl);
      continue;
    }
    const double c = std::cos(s.yaw_rad), sn = std::sin(s.yaw_rad);
    AddBox({s.x_m, s.y_m, s.bottom_m + 0.5 * s.height_m},
           {0.5 * s.length_m, 0.5 * s.width_m, 0.5 * s.height_m},
           {{{c, sn, 0.0}, {-sn, c, 0.0}, {0.0, 0.0, 1.0}}}, ObjectOfObstacle(i));
  }
  for (int i = 0; i < terrain_count_; ++i) {
    const models::TerrainPiece& t = scene.terrain[static_cast<std::size_t>(i)];
    AddBox({t.center_x_m, t.center_y_m, t.center_z_m},
           {0.5 * t.length_m, 0.5 * t.width_m, 0.5 * t.thickness_m}, models::TerrainAxes(t),
           ObjectOfTerrain(i));
  }
  for (std::size_t i = 0; i < scene.carried.size(); ++i) {
    const models::CarriedObject& co = scene.carried[i];
    const models::Belt& belt = scene.belts.at(static_cast<std::size_t>(co.belt));
    const auto range = models::CarriedTravelRange(belt.area, co.solid);
    carried_.push_back({co.solid, co.belt, std::cos(belt.area.direction_rad),
                        std::sin(belt.area.direction_rad), range[0], range[1],
                        std::cos(co.solid.yaw_rad), std::sin(co.solid.yaw_rad),
                        ObjectOfCarried(static_cast<int>(i)), 0.0, 0.0, 0.0});
    const models::Solid& s = co.solid;
    const double br = s.kind == models::Solid::Kind::kCylinder
                          ? s.radius_m
                          : 0.5 * std::hypot(s.length_m, s.width_m);
    carried_.back().bound_radius2 = (br + 1e-6) * (br + 1e-6);
    carried_.back().center_z = s.bottom_m + 0.5 * s.height_m;
    carried_.back().sphere_radius = std::hypot(br, 0.5 * s.height_m) + 1e-6;
  }
  candidates_.assign(carried_.size(), 0);

  RTCGeometry user = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_USER);
  rtcSetGeometryUserPrimitiveCount(user, static_cast<unsigned>(solids_.size()));
  rtcSetGeometryUserData(user, this);
  rtcSetGeometryBoundsFunction(user, SolidBounds, nullptr);
  rtcSetGeometryIntersectFunction(user, SolidIntersect);
  rtcCommitGeometry(user);
  rtcAttachGeometry(scene_, user);
  rtcReleaseGeometry(user);
  rtcCommitScene(scene_);
  if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) {
    rtcReleaseScene(scene_);
    rtcReleaseDevice(device_);
    throw std::runtime_error("Embree: building the scene failed");
  }
}

RayScene::~RayScene() {
  rtcReleaseScene(scene_);
  rtcReleaseDevice(device_);
}

void RayScene::SetBounds(StaticSolid& s, std::array<double, 3> lo, std::array<double, 3> hi) {
  // Padded by far more than Embree's single-precision slab tests can be off
  // (a few ulp of the coordinates: ~1e-7 relative), so that its traversal
  // never drops a solid whose exact hit could be the nearest.
  for (std::size_t k = 0; k < 3; ++k) {
    const double pad_lo = 1e-4 + 1e-5 * std::abs(lo[k]), pad_hi = 1e-4 + 1e-5 * std::abs(hi[k]);
    s.lower[k] = std::nextafter(static_cast<float>(lo[k] - pad_lo), -HUGE_VALF);
    s.upper[k] = std::nextafter(static_cast<float>(hi[k] + pad_hi), HUGE_VALF);
  }
}

void RayScene::AddBox(const std::array<double, 3>& center, const std::array<double, 3>& half,
                      const std::array<std::array<double, 3>, 3>& axes, int object) {
  StaticSolid box{};
  box.kind = StaticSolid::Kind::kBox;
  box.object = object;
  box.center = center;
  box.half = half;
  box.axes = axes;
  // The box's extent along each world axis: sum over its axes of |a_k[j]| h_k.
  std::array<double, 3> lo{}, hi{};
  for (std::size_t j = 0; j < 3; ++j) {
    double r = 0.0;
    for (std::size_t k = 0; k < 3; ++k) r += std::abs(axes[k][j]) * half[k];
    lo[j] = center[j] - r;
    hi[j] = center[j] + r;
  }
  SetBounds(box, lo, hi);
  solids_.push_back(box);
}

void RayScene::IntersectLaneOf(unsigned prim, unsigned lane_index, float& tfar) {
  Lane& lane = lanes_[lane_index];
  const StaticSolid& sd = solids_[prim];
  const Ray& r = *lane.ray;
  const double* o = r.origin.data();
  const double* d = r.direction.data();
  const double t_max = lane.t_max;
  double n[3] = {0.0, 0.0, 0.0};
  double t = kInf;
  switch (sd.kind) {
    case StaticSolid::Kind::kFloor:
      if (d[2] != 0.0) {
        const double tf = -o[2] / d[2];
        const double x = o[0] + tf * d[0], y = o[1] + tf * d[1];
        if (tf > kTMin && tf < t_max && x >= sd.floor_min_x && x <= sd.floor_max_x &&
            y >= sd.floor_min_y && y <= sd.floor_max_y) {
          t = tf;
          n[2] = 1.0;
        }
      }
      break;
    case StaticSolid::Kind::kBox:
      t = IntersectOrientedBox(sd.center, sd.half, sd.axes, o, d, t_max, n);
      break;
    case StaticSolid::Kind::kCylinder:
      t = IntersectCylinder(sd.cylinder, o, d, t_max, n);
      break;
  }
  if (std::isinf(t)) return;
  // The nearest wins; an exact tie goes to the lower object index, so the
  // order in which Embree offers candidates never matters.
  if (t < lane.best.range || (t == lane.best.range && sd.object < lane.best.object)) {
    lane.best = {t, std::abs(n[0] * d[0] + n[1] * d[1] + n[2] * d[2]), sd.object};
    // Embree may skip what lies beyond: never below the exact hit (t > 0:
    // one float step up from the nearest float is above it).
    const float rounded_up =
        std::bit_cast<float>(std::bit_cast<std::uint32_t>(static_cast<float>(t)) + 1u);
    if (rounded_up < tfar) tfar = rounded_up;
  }
}

RayScene::Bundle RayScene::Bundle::Of(std::span<const Ray> rays) {
  // In one pass over the rays: apex a the middle ray's origin, axis the
  // bisector of the first and last rays' directions (any apex and axis
  // bound the rays: the half angle is the widest ray from the axis and rho
  // the farthest origin from a), times in [s0, s1].
  Bundle b;
  const Ray& mid = rays[rays.size() / 2];
  for (int i = 0; i < 3; ++i) {
    b.a[i] = mid.origin[static_cast<std::size_t>(i)];
    b.ax[i] = rays.front().direction[static_cast<std::size_t>(i)] +
              rays.back().direction[static_cast<std::size_t>(i)];
  }
  const double axn = std::sqrt(b.ax[0] * b.ax[0] + b.ax[1] * b.ax[1] + b.ax[2] * b.ax[2]);
  const bool cone = axn > 1e-6;
  if (cone) {
    // (Not exactly unit after the reciprocal's rounding: the cone's 1e-6
    // widening below covers that.)
    const double inv = 1.0 / axn;
    for (double& x : b.ax) x *= inv;
  }
  double s0 = rays[0].dt_s, s1 = rays[0].dt_s;
  double cos_th = 1.0, rho = 0.0;
  for (const Ray& r : rays) {
    const double z_end = r.origin[2] + r.max_range * r.direction[2];
    b.z_lo = std::min(b.z_lo, std::min(r.origin[2], z_end));
    b.z_hi = std::max(b.z_hi, std::max(r.origin[2], z_end));
    s0 = std::min(s0, r.dt_s);
    s1 = std::max(s1, r.dt_s);
    b.t_far = std::max(b.t_far, r.max_range);
    const double dx = r.origin[0] - b.a[0], dy = r.origin[1] - b.a[1], dz = r.origin[2] - b.a[2];
    rho = std::max(rho, dx * dx + dy * dy + dz * dz);
    cos_th = std::min(cos_th, b.ax[0] * r.direction[0] + b.ax[1] * r.direction[1] +
                                  b.ax[2] * r.direction[2]);
  }
  b.rho = std::sqrt(rho);
  // Rounding of the unit directions: only ever widens the cone.
  b.cos_th = cone ? cos_th - 1e-6 : -1.0;
  b.sin_th = std::sqrt(std::max(0.0, 1.0 - b.cos_th * b.cos_th));
  b.s_mid = 0.5 * (s0 + s1);
  b.s_half = 0.5 * (s1 - s0);
  b.z_pad = 1e-9 * (1.0 + std::abs(b.z_lo) + std::abs(b.z_hi));
  return b;
}

bool RayScene::Bundle::MayMeet(double cx, double cy, double cz, double radius, double z_bottom,
                               double z_top) const {
  // Above or below all the rays (a level scan under a car body).
  if (z_bottom > z_hi + z_pad || z_top < z_lo - z_pad) return false;
  const double r = (radius + rho) * (1.0 + 1e-9) + 1e-9;
  if (cos_th < 0.0) return true;
  const double vx = cx - a[0], vy = cy - a[1], vz = cz - a[2];
  const double l2 = vx * vx + vy * vy + vz * vz;
  if (l2 <= r * r) return true;
  // Beyond the rays' reach, or off the cone by more than the sphere's
  // angular radius b (sin b = r / L): cos(angle to the axis) < cos(th + b)
  // = (cos th sqrt(L^2 - r^2) - sin th r) / L.
  const double t = t_far + r;
  if (l2 > t * t) return false;
  // Without the square root: along + sin th r < cos th sqrt(L^2 - r^2)
  // (both sides' signs known: cos th >= 0).
  const double lhs = (vx * ax[0] + vy * ax[1] + vz * ax[2]) + sin_th * r;
  return !(lhs < 0.0 || lhs * lhs < cos_th * cos_th * (l2 - r * r));
}

int RayScene::CullCarried(const Bundle& bundle, std::span<const double> belt_travel,
                          std::span<const double> belt_speed) {
  int n = 0;
  for (std::size_t i = 0; i < carried_.size(); ++i) {
    const Carried& c = carried_[i];
    const auto b = static_cast<std::size_t>(c.belt);
    const double travel = belt_travel[b] + belt_speed[b] * bundle.s_mid;
    const double sweep = std::abs(belt_speed[b]) * bundle.s_half;
    // Lifted off over all the bundle's times.
    if (travel + sweep < c.travel_min || travel - sweep > c.travel_max) continue;
    if (!bundle.MayMeet(c.solid.x_m + travel * c.ux, c.solid.y_m + travel * c.uy, c.center_z,
                        c.sphere_radius + sweep, c.solid.bottom_m,
                        c.solid.bottom_m + c.solid.height_m)) {
      continue;
    }
    candidates_[static_cast<std::size_t>(n++)] = static_cast<int>(i);
  }
  return n;
}

void RayScene::PrepareMovingBoxes(std::span<const double> boxes, int own_box) {
  using models::MovingBox;
  const std::size_t count = boxes.size() / MovingBox::kValues;
  if (box_candidates_.size() < count) {  // once per size
    box_candidates_.resize(count);
    prepared_.resize(count);
  }
  for (std::size_t i = 0; i < count; ++i) {
    const double* m = boxes.data() + i * MovingBox::kValues;
    const double length = m[MovingBox::kLength], width = m[MovingBox::kWidth];
    const double z0 = m[MovingBox::kZBottom], z1 = m[MovingBox::kZTop];
    PreparedBox& p = prepared_[i];
    // Absent (unsized), or the scanner's own robot.
    p.present = length > 0.0 && width > 0.0 && z1 > z0 && static_cast<int>(i) != own_box;
    if (!p.present) continue;
    p.radius = 0.5 * std::sqrt(length * length + width * width + (z1 - z0) * (z1 - z0));
    p.padded = p.radius * (1.0 + 1e-9) + 1e-9;
    // Only a sweep's bound: the padding in MayMeet covers its rounding.
    p.speed =
        std::sqrt(m[MovingBox::kVx] * m[MovingBox::kVx] + m[MovingBox::kVy] * m[MovingBox::kVy]);
    p.cos_yaw = std::cos(m[MovingBox::kYaw]);
    p.sin_yaw = std::sin(m[MovingBox::kYaw]);
  }
}

int RayScene::CullMovingBoxes(const Bundle& bundle, std::span<const double> boxes) {
  using models::MovingBox;
  const std::size_t count = boxes.size() / MovingBox::kValues;
  int n = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const PreparedBox& p = prepared_[i];
    if (!p.present) continue;
    const double* m = boxes.data() + i * MovingBox::kValues;
    const double z0 = m[MovingBox::kZBottom], z1 = m[MovingBox::kZTop];
    if (!bundle.MayMeet(m[MovingBox::kX] + m[MovingBox::kVx] * bundle.s_mid,
                        m[MovingBox::kY] + m[MovingBox::kVy] * bundle.s_mid, 0.5 * (z0 + z1),
                        p.radius + p.speed * bundle.s_half, z0, z1)) {
      continue;
    }
    box_candidates_[static_cast<std::size_t>(n++)] = static_cast<int>(i);
  }
  return n;
}

void RayScene::CastCarried(const Ray& ray, std::span<const int> candidates,
                           std::span<const double> belt_travel, std::span<const double> belt_speed,
                           RayHit& best) const {
  for (const int ci : candidates) {
    const Carried& c = carried_[static_cast<std::size_t>(ci)];
    const auto b = static_cast<std::size_t>(c.belt);
    const double travel = belt_travel[b] + belt_speed[b] * ray.dt_s;
    if (travel < c.travel_min || travel > c.travel_max) continue;  // lifted off
    const double x = c.solid.x_m + travel * c.ux, y = c.solid.y_m + travel * c.uy;
    const double t_max = std::isinf(best.range) ? ray.max_range : best.range;
    // Cull with the footprint's bounding circle: the ray's horizontal
    // line passes farther from its centre, or the object is behind.
    {
      const double px = x - ray.origin[0], py = y - ray.origin[1];
      const double cross = px * ray.direction[1] - py * ray.direction[0];
      const double h2 = ray.direction[0] * ray.direction[0] + ray.direction[1] * ray.direction[1];
      if (cross * cross > c.bound_radius2 * h2) continue;
      if (c.solid.kind == models::Solid::Kind::kBox) {
        // Tighter for a box: the horizontal line misses its footprint
        // rectangle (the separating axis of the line's normal; cross is
        // the same in the box's frame, where the direction's components
        // are ld_x, ld_y). Padded: only a clear miss is dropped.
        const double ldx = c.cos_yaw * ray.direction[0] + c.sin_yaw * ray.direction[1];
        const double ldy = -c.sin_yaw * ray.direction[0] + c.cos_yaw * ray.direction[1];
        const double reach =
            0.5 * (c.solid.length_m * std::abs(ldy) + c.solid.width_m * std::abs(ldx));
        if (std::abs(cross) > reach * (1.0 + 1e-9) + 1e-9) continue;
      }
      if (px * ray.direction[0] + py * ray.direction[1] < -std::sqrt(c.bound_radius2 * h2)) continue;
    }
    double n[3] = {0.0, 0.0, 0.0};
    double t;
    if (c.solid.kind == models::Solid::Kind::kCylinder) {
      const Cylinder cyl{x, y, c.solid.radius_m, c.solid.bottom_m,
                         c.solid.bottom_m + c.solid.height_m, c.object};
      t = IntersectCylinder(cyl, ray.origin.data(), ray.direction.data(), t_max, n);
    } else {
      t = IntersectYawedBox(x, y, c.solid.bottom_m + 0.5 * c.solid.height_m, 0.5 * c.solid.length_m,
                            0.5 * c.solid.width_m, 0.5 * c.solid.height_m, c.cos_yaw, c.sin_yaw,
                            ray.origin.data(), ray.direction.data(), t_max, n);
    }
    if (t < t_max) {
      best.range = t;
      best.object = c.object;
      best.cos_incidence = std::abs(n[0] * ray.direction[0] + n[1] * ray.direction[1] +
                                    n[2] * ray.direction[2]);
    }
  }
}

void RayScene::CastMoving(const Ray& ray, std::span<const double> moving, RayHit& best) const {
  const std::size_t count = moving.size() / kMovingValues;
  for (std::size_t i = 0; i < count; ++i) {
    const double* m = moving.data() + i * kMovingValues;
    const double t_max = std::isinf(best.range) ? ray.max_range : best.range;
    const Cylinder cyl{m[0] + m[2] * ray.dt_s, m[1] + m[3] * ray.dt_s, m[4], m[5], m[6],
                       ObjectOfMoving(static_cast<int>(i))};
    double n[3] = {0.0, 0.0, 0.0};
    const double t = IntersectCylinder(cyl, ray.origin.data(), ray.direction.data(), t_max, n);
    if (t < t_max) {
      best.range = t;
      best.object = cyl.object;
      best.cos_incidence = std::abs(n[0] * ray.direction[0] + n[1] * ray.direction[1] +
                                    n[2] * ray.direction[2]);
    }
  }
}

void RayScene::CastMovingBoxes(const Ray& ray, std::span<const double> boxes,
                               std::span<const int> candidates, int first_object,
                               RayHit& best) const {
  using models::MovingBox;
  for (const int i : candidates) {
    const double* m = boxes.data() + static_cast<std::size_t>(i) * MovingBox::kValues;
    const double z0 = m[MovingBox::kZBottom], z1 = m[MovingBox::kZTop];
    const double t_max = std::isinf(best.range) ? ray.max_range : best.range;
    const double cx = m[MovingBox::kX] + m[MovingBox::kVx] * ray.dt_s;
    const double cy = m[MovingBox::kY] + m[MovingBox::kVy] * ray.dt_s;
    const double cz = 0.5 * (z0 + z1);
    const PreparedBox& p = prepared_[static_cast<std::size_t>(i)];
    const double* o = ray.origin.data();
    const double* d = ray.direction.data();
    // The box's bounding sphere first (a group's cone is wider than the
    // box: most of its rays pass by): off the ray's line, behind its origin
    // or beyond t_max, the box cannot be met.
    const double vx = cx - o[0], vy = cy - o[1], vz = cz - o[2];
    {
      const double r = p.padded;
      const double along = vx * d[0] + vy * d[1] + vz * d[2];
      const double off2 = vx * vx + vy * vy + vz * vz - along * along;
      if (off2 > r * r || along < -r || along - r > t_max) continue;
    }
    // The yaw at the ray's time: the box's cos and sin (once per call,
    // prepared_) turned by a = yaw_rate dt through its series (|a| < 0.1
    // rad within a scan: the terms left out are below 1e-8 rad).
    const double a = m[MovingBox::kYawRate] * ray.dt_s, a2 = a * a;
    const double ca = 1.0 - a2 / 2.0 + a2 * a2 / 24.0, sa = a * (1.0 - a2 / 6.0 + a2 * a2 / 120.0);
    const double cos_yaw = p.cos_yaw * ca - p.sin_yaw * sa,
                 sin_yaw = p.sin_yaw * ca + p.cos_yaw * sa;
    const double hx = 0.5 * m[MovingBox::kLength], hy = 0.5 * m[MovingBox::kWidth];
    // Then its footprint: the ray's horizontal line passes the rectangle by
    // (the separating axis of the line's normal, as in CastCarried; padded:
    // only a clear miss is dropped). Without it 45 % of the exact tests
    // missed in a fleet's rows (BM_Fleet/10).
    {
      const double cross = vx * d[1] - vy * d[0];
      const double ldx = cos_yaw * d[0] + sin_yaw * d[1];
      const double ldy = -sin_yaw * d[0] + cos_yaw * d[1];
      const double reach = hx * std::abs(ldy) + hy * std::abs(ldx);
      if (std::abs(cross) > reach * (1.0 + 1e-9) + 1e-9) continue;
    }
    double n[3] = {0.0, 0.0, 0.0};
    const double t =
        IntersectYawedBox(cx, cy, cz, hx, hy, 0.5 * (z1 - z0), cos_yaw, sin_yaw, o, d, t_max, n);
    if (t < t_max) {
      best.range = t;
      best.object = ObjectOfMoving(first_object + i);
      best.cos_incidence =
          std::abs(n[0] * ray.direction[0] + n[1] * ray.direction[1] + n[2] * ray.direction[2]);
    }
  }
}

void RayScene::Cast(std::span<const Ray> rays, std::span<RayHit> hits,
                    std::span<const double> belt_travel, std::span<const double> belt_speed,
                    std::span<const double> moving, std::span<const double> moving_boxes,
                    int own_box) {
  const int cylinders = static_cast<int>(moving.size() / kMovingValues);
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  // Packets of 16 while 16 rays are left, then of 8 (a 1 ms step's 14 beams
  // are cast faster as 8 and 6 than as one packet of 16, measured). Not
  // Embree's coherent mode: its frustum traversal dropped level beams (a
  // vertical component of rounding size) against the factory's walls, on
  // AVX2 and AVX-512 kernels but not SSE: walls vanished on some machines
  // (tests/units/sensors/ray_scene_test.cc catches it).
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
  int candidates = 0, box_count = 0;
  if (!moving_boxes.empty()) PrepareMovingBoxes(moving_boxes, own_box);
  for (std::size_t first = 0; first < rays.size();) {
    const std::size_t count =
        rays.size() - first >= 16 ? 16 : std::min<std::size_t>(8, rays.size() - first);
    const auto packet_rays = rays.subspan(first, count);
    for (std::size_t k = 0; k < count; ++k) {
      // Hits up to max_range count (nextafter: t == max_range is in).
      lanes_[k] = {&packet_rays[k], std::nextafter(packet_rays[k].max_range, kInf),
                   {kInf, 0.0, -1}};
    }
    if (count == 16) {
      IntersectPacket<RTCRayHit16, 16>(packet_rays, scene_, &context);
    } else {
      IntersectPacket<RTCRayHit8, 8>(packet_rays, scene_, &context);
    }
    // The carried objects are culled once per group of kCullGroup rays (a
    // 1 ms step's beams are one group): a group's cone is a few degrees
    // wide, and the cull's fixed cost is paid once instead of per packet.
    if (first % kCullGroup == 0 && (!carried_.empty() || !moving_boxes.empty())) {
      const Bundle bundle = Bundle::Of(
          rays.subspan(first, std::min<std::size_t>(kCullGroup, rays.size() - first)));
      candidates = carried_.empty() ? 0 : CullCarried(bundle, belt_travel, belt_speed);
      box_count = moving_boxes.empty() ? 0 : CullMovingBoxes(bundle, moving_boxes);
    }
    for (std::size_t k = 0; k < count; ++k) {
      RayHit& h = hits[first + k];
      h = lanes_[k].best;
      if (candidates > 0) {
        CastCarried(packet_rays[k],
                    std::span<const int>(candidates_.data(), static_cast<std::size_t>(candidates)),
                    belt_travel, belt_speed, h);
      }
      if (!moving.empty()) CastMoving(packet_rays[k], moving, h);
      if (box_count > 0) {
        CastMovingBoxes(packet_rays[k], moving_boxes,
                        std::span<const int>(box_candidates_.data(),
                                             static_cast<std::size_t>(box_count)),
                        cylinders, h);
      }
    }
    first += count;
  }
}

}  // namespace linesim::sensors
