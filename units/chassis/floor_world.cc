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

}  // namespace

void FloorWorld::AddObstacle(const models::Solid& solid) {
  double z = 0.0;
  obstacles_.push_back(SolidGeom(solid, &z));
  Aabb box;
  dGeomGetAABB(obstacles_.back(), box.data());
  obstacle_aabbs_.push_back(box);
  near_region_ = {1.0, -1.0, 1.0, -1.0, 1.0, -1.0};  // list again
  collided_ = false;
}

void FloorWorld::AddTerrain(const models::TerrainPiece& t, double mu) {
  if (!(t.length_m > 0.0 && t.width_m > 0.0 && t.thickness_m > 0.0)) {
    throw std::invalid_argument("FloorWorld: terrain piece '" + t.name +
                                "' needs a positive length, width and thickness");
  }
  Terrain piece;
  piece.mu = mu;
  piece.geom = dCreateBox(nullptr, t.length_m, t.width_m, t.thickness_m);
  dGeomSetPosition(piece.geom, t.center_x_m, t.center_y_m, t.center_z_m);
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
    const double ax[3] = {r[0], r[4], r[8]}, ay[3] = {r[1], r[5], r[9]}, az[3] = {r[2], r[6], r[10]};
    if (az[2] <= 0.0) continue;  // never for a tilt within +-89 deg
    const double tc[3] = {c[0] + 0.5 * size[2] * az[0], c[1] + 0.5 * size[2] * az[1],
                          c[2] + 0.5 * size[2] * az[2]};
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
  if (body_geoms_.empty() || (near_obstacles_.empty() && near_terrain_.empty() &&
                              carried_.empty() && moving_box_geoms_.empty() &&
                              moving_cylinder_geoms_.empty())) {
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

void FloorWorld::SetMovingSolids(std::span<const double> boxes,
                                 std::span<const double> cylinders, int own_box) {
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

int FloorWorld::AddGeom(dGeomID geom) {
  geoms_.push_back(geom);
  GeomContact c;
  const dReal* p = dGeomGetPosition(geom);
  c.x_m = p[0];
  c.y_m = p[1];
  contacts_.push_back(c);
  points_.emplace_back();
  collided_ = false;
  return static_cast<int>(geoms_.size()) - 1;
}

void FloorWorld::ClearGeoms() {
  geoms_.clear();
  contacts_.clear();
  points_.clear();
  collided_ = false;
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

double FloorWorld::SurfaceMu(int s) const {
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
  if (!near_terrain_.empty()) {
    Aabb box;
    dGeomGetAABB(geom, box.data());
    for (std::size_t j : near_terrain_) {
      const Terrain& t = terrain_[j];
      if (n >= kMaxPoints || !Overlap(box, t.aabb)) continue;
      const int m = dCollide(geom, t.geom, kMaxPoints - n,
                             &pts.contact[static_cast<std::size_t>(n)].geom, sizeof(dContact));
      orient(n, n + m, t.geom, belt_count() + 1 + static_cast<int>(j));
      n += m;
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
    return;
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
}

void FloorWorld::Probe() {
  UpdateNear();
  for (std::size_t i = 0; i < geoms_.size(); ++i) Collide(i);
  collided_ = true;
}

void FloorWorld::MakeJoints(std::size_t i, double erp, double cfm) {
  const auto tangent = [](const dReal* nrm, const double v[3], double out[3]) {
    const double vn = v[0] * nrm[0] + v[1] * nrm[1] + v[2] * nrm[2];
    for (int d = 0; d < 3; ++d) out[d] = v[d] - vn * nrm[d];
    return std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2]);
  };
  Points& pts = points_[i];
  for (std::size_t j = 0; j < static_cast<std::size_t>(pts.count); ++j) {
    dContact& p = pts.contact[j];
    const dReal* nrm = p.geom.normal;
    double vx = 0.0, vy = 0.0;
    SurfaceVelocity(pts.surface[j], &vx, &vy);
    const double surface[3] = {vx, vy, 0.0};
    // Slip of the body's contact point over the surface, at step start.
    const dBodyID body = dGeomGetBody(p.geom.g1);
    dVector3 point_v = {0.0, 0.0, 0.0, 0.0};
    if (body) dBodyGetPointVel(body, p.geom.pos[0], p.geom.pos[1], p.geom.pos[2], point_v);
    const double slip[3] = {point_v[0] - vx, point_v[1] - vy, point_v[2]};
    double t1[3], fallback[3];
    const double slip_mps = tangent(nrm, slip, t1);
    const double surface_mps = tangent(nrm, surface, fallback);
    if (slip_mps > kSlipAlignMps) {
      for (double& e : t1) e /= slip_mps;
    } else if (surface_mps > 0.0) {
      for (int d = 0; d < 3; ++d) t1[d] = fallback[d] / surface_mps;
    } else {
      // Sticking on a still surface: any tangent will do; map x on the
      // plane, or map y if x is the normal.
      const double axis[3] = {std::abs(nrm[0]) < 0.9 ? 1.0 : 0.0,
                              std::abs(nrm[0]) < 0.9 ? 0.0 : 1.0, 0.0};
      const double len = tangent(nrm, axis, t1);
      for (double& e : t1) e /= len;
    }
    // ODE's second friction direction is normal x fdir1.
    const double t2[3] = {nrm[1] * t1[2] - nrm[2] * t1[1], nrm[2] * t1[0] - nrm[0] * t1[2],
                          nrm[0] * t1[1] - nrm[1] * t1[0]};
    const bool sliding = slip_mps > kSlipAlignMps;
    p.surface.mode = dContactApprox1 | dContactSoftCFM | dContactSoftERP | dContactMotion1 |
                     dContactMotion2 | dContactFDir1 | (sliding ? dContactSlip2 : 0);
    p.surface.mu = SurfaceMu(pts.surface[j]);
    p.surface.slip2 = 1.0 / surface_.slip_damping_n_s_per_m;
    p.surface.soft_erp = erp;
    p.surface.soft_cfm = cfm;
    p.surface.motion1 = surface[0] * t1[0] + surface[1] * t1[1];
    p.surface.motion2 = surface[0] * t2[0] + surface[1] * t2[1];
    p.surface.motionN = 0.0;
    p.surface.bounce = 0.0;
    p.surface.bounce_vel = 0.0;
    for (int d = 0; d < 3; ++d) p.fdir1[d] = t1[d];
    const dJointID joint = dJointCreateContact(world_, group_, &p);
    // body1 = the moving geom's body, body2 = the static floor or piece (0).
    dJointAttach(joint, body, dGeomGetBody(p.geom.g2));
  }
}

bool FloorWorld::Step(double h_s) {
  const auto [erp, cfm] = ErpCfm(h_s, surface_.stiffness_n_per_m, surface_.damping_n_s_per_m);
  int ok = 0;
  try {
    if (!collided_) Probe();
    for (std::size_t i = 0; i < geoms_.size(); ++i) MakeJoints(i, erp, cfm);
    CollideObjects(erp, cfm);
    ok = dWorldStep(world_, h_s);
    travel_elapsed_s_ += h_s;
    moving_elapsed_s_ += h_s;
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
