#include "units/sensors/ray_scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace linesim::sensors {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kTMin = 1e-9;
// Rays per Embree packet (rtcIntersect16).
constexpr std::size_t kPacket = 16;

// Embree user-geometry callbacks for the cylinders.
void CylinderBounds(const RTCBoundsFunctionArguments* args) {
  const auto* cyl = static_cast<const RayScene::Cylinder*>(args->geometryUserPtr);
  const RayScene::Cylinder& c = cyl[args->primID];
  // Widened by a relative float epsilon so that rounding never cuts a hit.
  const double pad = 1e-5 * (1.0 + std::abs(c.x) + std::abs(c.y) + c.radius + std::abs(c.z1));
  RTCBounds* b = args->bounds_o;
  b->lower_x = static_cast<float>(c.x - c.radius - pad);
  b->lower_y = static_cast<float>(c.y - c.radius - pad);
  b->lower_z = static_cast<float>(c.z0 - pad);
  b->upper_x = static_cast<float>(c.x + c.radius + pad);
  b->upper_y = static_cast<float>(c.y + c.radius + pad);
  b->upper_z = static_cast<float>(c.z1 + pad);
}

void CylinderIntersect(const RTCIntersectFunctionNArguments* args) {
  const auto* cyl = static_cast<const RayScene::Cylinder*>(args->geometryUserPtr);
  const RayScene::Cylinder& c = cyl[args->primID];
  RTCRayN* ray = RTCRayHitN_RayN(args->rayhit, args->N);
  RTCHitN* hit = RTCRayHitN_HitN(args->rayhit, args->N);
  for (unsigned i = 0; i < args->N; ++i) {
    if (!args->valid[i]) continue;
    const double o[3] = {RTCRayN_org_x(ray, args->N, i), RTCRayN_org_y(ray, args->N, i),
                         RTCRayN_org_z(ray, args->N, i)};
    const double d[3] = {RTCRayN_dir_x(ray, args->N, i), RTCRayN_dir_y(ray, args->N, i),
                         RTCRayN_dir_z(ray, args->N, i)};
    const double tfar = RTCRayN_tfar(ray, args->N, i);
    double n[3] = {0.0, 0.0, 0.0};
    const double t = IntersectCylinder(c, o, d, tfar, n);
    if (!(t < tfar) || t < RTCRayN_tnear(ray, args->N, i)) continue;
    RTCRayN_tfar(ray, args->N, i) = static_cast<float>(t);
    RTCHitN_Ng_x(hit, args->N, i) = static_cast<float>(n[0]);
    RTCHitN_Ng_y(hit, args->N, i) = static_cast<float>(n[1]);
    RTCHitN_Ng_z(hit, args->N, i) = static_cast<float>(n[2]);
    RTCHitN_u(hit, args->N, i) = 0.0f;
    RTCHitN_v(hit, args->N, i) = 0.0f;
    RTCHitN_primID(hit, args->N, i) = args->primID;
    RTCHitN_geomID(hit, args->N, i) = args->geomID;
    RTCHitN_instID(hit, args->N, i, 0) = args->context->instID[0];
  }
}

// What Cast needs of a packet's hits.
struct PacketHits {
  unsigned geom[kPacket], prim[kPacket];
  float tfar[kPacket];
};

