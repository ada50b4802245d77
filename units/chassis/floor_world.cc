#include "units/chassis/floor_world.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <utility>

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
  dWorldSetGravity(world_, 0.0, 0.0, -kGravityMps2);
  group_ = dJointGroupCreate(0);
  // Not in a space: geoms are collided with the floor one by one.
  floor_ = dCreatePlane(nullptr, 0.0, 0.0, 1.0, 0.0);
}

FloorWorld::~FloorWorld() {
  EnsureOdeForThisThread();
  dJointGroupDestroy(group_);
  dGeomDestroy(floor_);
  dWorldDestroy(world_);
}

void FloorWorld::SetBelts(std::vector<BeltPatch> belts) {
  belts_ = std::move(belts);
  belt_velocity_mps_.assign(belts_.size(), {0.0, 0.0});
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

int FloorWorld::AddGeom(dGeomID geom) {
  geoms_.push_back(geom);
  GeomContact c;
  const dReal* p = dGeomGetPosition(geom);
  c.x_m = p[0];
  c.y_m = p[1];
  contacts_.push_back(c);
  return static_cast<int>(geoms_.size()) - 1;
}

void FloorWorld::ClearGeoms() {
  geoms_.clear();
  contacts_.clear();
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

void FloorWorld::SurfaceVelocity(int surface, double* vx_mps, double* vy_mps) const {
  if (surface <= 0) {
    *vx_mps = 0.0;
    *vy_mps = 0.0;
    return;
  }
  const auto& v = belt_velocity_mps_[static_cast<std::size_t>(surface - 1)];
  *vx_mps = v[0];
  *vy_mps = v[1];
}

int FloorWorld::Collide(int i) {
  const dGeomID geom = geoms_[static_cast<std::size_t>(i)];
  const int n = dCollide(geom, floor_, kMaxPoints, &points_[0].geom, sizeof(dContact));
  GeomContact& c = contacts_[static_cast<std::size_t>(i)];
  c.points = n;
  c.depth_m = 0.0;
  if (n == 0) {
    const dReal* p = dGeomGetPosition(geom);
    c.surface = -1;
    c.x_m = p[0];
    c.y_m = p[1];
    return 0;
  }
  double sx = 0.0, sy = 0.0;
  for (int j = 0; j < n; ++j) {
    dContactGeom& g = points_[static_cast<std::size_t>(j)].geom;
    // Make the moving geom g1 with the normal pointing into it (from the
    // floor), whatever order the collider reports, so that the surface
    // motion sign below holds.
    if (g.g1 == floor_) {
      std::swap(g.g1, g.g2);
      for (int d = 0; d < 3; ++d) g.normal[d] = -g.normal[d];
    }
    sx += g.pos[0];
    sy += g.pos[1];
    c.depth_m = std::max(c.depth_m, static_cast<double>(g.depth));
  }
  c.x_m = sx / n;
  c.y_m = sy / n;
  c.surface = SurfaceAt(points_[0].geom.pos[0], points_[0].geom.pos[1]);
  return n;
}

void FloorWorld::Probe() {
  for (int i = 0; i < static_cast<int>(geoms_.size()); ++i) Collide(i);
}

void FloorWorld::MakeJoints(int n, double erp, double cfm) {
  for (int j = 0; j < n; ++j) {
    dContact& p = points_[static_cast<std::size_t>(j)];
    double vx = 0.0, vy = 0.0;
    SurfaceVelocity(SurfaceAt(p.geom.pos[0], p.geom.pos[1]), &vx, &vy);
    // The surface velocity projected on the contact plane.
    const dReal* nrm = p.geom.normal;
    const double vn = vx * nrm[0] + vy * nrm[1];
    double t[3] = {vx - vn * nrm[0], vy - vn * nrm[1], -vn * nrm[2]};
    double speed = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    if (speed > 0.0) {
      for (double& e : t) e /= speed;
    } else {
      // No surface motion: any tangent direction will do (friction is
      // isotropic); map x projected on the plane, or y if x is the normal.
      const double ax = std::abs(nrm[0]) < 0.9 ? 1.0 : 0.0;
      const double ay = 1.0 - ax;
      const double an = ax * nrm[0] + ay * nrm[1];
      t[0] = ax - an * nrm[0];
      t[1] = ay - an * nrm[1];
      t[2] = -an * nrm[2];
      const double len = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
      for (double& e : t) e /= len;
      speed = 0.0;
    }
    p.surface.mode = dContactApprox1 | dContactSoftCFM | dContactSoftERP | dContactMotion1 |
                     dContactMotion2 | dContactFDir1;
    p.surface.mu = surface_.mu;
    p.surface.soft_erp = erp;
    p.surface.soft_cfm = cfm;
    p.surface.motion1 = speed;
    p.surface.motion2 = 0.0;
    p.surface.motionN = 0.0;
    p.surface.bounce = 0.0;
    p.surface.bounce_vel = 0.0;
    p.fdir1[0] = t[0];
    p.fdir1[1] = t[1];
    p.fdir1[2] = t[2];
    const dJointID joint = dJointCreateContact(world_, group_, &p);
    // body1 = the moving geom's body, body2 = the static floor (0).
    dJointAttach(joint, dGeomGetBody(p.geom.g1), dGeomGetBody(p.geom.g2));
  }
}

bool FloorWorld::Step(double h_s) {
  // ODE's spring-damper equivalence for one implicit step of h:
  // ERP = h kp / (h kp + kd), CFM = 1 / (h kp + kd).
  const double hk = h_s * surface_.stiffness_n_per_m;
  const double erp = hk / (hk + surface_.damping_n_s_per_m);
  const double cfm = 1.0 / (hk + surface_.damping_n_s_per_m);
  int ok = 0;
  try {
    for (int i = 0; i < static_cast<int>(geoms_.size()); ++i) MakeJoints(Collide(i), erp, cfm);
    ok = dWorldStep(world_, h_s);
  } catch (const OdeError&) {
    dJointGroupEmpty(group_);
    throw;
  }
  dJointGroupEmpty(group_);
  return ok != 0;
}

}  // namespace linesim::chassis
