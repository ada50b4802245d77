#include "units/chassis/floor_world.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "models/moving_solids.h"

namespace linesim::chassis {

namespace {

// ODE calls abort() after its error and debug handlers return (for example
// on a non-finite quaternion), so the handlers throw instead.
[[noreturn]] void ThrowOdeError(int num, const char* msg, va_list ap) {
  char text[512];
  std::vsnprintf(text, sizeof(text), msg, ap);
  throw OdeError("ODE error " + std::to_string(num) + ": " + text);
}

bool InitOde() {
  dSetErrorHandler(&ThrowOdeError);
  dSetDebugHandler(&ThrowOdeError);
  return dInitODE2(0) != 0;
}

}  // namespace

void EnsureOdeForThisThread() {
  // dInitODE2 may be called once per process only; a function-local static
  // is initialised exactly once even under concurrent first calls.
  static const bool initialized = InitOde();
  // ODE ignores already allocated flags, but the flag saves the call.
  thread_local bool allocated = false;
  if (allocated) return;
  if (!initialized) throw std::runtime_error("ODE: dInitODE2 failed");
  if (dAllocateODEDataForThread(dAllocateMaskAll) == 0) {
    throw std::runtime_error("ODE: dAllocateODEDataForThread failed");
  }
  allocated = true;
}

FloorWorld::FloorWorld() {
  EnsureOdeForThisThread();
  world_ = dWorldCreate();
  threading_ = dThreadingAllocateSelfThreadedImplementation();
  dWorldSetStepThreadingImplementation(world_, dThreadingImplementationGetFunctions(threading_),
                                       threading_);
  dWorldSetGravity(world_, 0.0, 0.0, -kGravityMps2);
  group_ = dJointGroupCreate(0);
  // Not in a space: geoms are collided with the floor one by one.
  floor_ = dCreatePlane(nullptr, 0.0, 0.0, 1.0, 0.0);
}

FloorWorld::~FloorWorld() {
  EnsureOdeForThisThread();
  dJointGroupDestroy(group_);
  dGeomDestroy(floor_);
  for (dGeomID g : obstacles_) dGeomDestroy(g);
  for (const Terrain& t : terrain_) dGeomDestroy(t.geom);
  for (const Carried& c : carried_) dGeomDestroy(c.geom);
  for (dGeomID g : moving_box_geoms_) dGeomDestroy(g);
  for (dGeomID g : moving_cylinder_geoms_) dGeomDestroy(g);
  dWorldDestroy(world_);
  dThreadingFreeImplementation(threading_);
}

void FloorWorld::SetBelts(std::vector<BeltPatch> belts) {
  belts_ = std::move(belts);
  collided_ = false;
  belt_velocity_mps_.assign(belts_.size(), {0.0, 0.0});
  belt_travel_m_.assign(belts_.size(), 0.0);
  belt_axes_.clear();
  for (const BeltPatch& b : belts_) {
    const double c = std::cos(b.direction_rad);
    const double s = std::sin(b.direction_rad);
    belt_axes_.push_back({c, s, -s, c});
  }
}

void FloorWorld::SetBeltVelocity(int k, double vx_mps, double vy_mps) {
  belt_velocity_mps_.at(static_cast<std::size_t>(k)) = {vx_mps, vy_mps};
}

namespace {

// A geom (in no space) for a solid standing on the floor (bottom_m above it).
dGeomID SolidGeom(const models::Solid& s, double* z_m) {
  dGeomID g = s.kind == models::Solid::Kind::kBox
                  ? dCreateBox(nullptr, s.length_m, s.width_m, s.height_m)
                  : dCreateCylinder(nullptr, s.radius_m, s.height_m);  // axis along z
  *z_m = s.bottom_m + 0.5 * s.height_m;
  dGeomSetPosition(g, s.x_m, s.y_m, *z_m);
  dMatrix3 rot;
  dRFromAxisAndAngle(rot, 0.0, 0.0, 1.0, s.yaw_rad);
  dGeomSetRotation(g, rot);
  return g;
}

// Area of the convex polygon `poly` (n vertices, x y pairs, counter-
// clockwise or clockwise) inside the box |x| <= hx, |y| <= hy: clipped by
// the box's four half-planes in turn (Sutherland-Hodgman), then the
// shoelace formula. A quadrilateral clipped by four lines has at most 8
// vertices.
double AreaInBox(const std::array<double, 8>& quad, double hx, double hy) {
  std::array<double, 32> a{}, b{};
  int n = 4;
  std::copy(quad.begin(), quad.end(), a.begin());
  // Half-plane k keeps s * coord(axis) <= h.
  const int axis[4] = {0, 0, 1, 1};
  const double sign[4] = {1.0, -1.0, 1.0, -1.0};
  const double half[4] = {hx, hx, hy, hy};
  for (int k = 0; k < 4 && n > 0; ++k) {
    int m = 0;
    const auto inside = [&](const double* v) { return sign[k] * v[axis[k]] <= half[k]; };
    for (int j = 0; j < n; ++j) {
      const double* p = &a[static_cast<std::size_t>(2 * j)];
      const double* q = &a[static_cast<std::size_t>(2 * ((j + 1) % n))];
      const bool pin = inside(p), qin = inside(q);
      if (pin) {
        b[static_cast<std::size_t>(2 * m)] = p[0];
        b[static_cast<std::size_t>(2 * m + 1)] = p[1];
        ++m;
      }
      if (pin != qin) {
        const double t = (half[k] - sign[k] * p[axis[k]]) / (sign[k] * (q[axis[k]] - p[axis[k]]));
        b[static_cast<std::size_t>(2 * m)] = p[0] + t * (q[0] - p[0]);
        b[static_cast<std::size_t>(2 * m + 1)] = p[1] + t * (q[1] - p[1]);
        ++m;
      }
    }
    n = m;
    std::swap(a, b);
  }
  double twice = 0.0;
  for (int j = 0; j < n; ++j) {
    const auto p = static_cast<std::size_t>(2 * j), q = static_cast<std::size_t>(2 * ((j + 1) % n));
    twice += a[p] * a[q + 1] - a[q] * a[p + 1];
  }
  return 0.5 * std::abs(twice);
}

}  // namespace

void FloorWorld::Rows(std::size_t i, const dReal* nrm, double e0[3], double e1[3]) const {
  const Tread& t = treads_[i];
  const dBodyID body = dGeomGetBody(geoms_[i]);
  double len = 0.0;
  if (body && (t.axle[0] != 0.0 || t.axle[1] != 0.0 || t.axle[2] != 0.0)) {
    dVector3 axle;
    dBodyVectorToWorld(body, t.axle[0], t.axle[1], t.axle[2], axle);
    e0[0] = axle[1] * nrm[2] - axle[2] * nrm[1];
    e0[1] = axle[2] * nrm[0] - axle[0] * nrm[2];
    e0[2] = axle[0] * nrm[1] - axle[1] * nrm[0];
    len = std::sqrt(e0[0] * e0[0] + e0[1] * e0[1] + e0[2] * e0[2]);
  }
  if (len < 1e-6) {
    // No rolling direction: map x on the contact plane, or map y if x is
    // the normal.
    const double axis[3] = {std::abs(nrm[0]) < 0.9 ? 1.0 : 0.0, std::abs(nrm[0]) < 0.9 ? 0.0 : 1.0,
                            0.0};
    const double an = axis[0] * nrm[0] + axis[1] * nrm[1];
    for (int d = 0; d < 3; ++d) e0[d] = axis[d] - an * nrm[d];
    len = std::sqrt(e0[0] * e0[0] + e0[1] * e0[1] + e0[2] * e0[2]);
  }
  for (int d = 0; d < 3; ++d) e0[d] /= len;
  e1[0] = nrm[1] * e0[2] - nrm[2] * e0[1];
  e1[1] = nrm[2] * e0[0] - nrm[0] * e0[2];
  e1[2] = nrm[0] * e0[1] - nrm[1] * e0[0];
}

FloorWorld::Patch FloorWorld::PatchAt(std::size_t i, const dContactGeom& g, int surface) const {
  Patch patch;
  if (surface > belt_count()) return patch;  // a terrain piece: one surface
  const Tread& t = treads_[i];
  const bool point = !(t.patch_length_m > 0.0 && t.patch_width_m > 0.0);
  double e0[3], e1[3];
  Rows(i, g.normal, e0, e1);
  // The patch's corners on the floor plane (its rows made horizontal).
  const double l0 = std::hypot(e0[0], e0[1]);
  const double ax = l0 > 1e-9 ? e0[0] / l0 : 1.0, ay = l0 > 1e-9 ? e0[1] / l0 : 0.0;
  const double hl = 0.5 * t.patch_length_m, hw = 0.5 * t.patch_width_m;
  const double reach = std::hypot(hl, hw);
  const double area = t.patch_length_m * t.patch_width_m;
  double gap = 0.0;
  patch.own_share = 0.0;
  int kept = 0;
  for (std::size_t k = 0; k < belts_.size(); ++k) {
    const BeltPatch& b = belts_[k];
    const auto& u = belt_axes_[k];
    const double dx = g.pos[0] - b.center_x_m, dy = g.pos[1] - b.center_y_m;
    const double along = dx * u[0] + dy * u[1], across = dx * u[2] + dy * u[3];
    const double bl = 0.5 * b.length_m, bw = 0.5 * b.width_m, bg = b.edge_gap_m;
    double in = 0.0, out_gap = 0.0;
    if (point) {
      const bool on = std::abs(along) <= bl && std::abs(across) <= bw;
      in = on ? 1.0 : 0.0;
      out_gap = !on && std::abs(along) <= bl + bg && std::abs(across) <= bw + bg ? 1.0 : 0.0;
    } else {
      if (std::abs(along) >= bl + bg + reach || std::abs(across) >= bw + bg + reach) continue;
      if (std::abs(along) <= bl - reach && std::abs(across) <= bw - reach) {
        in = 1.0;
      } else {
        // Corners in the belt's frame: centre +- hl rolling +- hw across.
        const double ra = ax * u[0] + ay * u[1], rc = ax * u[2] + ay * u[3];  // rolling dir
        const double sa = -rc, sc = ra;                                       // across it
        std::array<double, 8> quad{};
        const double cs[4][2] = {{hl, hw}, {-hl, hw}, {-hl, -hw}, {hl, -hw}};
        for (int c = 0; c < 4; ++c) {
          quad[static_cast<std::size_t>(2 * c)] = along + cs[c][0] * ra + cs[c][1] * sa;
          quad[static_cast<std::size_t>(2 * c + 1)] = across + cs[c][0] * rc + cs[c][1] * sc;
        }
        in = AreaInBox(quad, bl, bw) / area;
        out_gap = bg > 0.0 ? AreaInBox(quad, bl + bg, bw + bg) / area - in : 0.0;
      }
    }
    gap += out_gap;
    if (in <= 0.0) continue;
    // Keep the kPatchBelts largest shares.
    std::size_t slot = 0;
    if (kept < kPatchBelts) {
      slot = static_cast<std::size_t>(kept++);
    } else {
      slot = patch.belt_share[0] < patch.belt_share[1] ? 0 : 1;
      if (patch.belt_share[slot] >= in) continue;
    }
    patch.belt[slot] = static_cast<int>(k);
    patch.belt_share[slot] = in;
  }
  patch.own_share = std::max(0.0, 1.0 - patch.belt_share[0] - patch.belt_share[1] - gap);
  return patch;
}

void FloorWorld::PatchSurface(std::size_t i, const Patch& patch, int s, double v[3],
                              double* mu) const {
  v[0] = v[1] = v[2] = 0.0;
  const double support = patch.Support();
  if (!(support > 0.0)) {
    *mu = 0.0;
    return;
  }
  // The surface the point touches: the floor (0) on the plane, else its
  // terrain piece, still either way.
  const int own = s > belt_count() ? s : 0;
  double weighted_mu = patch.own_share * SurfaceMu(i, own);
  for (std::size_t b = 0; b < static_cast<std::size_t>(kPatchBelts); ++b) {
    const int k = patch.belt[b];
    if (k < 0) continue;
    const double w = patch.belt_share[b];
    weighted_mu += w * SurfaceMu(i, k + 1);
    const auto& bv = belt_velocity_mps_[static_cast<std::size_t>(k)];
    v[0] += w * bv[0];
    v[1] += w * bv[1];
  }
  v[0] /= support;
  v[1] /= support;
  *mu = weighted_mu / support;
}

void FloorWorld::AddObstacle(const models::Solid& solid) {
  double z = 0.0;
  obstacles_.push_back(SolidGeom(solid, &z));
  Aabb box;
  dGeomGetAABB(obstacles_.back(), box.data());
  obstacle_aabbs_.push_back(box);
  near_region_ = {1.0, -1.0, 1.0, -1.0, 1.0, -1.0};  // list again
  collided_ = false;
}

void FloorWorld::SetFloorProfile(const models::SurfaceProfile& profile) {
  floor_profile_ = profile;
  dGeomPlaneSetParams(floor_, 0.0, 0.0, 1.0, profile.bound_m());
  collided_ = false;
}

void FloorWorld::AddTerrain(const models::TerrainPiece& t, double mu,
                            const models::SurfaceProfile& profile) {
  if (!(t.length_m > 0.0 && t.width_m > 0.0 && t.thickness_m > 0.0)) {
    throw std::invalid_argument("FloorWorld: terrain piece '" + t.name +
                                "' needs a positive length, width and thickness");
  }
  Terrain piece;
  piece.mu = mu;
  piece.profile = profile;
  piece.raise_m = profile.bound_m();
  piece.geom = dCreateBox(nullptr, t.length_m, t.width_m, t.thickness_m + piece.raise_m);
  // R = Rz(yaw) Ry(-pitch) Rx(roll): + pitch raises the far (+length) end,
  // as models::TerrainPiece says (and units/sensors/ray_scene.cc draws it);
  // its columns are the piece's axes in map. ODE's rows hold 4 entries.
  const double cy = std::cos(t.yaw_rad), sy = std::sin(t.yaw_rad);
  const double cp = std::cos(-t.pitch_rad), sp = std::sin(-t.pitch_rad);
  const double cr = std::cos(t.roll_rad), sr = std::sin(t.roll_rad);
  const double ax[3] = {cy * cp, sy * cp, -sp};
  const double ay[3] = {cy * sp * sr - sy * cr, sy * sp * sr + cy * cr, cp * sr};
  const double az[3] = {cy * sp * cr + sy * sr, sy * sp * cr - cy * sr, cp * cr};
  dMatrix3 rot;
  for (int r = 0; r < 3; ++r) {
    rot[4 * r + 0] = ax[r];
    rot[4 * r + 1] = ay[r];
    rot[4 * r + 2] = az[r];
    rot[4 * r + 3] = 0.0;
  }
  dGeomSetRotation(piece.geom, rot);
  // Thicker upwards by the profile's bound: the nominal bottom stays.
  const double up = 0.5 * piece.raise_m;
  dGeomSetPosition(piece.geom, t.center_x_m + up * az[0], t.center_y_m + up * az[1],
                   t.center_z_m + up * az[2]);
  dGeomGetAABB(piece.geom, piece.aabb.data());
  terrain_.push_back(piece);
  near_region_ = {1.0, -1.0, 1.0, -1.0, 1.0, -1.0};  // list again
  collided_ = false;
}

double FloorWorld::TerrainTopAt(double x_m, double y_m) const {
  double top = -std::numeric_limits<double>::infinity();
  for (const Terrain& t : terrain_) {
    const dReal* c = dGeomGetPosition(t.geom);
    const dReal* r = dGeomGetRotation(t.geom);
    dVector3 size;
    dGeomBoxGetLengths(t.geom, size);
    // The piece's axes (columns of R) and its top face's centre.
    const double ax[3] = {r[0], r[4], r[8]}, ay[3] = {r[1], r[5], r[9]},
                 az[3] = {r[2], r[6], r[10]};
    if (az[2] <= 0.0) continue;  // never for a tilt within +-89 deg
    // (The nominal top: a box stands raise_m above it for its profile.)
    const double half = 0.5 * size[2] - t.raise_m;
    const double tc[3] = {c[0] + half * az[0], c[1] + half * az[1], c[2] + half * az[2]};
    // The top face's plane above (x, y), and that point in the piece's axes.
    const double z = tc[2] - (az[0] * (x_m - tc[0]) + az[1] * (y_m - tc[1])) / az[2];
    const double d[3] = {x_m - tc[0], y_m - tc[1], z - tc[2]};
    const double along = ax[0] * d[0] + ax[1] * d[1] + ax[2] * d[2];
    const double across = ay[0] * d[0] + ay[1] * d[1] + ay[2] * d[2];
    if (std::abs(along) <= 0.5 * size[0] && std::abs(across) <= 0.5 * size[1]) {
      top = std::max(top, z);
    }
  }
  return top;
}

std::array<double, 2> CarriedTravelRange(const BeltPatch& b, const models::Solid& solid) {
  return models::CarriedTravelRange(
      {b.center_x_m, b.center_y_m, b.length_m, b.width_m, b.direction_rad}, solid);
}

void FloorWorld::AddCarried(const models::Solid& solid, int belt) {
  if (belt < 0 || belt >= belt_count()) throw std::out_of_range("FloorWorld: no such belt");
  const auto range = CarriedTravelRange(belts_[static_cast<std::size_t>(belt)], solid);
  if (!(0.0 <= range[1] && range[0] <= range[1])) {
    throw std::invalid_argument(
        "FloorWorld: a carried object's footprint overhangs the downstream end of its belt at "
        "zero travel, or is longer than the belt");
  }
  Carried c;
  c.travel_min_m = range[0];
  c.travel_max_m = range[1];
  c.geom = SolidGeom(solid, &c.z_m);
  c.belt = belt;
  c.x0_m = solid.x_m;
  c.y0_m = solid.y_m;
  dGeomGetAABB(c.geom, c.aabb0.data());
  carried_.push_back(c);
}

void FloorWorld::SetBeltTravel(int k, double travel_m) {
  belt_travel_m_.at(static_cast<std::size_t>(k)) = travel_m;
  travel_elapsed_s_ = 0.0;
}

double FloorWorld::CarriedSpeed(std::size_t i) const {
  const auto b = static_cast<std::size_t>(carried_[i].belt);
  const auto& v = belt_velocity_mps_[b];
  return v[0] * belt_axes_[b][0] + v[1] * belt_axes_[b][1];
}

void FloorWorld::CollideObject(dGeomID body_geom, dGeomID object, const double v[3]) {
  // The body geom first, so that the normal points into it (from the object).
  std::array<dContact, kMaxPoints> pts{};
  const int n = dCollide(body_geom, object, kMaxPoints, &pts[0].geom, sizeof(dContact));
  const dBodyID body = dGeomGetBody(body_geom);
  for (int j = 0; j < n; ++j) {
    dContact& p = pts[static_cast<std::size_t>(j)];
    const dReal* nrm = p.geom.normal;
    // A tangent: map z x normal, or map x less its normal part when the
    // normal is vertical.
    double t1[3] = {-nrm[1], nrm[0], 0.0};
    double len = std::hypot(t1[0], t1[1]);
    if (len < 1e-6) {
      t1[0] = 1.0 - nrm[0] * nrm[0];
      t1[1] = -nrm[0] * nrm[1];
      t1[2] = -nrm[0] * nrm[2];
      len = std::sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
    }
    for (double& e : t1) e /= len;
    const double t2[3] = {nrm[1] * t1[2] - nrm[2] * t1[1], nrm[2] * t1[0] - nrm[0] * t1[2],
                          nrm[0] * t1[1] - nrm[1] * t1[0]};
    // Contact rows with body2 = 0: n . v_body >= pushout + motionN, so
    // motionN = n . v_object keeps the body from moving into the object;
    // fdir . v_body = motion makes a sticking contact move with it.
    p.surface.mode = dContactApprox1 | dContactSoftCFM | dContactSoftERP | dContactMotion1 |
                     dContactMotion2 | dContactMotionN | dContactFDir1;
    p.surface.mu = body_mu_;
    p.surface.soft_erp = object_erp_;
    p.surface.soft_cfm = object_cfm_;
    p.surface.motion1 = v[0] * t1[0] + v[1] * t1[1] + v[2] * t1[2];
    p.surface.motion2 = v[0] * t2[0] + v[1] * t2[1] + v[2] * t2[2];
    p.surface.motionN = v[0] * nrm[0] + v[1] * nrm[1] + v[2] * nrm[2];
    for (int d = 0; d < 3; ++d) p.fdir1[d] = t1[d];
    const dJointID joint = dJointCreateContact(world_, group_, &p);
    dJointAttach(joint, body, nullptr);
  }
}

void FloorWorld::UpdateNear() {
  if (obstacles_.empty() && terrain_.empty()) return;
  // The AABB of every geom of the robot (wheels and body geoms).
  Aabb robot = {1.0, -1.0, 1.0, -1.0, 1.0, -1.0};
  bool any = false;
  const auto grow = [&](dGeomID g) {
    Aabb b;
    dGeomGetAABB(g, b.data());
    if (!any) {
      robot = b;
      any = true;
      return;
    }
    for (int d = 0; d < 3; ++d) {
      robot[2 * d] = std::min(robot[2 * d], b[2 * d]);
      robot[2 * d + 1] = std::max(robot[2 * d + 1], b[2 * d + 1]);
    }
  };
  for (dGeomID g : geoms_) grow(g);
  for (dGeomID g : body_geoms_) grow(g);
  if (!any) return;
  const Aabb& r = near_region_;
  if (r[0] <= robot[0] && robot[1] <= r[1] && r[2] <= robot[2] && robot[3] <= r[3] &&
      r[4] <= robot[4] && robot[5] <= r[5]) {
    return;
  }
  near_region_ = {robot[0] - kNearMarginM, robot[1] + kNearMarginM, robot[2] - kNearMarginM,
                  robot[3] + kNearMarginM, robot[4] - kNearMarginM, robot[5] + kNearMarginM};
  near_obstacles_.clear();
  for (std::size_t i = 0; i < obstacles_.size(); ++i) {
    if (Overlap(obstacle_aabbs_[i], near_region_)) near_obstacles_.push_back(i);
  }
  near_terrain_.clear();
  for (std::size_t j = 0; j < terrain_.size(); ++j) {
    if (Overlap(terrain_[j].aabb, near_region_)) near_terrain_.push_back(j);
  }
}

void FloorWorld::CollideObjects(double erp, double cfm) {
  if (body_geoms_.empty() ||
      (near_obstacles_.empty() && near_terrain_.empty() && carried_.empty() &&
       moving_box_geoms_.empty() && moving_cylinder_geoms_.empty())) {
    return;
  }
  object_erp_ = erp;
  object_cfm_ = cfm;
  const double still[3] = {0.0, 0.0, 0.0};
  for (dGeomID body_geom : body_geoms_) {
    Aabb body;
    dGeomGetAABB(body_geom, body.data());
    for (std::size_t i : near_obstacles_) {
      if (Overlap(obstacle_aabbs_[i], body)) CollideObject(body_geom, obstacles_[i], still);
    }
    for (std::size_t j : near_terrain_) {
      if (Overlap(terrain_[j].aabb, body)) CollideObject(body_geom, terrain_[j].geom, still);
    }
    for (std::size_t i = 0; i < carried_.size(); ++i) {
      const Carried& c = carried_[i];
      const auto b = static_cast<std::size_t>(c.belt);
      const double speed = CarriedSpeed(i);
      const double s = belt_travel_m_[b] + speed * travel_elapsed_s_;
      // Past an end of its belt: lifted off the line, gone from the scene.
      if (s < c.travel_min_m || s > c.travel_max_m) continue;
      const double dx = s * belt_axes_[b][0], dy = s * belt_axes_[b][1];
      const Aabb moved = {c.aabb0[0] + dx, c.aabb0[1] + dx, c.aabb0[2] + dy,
                          c.aabb0[3] + dy, c.aabb0[4],      c.aabb0[5]};
      if (!Overlap(moved, body)) continue;
      dGeomSetPosition(c.geom, c.x0_m + dx, c.y0_m + dy, c.z_m);
      const double v[3] = {speed * belt_axes_[b][0], speed * belt_axes_[b][1], 0.0};
      CollideObject(body_geom, c.geom, v);
    }
    CollideMoving(body_geom, body);
  }
}

void FloorWorld::SetMovingSolids(std::span<const double> boxes, std::span<const double> cylinders,
                                 int own_box) {
  own_box_ = own_box;
  using models::MovingBox;
  using models::MovingCylinder;
  const std::size_t nb = boxes.size() / MovingBox::kValues;
  const std::size_t nc = cylinders.size() / MovingCylinder::kValues;
  while (moving_box_geoms_.size() < nb) moving_box_geoms_.push_back(dCreateBox(nullptr, 1, 1, 1));
  while (moving_cylinder_geoms_.size() < nc) {
    // ODE's cylinder stands along its local z, the map's vertical here.
    moving_cylinder_geoms_.push_back(dCreateCylinder(nullptr, 1, 1));
  }
  const auto whole = [](std::span<const double> values, std::size_t count, std::size_t size) {
    return values.first(count * size);
  };
  const auto b = whole(boxes, nb, MovingBox::kValues);
  const auto c = whole(cylinders, nc, MovingCylinder::kValues);
  moving_boxes_.assign(b.begin(), b.end());
  moving_cylinders_.assign(c.begin(), c.end());
  moving_elapsed_s_ = 0.0;
}

void FloorWorld::CollideMoving(dGeomID body_geom, const Aabb& body) {
  using models::MovingBox;
  using models::MovingCylinder;
  const double t = moving_elapsed_s_;
  for (std::size_t i = 0; i < moving_boxes_.size() / MovingBox::kValues; ++i) {
    const double* m = moving_boxes_.data() + i * MovingBox::kValues;
    const double length = m[MovingBox::kLength], width = m[MovingBox::kWidth];
    const double z0 = m[MovingBox::kZBottom], z1 = m[MovingBox::kZTop];
    if (!(length > 0.0 && width > 0.0 && z1 > z0) || static_cast<int>(i) == own_box_) continue;
    const double x = m[MovingBox::kX] + m[MovingBox::kVx] * t;
    const double y = m[MovingBox::kY] + m[MovingBox::kVy] * t;
    const double r = 0.5 * std::hypot(length, width);
    const Aabb bound = {x - r, x + r, y - r, y + r, z0, z1};
    if (!Overlap(bound, body)) continue;
    const dGeomID g = moving_box_geoms_[i];
    dGeomBoxSetLengths(g, length, width, z1 - z0);
    dGeomSetPosition(g, x, y, 0.5 * (z0 + z1));
    dMatrix3 rotation;
    dRFromAxisAndAngle(rotation, 0, 0, 1, m[MovingBox::kYaw] + m[MovingBox::kYawRate] * t);
    dGeomSetRotation(g, rotation);
    const double v[3] = {m[MovingBox::kVx], m[MovingBox::kVy], 0.0};
    CollideObject(body_geom, g, v);
  }
  for (std::size_t i = 0; i < moving_cylinders_.size() / MovingCylinder::kValues; ++i) {
    const double* m = moving_cylinders_.data() + i * MovingCylinder::kValues;
    const double radius = m[MovingCylinder::kRadius];
    const double z0 = m[MovingCylinder::kZBottom], z1 = m[MovingCylinder::kZTop];
    if (!(radius > 0.0 && z1 > z0)) continue;
    const double x = m[MovingCylinder::kX] + m[MovingCylinder::kVx] * t;
    const double y = m[MovingCylinder::kY] + m[MovingCylinder::kVy] * t;
    const Aabb bound = {x - radius, x + radius, y - radius, y + radius, z0, z1};
    if (!Overlap(bound, body)) continue;
    const dGeomID g = moving_cylinder_geoms_[i];
    dGeomCylinderSetParams(g, radius, z1 - z0);
    dGeomSetPosition(g, x, y, 0.5 * (z0 + z1));
    const double v[3] = {m[MovingCylinder::kVx], m[MovingCylinder::kVy], 0.0};
    CollideObject(body_geom, g, v);
  }
}

int FloorWorld::AddGeom(dGeomID geom, Tread tread) {
  geoms_.push_back(geom);
  GeomContact c;
  const dReal* p = dGeomGetPosition(geom);
  c.x_m = p[0];
  c.y_m = p[1];
  contacts_.push_back(c);
  points_.emplace_back();
  treads_.push_back(std::move(tread));
  tread_states_.emplace_back();
  collided_ = false;
  return static_cast<int>(geoms_.size()) - 1;
}

void FloorWorld::ClearGeoms() {
  geoms_.clear();
  contacts_.clear();
  points_.clear();
  treads_.clear();
  tread_states_.clear();
  collided_ = false;
}

std::vector<double> FloorWorld::TreadStates() const {
  std::vector<double> out;
  out.reserve(tread_states_.size() * kTreadStateReals);
  for (const TreadState& t : tread_states_) {
    out.insert(out.end(), t.deflection, t.deflection + 3);
    out.insert(out.end(), t.force_dir, t.force_dir + 3);
  }
  return out;
}

void FloorWorld::SetTreadStates(std::span<const double> values) {
  if (values.size() != tread_states_.size() * kTreadStateReals) {
    throw std::invalid_argument("FloorWorld: " + std::to_string(values.size()) +
                                " tread state values for " + std::to_string(tread_states_.size()) +
                                " treads");
  }
  for (std::size_t i = 0; i < tread_states_.size(); ++i) {
    const double* v = values.data() + i * kTreadStateReals;
    TreadState& t = tread_states_[i];
    std::copy(v, v + 3, t.deflection);
    std::copy(v + 3, v + 6, t.force_dir);
  }
}

void FloorWorld::ResetTreads() {
  for (TreadState& t : tread_states_) t = TreadState{};
}

double FloorWorld::TreadEnergy() const {
  double energy = 0.0;
  for (std::size_t i = 0; i < treads_.size(); ++i) {
    const TreadState& t = tread_states_[i];
    for (int r = 0; r < 2; ++r) {
      const double d =
          t.e[r][0] * t.deflection[0] + t.e[r][1] * t.deflection[1] + t.e[r][2] * t.deflection[2];
      energy += 0.5 * t.support * treads_[i].stiffness_n_per_m[r] * d * d;
    }
  }
  return energy;
}

void FloorWorld::PatchVelocity(int i, double* vx_mps, double* vy_mps) const {
  const auto k = static_cast<std::size_t>(i);
  const Points& pts = points_[k];
  *vx_mps = 0.0;
  *vy_mps = 0.0;
  if (pts.count == 0) return;
  std::size_t deepest = 0;
  for (std::size_t j = 1; j < static_cast<std::size_t>(pts.count); ++j) {
    if (pts.contact[j].geom.depth > pts.contact[deepest].geom.depth) deepest = j;
  }
  double v[3], mu = 0.0;
  PatchSurface(k, pts.patch[deepest], pts.surface[deepest], v, &mu);
  *vx_mps = v[0];
  *vy_mps = v[1];
}

int FloorWorld::SurfaceAt(double x_m, double y_m) const {
  for (std::size_t k = 0; k < belts_.size(); ++k) {
    const BeltPatch& b = belts_[k];
    const auto& a = belt_axes_[k];
    const double dx = x_m - b.center_x_m;
    const double dy = y_m - b.center_y_m;
    const double along = dx * a[0] + dy * a[1];
    const double across = dx * a[2] + dy * a[3];
    if (std::abs(along) <= 0.5 * b.length_m && std::abs(across) <= 0.5 * b.width_m) {
      return static_cast<int>(k) + 1;
    }
  }
  return 0;
}

double FloorWorld::SurfaceMu(std::size_t i, int s) const {
  const std::vector<double>& own = treads_[i].mu;
  if (s >= 0 && static_cast<std::size_t>(s) < own.size()) return own[static_cast<std::size_t>(s)];
  if (s > belt_count()) return terrain_[static_cast<std::size_t>(s - belt_count() - 1)].mu;
  return s > 0 ? belts_[static_cast<std::size_t>(s - 1)].mu : surface_.mu;
}

void FloorWorld::SurfaceVelocity(int surface, double* vx_mps, double* vy_mps) const {
  if (surface <= 0 || surface > belt_count()) {
    *vx_mps = 0.0;
    *vy_mps = 0.0;
    return;
  }
  const auto& v = belt_velocity_mps_[static_cast<std::size_t>(surface - 1)];
  *vx_mps = v[0];
  *vy_mps = v[1];
}

void FloorWorld::Collide(std::size_t i) {
  const dGeomID geom = geoms_[i];
  Points& pts = points_[i];
  GeomContact& c = contacts_[i];
  // Makes the moving geom g1 with the normal pointing into it (from the
  // static one), whatever order the collider reports, so that the surface
  // motion sign in MakeJoints holds; notes each point's surface.
  const auto orient = [&](int from, int to, dGeomID other, int surface) {
    for (std::size_t j = static_cast<std::size_t>(from); j < static_cast<std::size_t>(to); ++j) {
      dContactGeom& g = pts.contact[j].geom;
      if (g.g1 == other) {
        std::swap(g.g1, g.g2);
        for (int d = 0; d < 3; ++d) g.normal[d] = -g.normal[d];
      }
      pts.surface[j] = surface >= 0 ? surface : SurfaceAt(g.pos[0], g.pos[1]);
    }
  };
  int n = dCollide(geom, floor_, kMaxPoints, &pts.contact[0].geom, sizeof(dContact));
  orient(0, n, floor_, -1);
  if (floor_profile_.bound_m() > 0.0) n = ToUnevenSurface(pts, 0, n, 0);
  if (!near_terrain_.empty()) {
    Aabb box;
    dGeomGetAABB(geom, box.data());
    for (std::size_t j : near_terrain_) {
      const Terrain& t = terrain_[j];
      if (n >= kMaxPoints || !Overlap(box, t.aabb)) continue;
      const int m = dCollide(geom, t.geom, kMaxPoints - n,
                             &pts.contact[static_cast<std::size_t>(n)].geom, sizeof(dContact));
      const int s = belt_count() + 1 + static_cast<int>(j);
      orient(n, n + m, t.geom, s);
      n = t.raise_m > 0.0 ? ToUnevenSurface(pts, n, n + m, s) : n + m;
    }
  }
  pts.count = n;
  c.points = n;
  if (n == 0) {
    const dReal* p = dGeomGetPosition(geom);
    c.surface = -1;
    c.x_m = p[0];
    c.y_m = p[1];
    c.depth_m = 0.0;
    c.support_share = 0.0;
    return;
  }
  for (std::size_t j = 0; j < static_cast<std::size_t>(n); ++j) {
    pts.patch[j] = PatchAt(i, pts.contact[j].geom, pts.surface[j]);
  }
  double sx = 0.0, sy = 0.0;
  std::size_t deepest = 0;
  for (std::size_t j = 0; j < static_cast<std::size_t>(n); ++j) {
    const dContactGeom& g = pts.contact[j].geom;
    sx += g.pos[0];
    sy += g.pos[1];
    if (g.depth > pts.contact[deepest].geom.depth) deepest = j;
  }
  c.x_m = sx / n;
  c.y_m = sy / n;
  c.surface = pts.surface[deepest];
  c.depth_m = pts.contact[deepest].geom.depth;
  c.support_share = pts.patch[deepest].Support();
}

int FloorWorld::ToUnevenSurface(Points& pts, int from, int to, int s) const {
  // The surface's plane: its axes (columns of R), a point of its nominal
  // level and how far the collision geometry stands above that.
  const models::SurfaceProfile* profile = &floor_profile_;
  double ax[3] = {1.0, 0.0, 0.0}, ay[3] = {0.0, 1.0, 0.0}, az[3] = {0.0, 0.0, 1.0};
  double origin[3] = {0.0, 0.0, 0.0};
  double raise = floor_profile_.bound_m();
  const int piece = s - belt_count() - 1;
  if (piece >= 0) {
    const Terrain& t = terrain_[static_cast<std::size_t>(piece)];
    profile = &t.profile;
    raise = t.raise_m;
    const dReal* r = dGeomGetRotation(t.geom);
    const dReal* c = dGeomGetPosition(t.geom);
    dVector3 size;
    dGeomBoxGetLengths(t.geom, size);
    for (int k = 0; k < 3; ++k) {
      ax[k] = r[4 * k];
      ay[k] = r[4 * k + 1];
      az[k] = r[4 * k + 2];
    }
    const double half = 0.5 * size[2] - raise;  // to the nominal top
    for (int k = 0; k < 3; ++k) origin[k] = c[k] + half * az[k];
  }
  int kept = from;
  for (int j = from; j < to; ++j) {
    dContact& contact = pts.contact[static_cast<std::size_t>(j)];
    dContactGeom& g = contact.geom;
    const double facing = g.normal[0] * az[0] + g.normal[1] * az[1] + g.normal[2] * az[2];
    double h = 0.0, dh_du = 0.0, dh_dv = 0.0;
    // A belt is level (h = 0): only the floor around it is uneven.
    const bool on_profile = piece >= 0 || pts.surface[static_cast<std::size_t>(j)] == 0;
    if (on_profile) {
      const double d[3] = {g.pos[0] - origin[0], g.pos[1] - origin[1], g.pos[2] - origin[2]};
      const double u = ax[0] * d[0] + ax[1] * d[1] + ax[2] * d[2];
      const double v = ay[0] * d[0] + ay[1] * d[1] + ay[2] * d[2];
      h = profile->Height(u, v, &dh_du, &dh_dv);
    }
    const double drop = (raise - h) * facing;
    g.depth -= drop;
    if (!(g.depth > 0.0)) continue;
    double nrm[3];
    for (int k = 0; k < 3; ++k) {
      g.pos[k] -= drop * az[k];
      nrm[k] = g.normal[k] - facing * (dh_du * ax[k] + dh_dv * ay[k]);
    }
    const double len = std::sqrt(nrm[0] * nrm[0] + nrm[1] * nrm[1] + nrm[2] * nrm[2]);
    for (int k = 0; k < 3; ++k) g.normal[k] = nrm[k] / len;
    if (kept != j) {
      pts.contact[static_cast<std::size_t>(kept)] = contact;
      pts.surface[static_cast<std::size_t>(kept)] = pts.surface[static_cast<std::size_t>(j)];
    }
    ++kept;
  }
  return kept;
}

void FloorWorld::Probe() {
  UpdateNear();
  for (std::size_t i = 0; i < geoms_.size(); ++i) Collide(i);
  collided_ = true;
}

void FloorWorld::MakeJoints(std::size_t i, double h_s, double erp, double cfm) {
  Points& pts = points_[i];
  const Tread& tread = treads_[i];
  TreadState& state = tread_states_[i];
  const dBodyID body = dGeomGetBody(geoms_[i]);
  const auto n_points = static_cast<std::size_t>(pts.count);
  pts.joints = 0;
  if (n_points == 0) return;
  const bool rolls = tread.axle[0] != 0.0 || tread.axle[1] != 0.0 || tread.axle[2] != 0.0;
  const dReal* centre_v = body ? dBodyGetLinearVel(body) : nullptr;
  // The shared deflection's share per point: each point's rows carry
  // 1 / n of the tread's stiffness and damping (their forces add up).
  const double per_point = 1.0 / static_cast<double>(n_points);
  std::size_t deepest = 0;
  for (std::size_t j = 0; j < n_points; ++j) {
    if (pts.contact[j].geom.depth > pts.contact[deepest].geom.depth) deepest = j;
  }
  for (std::size_t j = 0; j < n_points; ++j) {
    dContact& p = pts.contact[j];
    const dReal* nrm = p.geom.normal;
    double e[2][3], v_surface[3], mu = 0.0;
    Rows(i, nrm, e[0], e[1]);
    PatchSurface(i, pts.patch[j], pts.surface[j], v_surface, &mu);
    const double support = pts.patch[j].Support();
    p.surface.mode = dContactApprox1 | dContactSoftCFM | dContactSoftERP | dContactMotion1 |
                     dContactMotion2 | dContactFDir1 | dContactSlip1 | dContactSlip2 | dContactMu2;
    double motion[2], slip[2], bound[2], relax[2];
    const double* u = state.force_dir;
    const bool saturated = u[0] != 0.0 || u[1] != 0.0 || u[2] != 0.0;
    for (int r = 0; r < 2; ++r) {
      const double* er = e[r];
      // Forward speed of the wheel centre over the surface: the rate at
      // which new tread enters the patch (a block never relaxes).
      const double vx = centre_v && rolls
                            ? e[0][0] * (centre_v[0] - v_surface[0]) +
                                  e[0][1] * (centre_v[1] - v_surface[1]) + e[0][2] * centre_v[2]
                            : 0.0;
      relax[r] = 1.0 / (1.0 + h_s * std::abs(vx) / tread.relaxation_m[r]);
      const double k = support * per_point * tread.stiffness_n_per_m[r] * relax[r];
      const double d = support * per_point * tread.damping_n_s_per_m[r];
      const double delta =
          er[0] * state.deflection[0] + er[1] * state.deflection[1] + er[2] * state.deflection[2];
      const double surface_along = er[0] * v_surface[0] + er[1] * v_surface[1];
      if (h_s * k + d > 0.0) {
        slip[r] = 1.0 / (h_s * k + d);
        motion[r] = surface_along - k * slip[r] * delta;  // (erp / h) delta, erp = h k slip
      } else {
        slip[r] = 1.0;  // nothing under the patch: no friction (bound 0)
        motion[r] = surface_along;
      }
      // A saturated tread's mu split by its force direction, never below
      // kMinMuShare: ODE's LCP fails on a friction row with a bound near 0
      // and a large slip ("LCP internal error, s <= 0": seen at shares of
      // 0.1 and below, none at 0.2). A row keeps 0.2 mu N at least, so a
      // tread sliding along one row may carry up to 0.2 mu N across it
      // (1.02 mu N in all) when the other row slides too.
      bound[r] = saturated ? mu * std::max(kMinMuShare,
                                           std::abs(er[0] * u[0] + er[1] * u[1] + er[2] * u[2]))
                           : mu;
    }
    p.surface.mu = bound[0];
    p.surface.mu2 = bound[1];
    p.surface.slip1 = slip[0];
    p.surface.slip2 = slip[1];
    p.surface.soft_erp = erp;
    p.surface.soft_cfm = cfm;
    p.surface.motion1 = motion[0];
    p.surface.motion2 = motion[1];
    p.surface.motionN = 0.0;
    p.surface.bounce = 0.0;
    p.surface.bounce_vel = 0.0;
    for (int d = 0; d < 3; ++d) p.fdir1[d] = e[0][d];
    const dJointID joint = dJointCreateContact(world_, group_, &p);
    // body1 = the moving geom's body, body2 = the static floor or piece (0).
    dJointAttach(joint, body, dGeomGetBody(p.geom.g2));
    dJointSetFeedback(joint, &pts.feedback[j]);
    if (j == deepest) {
      std::copy(&e[0][0], &e[0][0] + 6, &state.e[0][0]);
      state.relax[0] = relax[0];
      state.relax[1] = relax[1];
      state.mu = mu;
      state.support = support;
      std::copy(v_surface, v_surface + 3, state.surface_v);
    }
  }
  pts.joints = static_cast<int>(n_points);
}

void FloorWorld::UpdateTread(std::size_t i, double h_s) {
  Points& pts = points_[i];
  TreadState& state = tread_states_[i];
  const Tread& tread = treads_[i];
  if (pts.joints == 0 || !(state.support > 0.0)) {
    state = TreadState{};  // off the ground (or over a gap): the tread unloads
    return;
  }
  // The step's normal load and the slip at its end, at the points it used.
  const dBodyID body = dGeomGetBody(geoms_[i]);
  double load = 0.0, slip[2] = {0.0, 0.0};
  const double n_points = pts.joints;
  for (std::size_t j = 0; j < static_cast<std::size_t>(pts.joints); ++j) {
    const dContactGeom& g = pts.contact[j].geom;
    const dReal* f = pts.feedback[j].f1;
    load += f[0] * g.normal[0] + f[1] * g.normal[1] + f[2] * g.normal[2];
    dVector3 v = {0.0, 0.0, 0.0, 0.0};
    if (body) dBodyGetPointVel(body, g.pos[0], g.pos[1], g.pos[2], v);
    for (int r = 0; r < 2; ++r) {
      const double* er = state.e[r];
      slip[r] += (er[0] * (v[0] - state.surface_v[0]) + er[1] * (v[1] - state.surface_v[1]) +
                  er[2] * v[2]) /
                 n_points;
    }
  }
  // delta(t + h) = (delta + h v_slip) / (1 + h |V_x| / sigma) per row, and
  // the force those springs and dampers ask for.
  double delta[2], trial[2];
  for (int r = 0; r < 2; ++r) {
    const double* er = state.e[r];
    const double d0 =
        er[0] * state.deflection[0] + er[1] * state.deflection[1] + er[2] * state.deflection[2];
    delta[r] = (d0 + h_s * slip[r]) * state.relax[r];
    trial[r] = -state.support *
               (tread.stiffness_n_per_m[r] * delta[r] + tread.damping_n_s_per_m[r] * slip[r]);
  }
  const double limit = state.mu * std::max(load, 0.0);
  const double trial_n = std::hypot(trial[0], trial[1]);
  std::fill(state.force_dir, state.force_dir + 3, 0.0);
  if (trial_n > limit) {
    // Saturated: the next step's force is mu N along -slip while the tread
    // slides, along the trial force while it barely moves.
    const double slip_n = std::hypot(slip[0], slip[1]);
    double u[2] = {trial[0] / trial_n, trial[1] / trial_n};
    if (slip_n > kSlipAlignMps) {
      u[0] = -slip[0] / slip_n;
      u[1] = -slip[1] / slip_n;
    }
    for (int r = 0; r < 2; ++r) {
      for (int d = 0; d < 3; ++d) state.force_dir[d] += u[r] * state.e[r][d];
    }
    // The bristles deflect no further than mu N holds them (elasto-plastic):
    // the springs' force is scaled back onto the circle, which only takes
    // energy out of the tread.
    const double spring_n = state.support * std::hypot(tread.stiffness_n_per_m[0] * delta[0],
                                                       tread.stiffness_n_per_m[1] * delta[1]);
    if (spring_n > limit) {
      for (double& d : delta) d *= limit / spring_n;
    }
  }
  for (int d = 0; d < 3; ++d) {
    state.deflection[d] = delta[0] * state.e[0][d] + delta[1] * state.e[1][d];
  }
}

bool FloorWorld::Step(double h_s) {
  const auto [erp, cfm] = ErpCfm(h_s, surface_.stiffness_n_per_m, surface_.damping_n_s_per_m);
  int ok = 0;
  try {
    if (!collided_) Probe();
    for (std::size_t i = 0; i < geoms_.size(); ++i) MakeJoints(i, h_s, erp, cfm);
    CollideObjects(erp, cfm);
    ok = dWorldStep(world_, h_s);
    travel_elapsed_s_ += h_s;
    moving_elapsed_s_ += h_s;
    if (ok != 0) {
      for (std::size_t i = 0; i < geoms_.size(); ++i) UpdateTread(i, h_s);
    }
    dJointGroupEmpty(group_);
    // At the new positions: for contact(i) now and the next step's joints.
    if (ok != 0) Probe();
  } catch (const OdeError&) {
    dJointGroupEmpty(group_);
    collided_ = false;
    // The step was left midway: its threading object still lists its jobs,
    // and ODE asserts when such an object is freed. It is left allocated
    // (a few hundred bytes, once per failed run) and the world gets a fresh
    // one, so that it can be initialised and stepped again.
    threading_ = dThreadingAllocateSelfThreadedImplementation();
    dWorldSetStepThreadingImplementation(world_, dThreadingImplementationGetFunctions(threading_),
                                         threading_);
    throw;
  }
  if (ok == 0) collided_ = false;
  return ok != 0;
}

}  // namespace linesim::chassis