// Intersects up to N rays as one Embree packet of width N (8 or 16).
template <class Packet, std::size_t N>
void IntersectPacket(std::span<const Ray> rays, RTCScene scene, RTCIntersectContext* context,
                     PacketHits& out) {
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
    // Beyond max_range by a margin: the exact distance is decided below.
    packet.ray.tfar[k] = static_cast<float>(r.max_range * (1.0 + 1e-5) + 1e-4);
    packet.ray.time[k] = 0.0f;
    packet.ray.mask[k] = ~0u;
    packet.ray.id[k] = 0;
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
  for (std::size_t k = 0; k < count; ++k) {
    out.geom[k] = packet.hit.geomID[k];
    out.prim[k] = packet.hit.primID[k];
    out.tfar[k] = packet.ray.tfar[k];
  }
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

double IntersectYawedBox(double cx, double cy, double cz, double hx, double hy, double hz,
                         double cos_yaw, double sin_yaw, const double* o, const double* d,
                         double t_max, double* normal) {
  // Into the box frame (yaw only).
  const double px = o[0] - cx, py = o[1] - cy, pz = o[2] - cz;
  const double lo[3] = {cos_yaw * px + sin_yaw * py, -sin_yaw * px + cos_yaw * py, pz};
  const double ld[3] = {cos_yaw * d[0] + sin_yaw * d[1], -sin_yaw * d[0] + cos_yaw * d[1], d[2]};
  const double h[3] = {hx, hy, hz};
  double t_in = -kInf, t_out = kInf;
  int axis = -1;
  double sign = 0.0;
  for (int k = 0; k < 3; ++k) {
    if (ld[k] == 0.0) {
      if (lo[k] < -h[k] || lo[k] > h[k]) return kInf;
      continue;
    }
    const double inv = 1.0 / ld[k];
    double t0 = (-h[k] - lo[k]) * inv, t1 = (h[k] - lo[k]) * inv;
    double s = -1.0;  // the face entered: -h when moving +
    if (t0 > t1) {
      std::swap(t0, t1);
      s = 1.0;
    }
    if (t0 > t_in) {
      t_in = t0;
      axis = k;
      sign = s;
    }
    t_out = std::min(t_out, t1);
  }
  // A ray starting inside sees nothing of it (a sensor is never inside).
  if (axis < 0 || t_in > t_out || t_in <= kTMin || t_in >= t_max) return kInf;
  double ln[3] = {0.0, 0.0, 0.0};
  ln[axis] = sign;
  normal[0] = cos_yaw * ln[0] - sin_yaw * ln[1];
  normal[1] = sin_yaw * ln[0] + cos_yaw * ln[1];
  normal[2] = ln[2];
  return t_in;
}

RayScene::RayScene(const models::Scene& scene)
    : obstacle_count_(static_cast<int>(scene.obstacles.size())),
      terrain_count_(static_cast<int>(scene.terrain.size())) {
  // Single-threaded: without "threads=1" Embree starts a worker per core.
  device_ = rtcNewDevice("threads=1");
  if (!device_) {
    throw std::runtime_error("Embree: cannot create a device (error " +
                             std::to_string(static_cast<int>(rtcGetDeviceError(nullptr))) + ")");
  }
  scene_ = rtcNewScene(device_);
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);

  std::vector<float> vertices;
  std::vector<unsigned> indices;
  // The floor: its rectangle at z = 0, two triangles facing up.
  {
    const models::Floor& f = scene.floor;
    const unsigned base = static_cast<unsigned>(vertices.size() / 3);
    const double xs[4] = {f.min_x_m, f.max_x_m, f.max_x_m, f.min_x_m};
    const double ys[4] = {f.min_y_m, f.min_y_m, f.max_y_m, f.max_y_m};
    for (int k = 0; k < 4; ++k) {
      vertices.insert(vertices.end(), {static_cast<float>(xs[k]), static_cast<float>(ys[k]), 0.f});
    }
    indices.insert(indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    faces_.push_back({0.0, 0.0, 1.0, 0.0, kFloor});
    faces_.push_back({0.0, 0.0, 1.0, 0.0, kFloor});
  }
  for (int i = 0; i < obstacle_count_; ++i) {
    const models::Solid& s = scene.obstacles[static_cast<std::size_t>(i)].solid;
    if (s.kind == models::Solid::Kind::kCylinder) {
      cylinders_.push_back({s.x_m, s.y_m, s.radius_m, s.bottom_m, s.bottom_m + s.height_m,
                            ObjectOfObstacle(i)});
      continue;
    }
    const double c = std::cos(s.yaw_rad), sn = std::sin(s.yaw_rad);
    AddBox(vertices, indices, {s.x_m, s.y_m, s.bottom_m + 0.5 * s.height_m},
           {0.5 * s.length_m, 0.5 * s.width_m, 0.5 * s.height_m},
           {{{c, sn, 0.0}, {-sn, c, 0.0}, {0.0, 0.0, 1.0}}}, ObjectOfObstacle(i));
  }
  for (int i = 0; i < terrain_count_; ++i) {
    const models::TerrainPiece& t = scene.terrain[static_cast<std::size_t>(i)];
    AddBox(vertices, indices, {t.center_x_m, t.center_y_m, t.center_z_m},
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

  RTCGeometry mesh = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(
      mesh, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertices.size() / 3));
  std::copy(vertices.begin(), vertices.end(), vb);
  auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
      mesh, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), indices.size() / 3));
  std::copy(indices.begin(), indices.end(), ib);
  rtcCommitGeometry(mesh);
  mesh_geom_ = rtcAttachGeometry(scene_, mesh);
  rtcReleaseGeometry(mesh);

  if (!cylinders_.empty()) {
    RTCGeometry user = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_USER);
    rtcSetGeometryUserPrimitiveCount(user, static_cast<unsigned>(cylinders_.size()));
    rtcSetGeometryUserData(user, cylinders_.data());
    rtcSetGeometryBoundsFunction(user, CylinderBounds, nullptr);
    rtcSetGeometryIntersectFunction(user, CylinderIntersect);
    rtcCommitGeometry(user);
    cylinder_geom_ = rtcAttachGeometry(scene_, user);
    rtcReleaseGeometry(user);
  }
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

void RayScene::AddBox(std::vector<float>& vertices, std::vector<unsigned>& indices,
                      const std::array<double, 3>& center, const std::array<double, 3>& half,
                      const std::array<std::array<double, 3>, 3>& axes, int object) {
  const unsigned base = static_cast<unsigned>(vertices.size() / 3);
  for (int k = 0; k < 8; ++k) {
    const double s[3] = {(k & 1) ? 1.0 : -1.0, (k & 2) ? 1.0 : -1.0, (k & 4) ? 1.0 : -1.0};
    for (int j = 0; j < 3; ++j) {
      double p = center[static_cast<std::size_t>(j)];
      for (int a = 0; a < 3; ++a) {
        p += s[a] * half[static_cast<std::size_t>(a)] *
             axes[static_cast<std::size_t>(a)][static_cast<std::size_t>(j)];
      }
      vertices.push_back(static_cast<float>(p));
    }
  }
  // Per axis a, the faces at -half and +half: corners with bit a clear / set.
  for (int a = 0; a < 3; ++a) {
    const int b1 = 1 << ((a + 1) % 3), b2 = 1 << ((a + 2) % 3), ba = 1 << a;
    for (int side = 0; side < 2; ++side) {
      const unsigned o = side ? static_cast<unsigned>(ba) : 0u;
      const unsigned q[4] = {base + o, base + o + static_cast<unsigned>(b1),
                             base + o + static_cast<unsigned>(b1 | b2),
                             base + o + static_cast<unsigned>(b2)};
      indices.insert(indices.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
      const double sg = side ? 1.0 : -1.0;
      const auto& n = axes[static_cast<std::size_t>(a)];
      Face f{sg * n[0], sg * n[1], sg * n[2], 0.0, object};
      f.c = f.nx * center[0] + f.ny * center[1] + f.nz * center[2] +
            half[static_cast<std::size_t>(a)];
      faces_.push_back(f);
      faces_.push_back(f);
    }
  }
}

int RayScene::CullCarried(std::span<const Ray> rays, std::span<const double> belt_travel,
                          std::span<const double> belt_speed) {
  // The bundle, in one pass over the rays: apex a the middle ray's origin,
  // axis the bisector of the first and last rays' directions (any apex and
  // axis bound the rays: the half angle is the widest ray from the axis and
  // rho the farthest origin from a), times in [s0, s1].
  const Ray& mid = rays[rays.size() / 2];
  const double a[3] = {mid.origin[0], mid.origin[1], mid.origin[2]};
  double ax[3] = {rays.front().direction[0] + rays.back().direction[0],
                  rays.front().direction[1] + rays.back().direction[1],
                  rays.front().direction[2] + rays.back().direction[2]};
  const double axn = std::sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
  const bool cone = axn > 1e-6;
  if (cone) {
    // (Not exactly unit after the reciprocal's rounding: the cone's 1e-6
    // widening below covers that.)
    const double inv = 1.0 / axn;
    for (double& x : ax) x *= inv;
  }
  double s0 = rays[0].dt_s, s1 = rays[0].dt_s, t_far = 0.0;
  // The heights the rays pass through within their reach.
  double z_lo = kInf, z_hi = -kInf;
  double cos_th = 1.0, rho = 0.0;
  for (const Ray& r : rays) {
    const double z_end = r.origin[2] + r.max_range * r.direction[2];
    z_lo = std::min(z_lo, std::min(r.origin[2], z_end));
    z_hi = std::max(z_hi, std::max(r.origin[2], z_end));
    s0 = std::min(s0, r.dt_s);
    s1 = std::max(s1, r.dt_s);
    t_far = std::max(t_far, r.max_range);
    const double dx = r.origin[0] - a[0], dy = r.origin[1] - a[1], dz = r.origin[2] - a[2];
    rho = std::max(rho, dx * dx + dy * dy + dz * dz);
    cos_th = std::min(cos_th, ax[0] * r.direction[0] + ax[1] * r.direction[1] +
                                  ax[2] * r.direction[2]);
  }
  rho = std::sqrt(rho);
  // Rounding of the unit directions: only ever widens the cone.
  cos_th = cone ? cos_th - 1e-6 : -1.0;
  const double sin_th = std::sqrt(std::max(0.0, 1.0 - cos_th * cos_th));
  const double s_mid = 0.5 * (s0 + s1), s_half = 0.5 * (s1 - s0);
  const double z_pad = 1e-9 * (1.0 + std::abs(z_lo) + std::abs(z_hi));
  int n = 0;
  for (std::size_t i = 0; i < carried_.size(); ++i) {
    const Carried& c = carried_[i];
    // Above or below all the rays (a level scan under a car body).
    if (c.solid.bottom_m > z_hi + z_pad || c.solid.bottom_m + c.solid.height_m < z_lo - z_pad) {
      continue;
    }
    const auto b = static_cast<std::size_t>(c.belt);
    const double travel = belt_travel[b] + belt_speed[b] * s_mid;
    const double sweep = std::abs(belt_speed[b]) * s_half;
    // Lifted off over all the bundle's times.
    if (travel + sweep < c.travel_min || travel - sweep > c.travel_max) continue;
    const double r = (c.sphere_radius + sweep + rho) * (1.0 + 1e-9) + 1e-9;
    if (cos_th >= 0.0) {
      const double vx = c.solid.x_m + travel * c.ux - a[0], vy = c.solid.y_m + travel * c.uy - a[1],
                   vz = c.center_z - a[2];
      const double l2 = vx * vx + vy * vy + vz * vz;
      if (l2 > r * r) {
        // Beyond the rays' reach, or off the cone by more than the
        // sphere's angular radius b (sin b = r / L): cos(angle to the
        // axis) < cos(th + b) = (cos th sqrt(L^2 - r^2) - sin th r) / L.
        const double t = t_far + r;
        if (l2 > t * t) continue;
        // Without the square root: along + sin th r < cos th sqrt(L^2 - r^2)
        // (both sides' signs known: cos th >= 0).
        const double lhs = (vx * ax[0] + vy * ax[1] + vz * ax[2]) + sin_th * r;
        if (lhs < 0.0 || lhs * lhs < cos_th * cos_th * (l2 - r * r)) continue;
      }
    }
    candidates_[static_cast<std::size_t>(n++)] = static_cast<int>(i);
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

void RayScene::Cast(std::span<const Ray> rays, std::span<RayHit> hits,
                    std::span<const double> belt_travel, std::span<const double> belt_speed) {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  // The beams of a scan are neighbours: coherent packets of 16 while 16
  // rays are left, then of 8 (a 1 ms step's 14 beams are cast faster as 8
  // and 6 than as one packet of 16, measured).
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  PacketHits ph;
  int candidates = 0;
  for (std::size_t first = 0; first < rays.size();) {
    const std::size_t count =
        rays.size() - first >= 16 ? 16 : std::min<std::size_t>(8, rays.size() - first);
    const auto packet_rays = rays.subspan(first, count);
    if (count == 16) {
      IntersectPacket<RTCRayHit16, 16>(packet_rays, scene_, &context, ph);
    } else {
      IntersectPacket<RTCRayHit8, 8>(packet_rays, scene_, &context, ph);
    }
    // The carried objects are culled once per group of kCullGroup rays (a
    // 1 ms step's beams are one group): a group's cone is a few degrees
    // wide, and the cull's fixed cost is paid once instead of per packet.
    if (first % kCullGroup == 0) {
      candidates =
          carried_.empty()
              ? 0
              : CullCarried(
                    rays.subspan(first, std::min<std::size_t>(kCullGroup, rays.size() - first)),
                    belt_travel, belt_speed);
    }
    for (std::size_t k = 0; k < count; ++k) {
      const Ray& r = rays[first + k];
      RayHit& h = hits[first + k];
      h = {std::numeric_limits<double>::infinity(), 0.0, -1};
      const unsigned geom = ph.geom[k];
      if (geom == mesh_geom_) {
        // The exact distance to the face's plane.
        const Face& f = faces_[ph.prim[k]];
        const double dn = f.nx * r.direction[0] + f.ny * r.direction[1] + f.nz * r.direction[2];
        const double on = f.nx * r.origin[0] + f.ny * r.origin[1] + f.nz * r.origin[2];
        const double t = dn != 0.0 ? (f.c - on) / dn : static_cast<double>(ph.tfar[k]);
        if (t > 0.0 && t <= r.max_range) h = {t, std::abs(dn), f.object};
      } else if (geom == cylinder_geom_ && geom != RTC_INVALID_GEOMETRY_ID) {
        const Cylinder& c = cylinders_[ph.prim[k]];
        double n[3];
        const double t = IntersectCylinder(c, r.origin.data(), r.direction.data(),
                                           r.max_range * 1.001 + 1e-3, n);
        if (t <= r.max_range) {
          h = {t, std::abs(n[0] * r.direction[0] + n[1] * r.direction[1] + n[2] * r.direction[2]),
               c.object};
        }
      }
      if (candidates > 0) {
        CastCarried(r,
                    std::span<const int>(candidates_.data(), static_cast<std::size_t>(candidates)),
                    belt_travel, belt_speed, h);
      }
    }
    first += count;
  }
}

}  // namespace linesim::sensors
