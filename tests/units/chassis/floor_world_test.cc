#include "units/chassis/floor_world.h"

#include <gtest/gtest.h>
#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <utility>
#include <vector>

namespace linesim::chassis {
namespace {

constexpr double kStepS = 1e-3;

// A block's tread (no rolling direction): a shear spring of 1e5 N/m each
// way, critically damped on the block's mass (d = 2 sqrt(k m)), so that a
// block that stops sliding settles within a few ms (1 / sqrt(k / m) = 4.5
// ms for 2 kg) instead of ringing on it.
Tread BlockTread(double mass_kg) {
  Tread t;
  const double k = 1e5, d = 2.0 * std::sqrt(k * mass_kg);
  t.stiffness_n_per_m[0] = t.stiffness_n_per_m[1] = k;
  t.damping_n_s_per_m[0] = t.damping_n_s_per_m[1] = d;
  return t;
}

// A free box resting on the floor plane, registered with the floor world.
struct Box {
  dBodyID body = nullptr;
  dGeomID geom = nullptr;

  Box(FloorWorld& f, double x_m, double y_m, double mass_kg, double side_m) {
    body = dBodyCreate(f.world());
    dMass m;
    dMassSetBoxTotal(&m, mass_kg, side_m, side_m, side_m);
    dBodySetMass(body, &m);
    // Pressed in by its static deflection (4 corner contacts), so that it
    // starts at rest.
    const double depth_m = mass_kg * kGravityMps2 / (4.0 * f.surface().stiffness_n_per_m);
    dBodySetPosition(body, x_m, y_m, 0.5 * side_m - depth_m);
    geom = dCreateBox(nullptr, side_m, side_m, side_m);
    dGeomSetBody(geom, body);
    f.AddGeom(geom, BlockTread(mass_kg));
  }
  // Declared after the world, so destroyed before it.
  ~Box() { dGeomDestroy(geom); }
  Box(const Box&) = delete;
  Box& operator=(const Box&) = delete;
  double vx() const { return dBodyGetLinearVel(body)[0]; }
  double vy() const { return dBodyGetLinearVel(body)[1]; }
  double x() const { return dBodyGetPosition(body)[0]; }
  double y() const { return dBodyGetPosition(body)[1]; }
};

// Guards against a wrong surface-motion sign or magnitude (object dragged
// against the belt, or not at all), a belt velocity applied outside its
// patch, and sliding friction that is not Coulomb's mu N. Numbers: a body
// put at rest on a belt of speed v slides with acceleration mu g until it
// reaches v, at t = v / (mu g) = 0.0204 s for 0.2 m/s and mu 1; afterwards
// it sticks.
TEST(FloorWorld, BoxOnBeltReachesBeltSpeedAfterCoulombTime) {
  const double belt_mps = 0.2, mu = 1.0;
  FloorWorld f;
  // Contacts as the chassis defaults: stiff and well damped, so the box
  // does not rock on its corners (which would lighten the friction).
  f.SetSurface({mu, 1e6, 1e4});
  f.SetBelts({{0.0, 0.0, 4.0, 1.0, 0.0, mu}});
  f.SetBeltVelocity(0, belt_mps, 0.0);
  Box on_belt(f, 0.0, 0.0, 2.0, 0.2);
  Box on_floor(f, 0.0, 1.0, 2.0, 0.2);  // 0.5 m from the belt edge

  double t99_s = -1.0;
  for (int i = 1; i <= 300; ++i) {
    ASSERT_TRUE(f.Step(kStepS));
    const double t_s = i * kStepS;
    if (i == 10) {
      // Still sliding: v = mu g t.
      EXPECT_NEAR(on_belt.vx(), mu * kGravityMps2 * t_s, 0.01 * mu * kGravityMps2 * t_s);
    }
    if (t99_s < 0.0 && on_belt.vx() >= 0.99 * belt_mps) t99_s = t_s;
  }
  const double t_coulomb_s = belt_mps / (mu * kGravityMps2);
  EXPECT_NEAR(t99_s, 0.99 * t_coulomb_s, 1.5 * kStepS);
  EXPECT_NEAR(on_belt.vx(), belt_mps, 1e-9);
  EXPECT_NEAR(on_belt.vy(), 0.0, 1e-9);
  // The box beside the belt does not move.
  EXPECT_NEAR(on_floor.vx(), 0.0, 1e-9);
  EXPECT_NEAR(on_floor.vy(), 0.0, 1e-9);
  EXPECT_NEAR(on_floor.x(), 0.0, 1e-9);
  EXPECT_NEAR(on_floor.y(), 1.0, 1e-9);

  // Contact reports: belt 0 is surface 1, the floor 0; contact point is the
  // centre of the four corners. Step collided at its end, so they describe
  // the positions after it without a Probe (which finds the same).
  EXPECT_NEAR(f.contact(0).x_m, on_belt.x(), 1e-9);
  EXPECT_NEAR(f.contact(1).y_m, on_floor.y(), 1e-9);
  f.Probe();
  EXPECT_EQ(f.contact(0).surface, 1);
  EXPECT_EQ(f.contact(0).points, 4);
  EXPECT_NEAR(f.contact(0).x_m, on_belt.x(), 1e-9);
  EXPECT_EQ(f.contact(1).surface, 0);
  double vx = -1.0, vy = -1.0;
  f.SurfaceVelocity(f.contact(1).surface, &vx, &vy);
  EXPECT_EQ(vx, 0.0);
  EXPECT_EQ(vy, 0.0);
  f.SurfaceVelocity(f.contact(0).surface, &vx, &vy);
  EXPECT_EQ(vx, belt_mps);
  EXPECT_EQ(vy, 0.0);
}

// Guards against a surface velocity that is only right along map x (fdir1
// or motion sign lost for other directions). A box on belts running in
// other directions ends at the belt velocity vector; geometry: a body
// sticking to the surface moves with it.
TEST(FloorWorld, BoxFollowsBeltInAnyDirection) {
  for (const double dir_rad : {std::numbers::pi / 2.0, 2.0, -2.5}) {
    FloorWorld f;
    f.SetSurface({0.8, 1e6, 1e4});
    f.SetBelts({{1.0, -1.0, 3.0, 2.0, dir_rad}});
    const double vx = 0.2 * std::cos(dir_rad), vy = 0.2 * std::sin(dir_rad);
    f.SetBeltVelocity(0, vx, vy);
    Box box(f, 1.0, -1.0, 2.0, 0.2);
    for (int i = 0; i < 200; ++i) ASSERT_TRUE(f.Step(kStepS));
    EXPECT_NEAR(box.vx(), vx, 1e-9) << dir_rad;
    EXPECT_NEAR(box.vy(), vy, 1e-9) << dir_rad;
  }
}

// Guards against friction that depends on the direction of sliding in map
// (ODE's dContactApprox1 pyramid would brake a diagonal slide with
// sqrt(2) mu N). Analytic, Coulomb: a box sliding on the still floor
// decelerates at mu g along its velocity, whatever that direction:
// v(t) = v0 - mu g t, direction unchanged. The first step, in which the
// tread leaves the friction circle, is bounded by the pyramid (each row mu
// N): its velocity change mu g h may turn the direction by at most
// mu g h / v0 = 4.9 mrad; from then on the saturated tread's force is along
// -slip, and the direction holds.
TEST(FloorWorld, SlidingFrictionIsCoulombInAnyDirection) {
  const double mu = 0.5, v0_mps = 1.0;
  for (const double dir_rad : {0.0, std::numbers::pi / 4.0, 2.0}) {
    SCOPED_TRACE(dir_rad);
    FloorWorld f;
    f.SetSurface({mu, 1e6, 1e4});
    Box box(f, 0.0, 0.0, 2.0, 0.2);
    dBodySetLinearVel(box.body, v0_mps * std::cos(dir_rad), v0_mps * std::sin(dir_rad), 0.0);
    ASSERT_TRUE(f.Step(kStepS));
    const double after_first = std::atan2(box.vy(), box.vx());
    EXPECT_NEAR(after_first, dir_rad, mu * kGravityMps2 * kStepS / v0_mps);
    for (int i = 1; i < 100; ++i) ASSERT_TRUE(f.Step(kStepS));
    const double v_mps = v0_mps - mu * kGravityMps2 * 0.1;
    EXPECT_NEAR(std::hypot(box.vx(), box.vy()), v_mps, 0.01 * v_mps);
    EXPECT_NEAR(std::atan2(box.vy(), box.vx()), after_first, 1e-6);
  }
}

// Guards against a wrong inside test of a rotated patch (sign of the
// across axis, half sizes) and belt indices. Geometry by hand: a 4 x 1 m
// patch centred at (2, 1), length axis at 90 deg (along map y).
TEST(FloorWorld, SurfaceAtRotatedPatches) {
  FloorWorld f;
  f.SetBelts({{2.0, 1.0, 4.0, 1.0, std::numbers::pi / 2.0}, {0.0, 0.0, 10.0, 10.0, 0.0}});
  EXPECT_EQ(f.belt_count(), 2);
  EXPECT_EQ(f.SurfaceAt(2.0, 2.9), 1);    // 1.9 m along, inside 2 m
  EXPECT_EQ(f.SurfaceAt(2.45, -0.9), 1);  // 0.45 across, inside 0.5
  EXPECT_EQ(f.SurfaceAt(2.6, 1.0), 2);    // 0.6 across: outside belt 0, inside belt 1
  EXPECT_EQ(f.SurfaceAt(2.0, 3.1), 2);
  EXPECT_EQ(f.SurfaceAt(6.0, 0.0), 0);  // outside both
}

// Guards against carried objects that ride past their belt's end: the
// travel over which a footprint lies along a belt's length, for a belt
// along map y and boxes turned on it, and a cylinder; AddCarried refuses
// one that overhangs the downstream end at zero travel (one upstream waits
// to be put on the line).
TEST(FloorWorld, CarriedTravelRangeEndsAtTheBeltsEnds) {
  // Belt along +y from y = -4 to 6 (centre (2, 1), 10 m long, 3 m wide).
  const BeltPatch belt{2.0, 1.0, 10.0, 3.0, std::numbers::pi / 2.0};
  models::Solid box;
  box.x_m = 2.0;
  box.y_m = 0.0;
  box.length_m = 4.0;
  box.width_m = 2.0;
  box.yaw_rad = std::numbers::pi / 2.0;  // along the belt: 2 m either side along it
  auto r = CarriedTravelRange(belt, box);
  EXPECT_NEAR(r[0], -2.0, 1e-12);  // its rear face reaches y = -4
  EXPECT_NEAR(r[1], 4.0, 1e-12);   // its front face reaches y = 6
  box.yaw_rad = 0.0;               // across the belt: 1 m either side along it
  r = CarriedTravelRange(belt, box);
  EXPECT_NEAR(r[0], -3.0, 1e-12);
  EXPECT_NEAR(r[1], 5.0, 1e-12);
  models::Solid drum;
  drum.kind = models::Solid::Kind::kCylinder;
  drum.x_m = 2.5;
  drum.y_m = 5.0;
  drum.radius_m = 0.5;
  r = CarriedTravelRange(belt, drum);
  EXPECT_NEAR(r[0], -8.5, 1e-12);
  EXPECT_NEAR(r[1], 0.5, 1e-12);

  FloorWorld f;
  f.SetBelts({belt});
  EXPECT_NO_THROW(f.AddCarried(drum, 0));
  drum.y_m = 5.6;  // 0.1 m past the end
  EXPECT_THROW(f.AddCarried(drum, 0), std::invalid_argument);
  drum.y_m = -5.0;  // 0.5 m before the start (y = -4): it enters after 1.5 m of travel
  EXPECT_NO_THROW(f.AddCarried(drum, 0));
  EXPECT_NEAR(CarriedTravelRange(belt, drum)[0], 1.5, 1e-12);
  EXPECT_THROW(f.AddCarried(drum, 1), std::out_of_range);
}

// Guards against a slip in the one spring-damper formula the contacts and
// the suspension share. By hand, the contact defaults at 1 ms: h k = 1000,
// ERP = 1000 / (1000 + 1e4) = 1/11, CFM = 1 / 11000; no damping gives
// ERP 1 and CFM 1 / (h k).
TEST(FloorWorld, ErpCfmOfASpringDamper) {
  const SoftParams p = ErpCfm(1e-3, 1e6, 1e4);
  EXPECT_DOUBLE_EQ(p.erp, 1.0 / 11.0);
  EXPECT_DOUBLE_EQ(p.cfm, 1.0 / 11000.0);
  const SoftParams stiff = ErpCfm(1e-3, 1e7, 0.0);
  EXPECT_EQ(stiff.erp, 1.0);
  EXPECT_DOUBLE_EQ(stiff.cfm, 1e-4);
}

// Guards against geoms that are not on the floor being reported as
// touching it.
TEST(FloorWorld, NoContactAboveTheFloor) {
  FloorWorld f;
  Box box(f, 0.3, 0.4, 1.0, 0.2);
  dBodySetPosition(box.body, 0.3, 0.4, 0.5);
  f.Probe();
  EXPECT_EQ(f.contact(0).surface, -1);
  EXPECT_EQ(f.contact(0).points, 0);
  EXPECT_EQ(f.contact(0).x_m, 0.3);
  EXPECT_EQ(f.contact(0).y_m, 0.4);
}

// A terrain piece tilted by `pitch_rad` about map y (+ raises its +x end),
// its top face's centre at (0, 0, 1), wide enough for the tests below.
models::TerrainPiece Slope(double pitch_rad) {
  models::TerrainPiece t;
  t.name = "slope";
  t.length_m = 4.0;
  t.width_m = 2.0;
  t.thickness_m = 0.2;
  t.pitch_rad = pitch_rad;
  // Centre = top centre - half the thickness along the top's normal
  // (-sin p, 0, cos p).
  t.center_x_m = 0.1 * std::sin(pitch_rad);
  t.center_z_m = 1.0 - 0.1 * std::cos(pitch_rad);
  return t;
}

// Guards against terrain contacts that are not Coulomb's (a pyramid, or a
// friction row left in map x), a wrong tilt sign, and the piece's own
// friction not being used. Analytic (Coulomb, a block on an incline): below
// the friction angle (mu > tan p) it stays; above it, it slides down the
// slope with a = g (sin p - mu cos p). The block (2 kg, 0.2 m cube) is put
// on the top face tilted with it, pressed in by its static deflection.
TEST(FloorWorld, BlockOnATiltedTerrainPieceIsCoulomb) {
  const double pitch = 20.0 * std::numbers::pi / 180.0;  // tan = 0.364
  for (const double mu : {0.5, 0.25}) {
    SCOPED_TRACE(mu);
    FloorWorld f;
    // The floor far below and slippery: only the piece's friction acts.
    f.SetSurface({0.0, 1e6, 1e4});
    f.AddTerrain(Slope(pitch), mu);
    ASSERT_EQ(f.terrain_count(), 1);
    Box box(f, 0.0, 0.0, 2.0, 0.2);
    const double n[3] = {-std::sin(pitch), 0.0, std::cos(pitch)};
    const double depth = 2.0 * kGravityMps2 * std::cos(pitch) / (4.0 * 1e6);
    dBodySetPosition(box.body, (0.1 - depth) * n[0], 0.0, 1.0 + (0.1 - depth) * n[2]);
    dMatrix3 rot;
    dRFromAxisAndAngle(rot, 0.0, 1.0, 0.0, -pitch);  // x axis up the slope
    dBodySetRotation(box.body, rot);
    f.Probe();
    EXPECT_EQ(f.contact(0).points, 4);
    EXPECT_EQ(f.contact(0).surface, 1);  // no belts: terrain piece 0 is surface 1
    EXPECT_NEAR(f.TerrainTopAt(0.5, 0.3), 1.0 + 0.5 * std::tan(pitch), 1e-12);
    EXPECT_EQ(f.TerrainTopAt(3.0, 0.0), -std::numeric_limits<double>::infinity());
    // Where it is once the contact springs settled (0.1 s: a few periods
    // of the 2 kg block on 4 x 1e6 N/m).
    double x0 = 0.0, v_half = 0.0;
    for (int i = 1; i <= 1000; ++i) {
      ASSERT_TRUE(f.Step(kStepS));
      if (i == 100) x0 = box.x();
      if (i == 500) v_half = dBodyGetLinearVel(box.body)[0];
    }
    const dReal* v = dBodyGetLinearVel(box.body);
    const double along_mps = v[0] * std::cos(pitch) + v[2] * std::sin(pitch);
    if (mu > std::tan(pitch)) {
      EXPECT_NEAR(box.x(), x0, 1e-6);
      EXPECT_NEAR(along_mps, 0.0, 1e-6);
    } else {
      // Down the slope (-x): a over the last 0.5 s from the velocity change.
      const double a = kGravityMps2 * (std::sin(pitch) - mu * std::cos(pitch));
      const double measured = -(v[0] - v_half) / std::cos(pitch) / 0.5;
      EXPECT_NEAR(measured, a, 0.01 * a);
      EXPECT_NEAR(v[1], 0.0, 1e-9);
    }
  }
}

// Guards against a wheel that sinks into a piece or jumps at its edge: a
// sphere rolled over the foot of a ramp keeps one contact point with the
// floor or the ramp (two while on the edge) and never sinks deeper than its
// static deflection allows (a few times m g / k).
TEST(FloorWorld, SphereRollsOntoARampOverItsEdge) {
  const double pitch = 15.0 * std::numbers::pi / 180.0;
  FloorWorld f;
  f.SetSurface({0.8, 1e6, 1e4});
  // The ramp's top face starts on the floor at x = 1.
  models::TerrainPiece t;
  t.name = "ramp";
  t.length_m = 2.0;
  t.width_m = 1.0;
  t.thickness_m = 0.05;
  t.pitch_rad = pitch;
  t.center_x_m = 1.0 + std::cos(pitch) + 0.025 * std::sin(pitch);
  t.center_z_m = std::sin(pitch) - 0.025 * std::cos(pitch);
  f.AddTerrain(t, 0.8);
  const double r = 0.15, m = 5.0;
  const dBodyID b = dBodyCreate(f.world());
  dMass mass;
  dMassSetSphereTotal(&mass, m, r);
  dBodySetMass(b, &mass);
  dBodySetPosition(b, 0.0, 0.0, r - m * kGravityMps2 / 1e6);
  dBodySetLinearVel(b, 2.0, 0.0, 0.0);
  dBodySetAngularVel(b, 0.0, 2.0 / r, 0.0);
  const dGeomID g = dCreateSphere(nullptr, r);
  dGeomSetBody(g, b);
  f.AddGeom(g, BlockTread(m));
  double deepest = 0.0;
  int most_points = 0;
  bool on_ramp = false;
  for (int i = 0; i < 800; ++i) {
    ASSERT_TRUE(f.Step(kStepS));
    deepest = std::max(deepest, f.contact(0).depth_m);
    most_points = std::max(most_points, f.contact(0).points);
    on_ramp = on_ramp || f.contact(0).surface == 1;
  }
  EXPECT_TRUE(on_ramp);
  EXPECT_LE(most_points, 2);
  // Static deflection 5 x 9.81 / 1e6 = 0.05 mm; the edge's impulse adds
  // a few times that.
  EXPECT_LT(deepest, 1e-3);
  // Still rolling up the ramp's face, at most its radius above it.
  const dReal* p = dBodyGetPosition(b);
  EXPECT_GT(p[0], 1.3);
  EXPECT_NEAR(p[2], (p[0] - 1.0) * std::tan(pitch) + r / std::cos(pitch), 2e-3);
  f.ClearGeoms();
  dGeomDestroy(g);
}

// A wheel (a sphere on an axle along its body's y) whose centre is held by
// a hinge to the world at the height that presses it in by load_n, free to
// spin: the ground under it moves, the tread does the rest.
struct HeldWheel {
  dBodyID body = nullptr;
  dGeomID geom = nullptr;
  dJointID hinge = nullptr;
  dJointFeedback feedback{};

  HeldWheel(FloorWorld& f, double yaw_rad, double load_n, const Tread& tread) {
    const double r = 0.1, m = 2.0;
    body = dBodyCreate(f.world());
    dMass mass;
    dMassSetSphereTotal(&mass, m, r);
    dBodySetMass(body, &mass);
    dBodySetPosition(body, 0.0, 0.0, r - load_n / f.surface().stiffness_n_per_m);
    dMatrix3 rot;
    dRFromAxisAndAngle(rot, 0.0, 0.0, 1.0, yaw_rad);
    dBodySetRotation(body, rot);
    geom = dCreateSphere(nullptr, r);
    dGeomSetBody(geom, body);
    f.AddGeom(geom, tread);
    hinge = dJointCreateHinge(f.world(), nullptr);
    dJointAttach(hinge, body, nullptr);
    const dReal* p = dBodyGetPosition(body);
    dJointSetHingeAnchor(hinge, p[0], p[1], p[2]);
    dJointSetHingeAxis(hinge, -std::sin(yaw_rad), std::cos(yaw_rad), 0.0);
    dJointSetFeedback(hinge, &feedback);
  }
  ~HeldWheel() { dGeomDestroy(geom); }
  HeldWheel(const HeldWheel&) = delete;
  HeldWheel& operator=(const HeldWheel&) = delete;
  // The force the ground puts on the wheel, from the hinge that holds it
  // (the hinge's force on the wheel is minus that, plus the weight).
  double Along(double yaw_rad) const {
    return -(feedback.f1[0] * std::cos(yaw_rad) + feedback.f1[1] * std::sin(yaw_rad));
  }
  double Across(double yaw_rad) const {
    return -(-feedback.f1[0] * std::sin(yaw_rad) + feedback.f1[1] * std::cos(yaw_rad));
  }
};

// A rolling tread with cornering stiffness C and relaxation length sigma.
Tread RollingTread(double c_n_per_rad, double sigma_m) {
  Tread t;
  for (int r = 0; r < 2; ++r) {
    t.stiffness_n_per_m[r] = c_n_per_rad / sigma_m;
    t.relaxation_m[r] = sigma_m;
  }
  t.axle[1] = 1.0;
  return t;
}

// Guards the transient brush tyre's creep and relaxation (Pacejka, ch. 7):
// a wheel held at slip angle alpha over a belt running at v builds its
// lateral force as F(t) = C alpha (1 - exp(-v t / sigma)) (the first-order
// relaxation; the deflection starts at 0), to the creep force C alpha far
// below mu N. Numbers: C = 1000 N/rad, sigma = 0.05 m, alpha = 0.02 rad,
// v = 0.2 m/s: C alpha = 20 N (mu N = 240 N), time constant 0.25 s. The
// implicit step's relaxation is exp's first-order rational approximant:
// at h = 1 ms, v h / sigma = 0.004, off by 0.2 % per time constant.
TEST(FloorWorld, TreadCreepBuildsOverTheRelaxationLength) {
  const double c = 1000.0, sigma = 0.05, alpha = 0.02, v = 0.2, load = 300.0;
  FloorWorld f;
  f.SetSurface({0.8, 1e6, 1e4});
  f.SetBelts({{0.0, 0.0, 10.0, 10.0, 0.0, 0.8}});
  // The wheel heads along -x turned by alpha: the belt (+x) runs under it
  // backwards at v, with a lateral slip v sin(alpha).
  const double yaw = std::numbers::pi + alpha;
  HeldWheel wheel(f, yaw, load, RollingTread(c, sigma));
  for (int i = 0; i < 300; ++i) ASSERT_TRUE(f.Step(kStepS));  // settle on the still belt
  f.ResetTreads();
  f.SetBeltVelocity(0, v, 0.0);
  const double tau = sigma / v;
  const double steady = c * std::sin(alpha) * v / std::abs(v * std::cos(alpha));
  double at_tau = 0.0;
  for (int i = 1; i <= 2000; ++i) {
    ASSERT_TRUE(f.Step(kStepS));
    if (i == static_cast<int>(std::lround(tau / kStepS))) at_tau = std::abs(wheel.Across(yaw));
  }
  // The wheel spins up within a few ms (its inertia on the longitudinal
  // creep), so the relaxation starts at once.
  EXPECT_NEAR(at_tau, steady * (1.0 - std::exp(-1.0)), 0.02 * steady);
  EXPECT_NEAR(std::abs(wheel.Across(yaw)), steady, 0.01 * steady);
  // Free to spin: no longitudinal force once it rolls with the belt.
  EXPECT_NEAR(wheel.Along(yaw), 0.0, 0.01 * steady);
  f.ClearGeoms();
}

// Guards against a contact that creates energy (a passive system's energy
// never rises): a block put on a running belt slides, then sticks on its
// tread; in the belt's frame (the only frame in which the belt does no
// work) kinetic + potential + tread energy may only fall. Checked every
// step, with a tolerance of 1e-6 J for the normal springs' rounding.
TEST(FloorWorld, ContactsNeverCreateEnergyInTheBeltsFrame) {
  const double v = 0.3, m = 2.0;
  for (const bool sideways : {false, true}) {
    SCOPED_TRACE(sideways);
    FloorWorld f;
    f.SetSurface({0.8, 1e6, 1e4});
    f.SetBelts({{0.0, 0.0, 10.0, 10.0, 0.0, 0.8}});
    Box box(f, 0.0, 0.0, m, 0.2);
    for (int i = 0; i < 200; ++i) ASSERT_TRUE(f.Step(kStepS));
    f.ResetTreads();
    f.SetBeltVelocity(0, v, 0.0);
    if (sideways) {
      // A slow sideways push too, so that both rows work.
      dBodySetLinearVel(box.body, 0.0, 0.05, 0.0);
    }
    const auto energy = [&] {
      const dReal* lv = dBodyGetLinearVel(box.body);
      const dReal* av = dBodyGetAngularVel(box.body);
      dMass mass;
      dBodyGetMass(box.body, &mass);
      double rot = 0.0;  // w . I w in the body's frame: the cube's I is isotropic
      for (int d = 0; d < 3; ++d) rot += mass.I[5 * d] * av[d] * av[d];
      const double dv[3] = {lv[0] - v, lv[1], lv[2]};
      return 0.5 * m * (dv[0] * dv[0] + dv[1] * dv[1] + dv[2] * dv[2]) + 0.5 * rot +
             m * kGravityMps2 * dBodyGetPosition(box.body)[2] + f.TreadEnergy();
    };
    double before = energy(), rise = 0.0;
    for (int i = 0; i < 500; ++i) {
      ASSERT_TRUE(f.Step(kStepS));
      const double now = energy();
      rise = std::max(rise, now - before);
      before = now;
    }
    EXPECT_LT(rise, 1e-6);
    EXPECT_NEAR(box.vx(), v, 1e-6);  // stuck on the belt at the end
  }
}

// Guards against a wheel whose surface velocity jumps where its patch
// crosses a belt edge, and against a gap that carries friction: rolled
// across the edge, the patch's surface velocity is the belt's share of its
// area (a linear ramp over the patch length for an edge across the rolling
// direction), and over the edge gap the supported share drops by the gap's
// width over the patch length.
TEST(FloorWorld, PatchCrossesABeltEdgeContinuously) {
  const double length = 0.05, width = 0.04, gap = 0.01;
  FloorWorld f;
  f.SetSurface({0.8, 1e6, 1e4});
  // The belt covers x > 0 (its edge at x = 0, across map y).
  f.SetBelts({{5.0, 0.0, 10.0, 10.0, 0.0, 0.8, gap}});
  f.SetBeltVelocity(0, 0.0, 0.4);
  Tread tread = RollingTread(1000.0, 0.05);
  tread.patch_length_m = length;
  tread.patch_width_m = width;
  const dBodyID b = dBodyCreate(f.world());
  dMass mass;
  dMassSetSphereTotal(&mass, 2.0, 0.1);
  dBodySetMass(b, &mass);
  const dGeomID g = dCreateSphere(nullptr, 0.1);
  dGeomSetBody(g, b);
  f.AddGeom(g, tread);
  for (const double x : {-0.06, -0.04, -0.02, -0.015, 0.0, 0.01, 0.02, 0.03, 0.05}) {
    SCOPED_TRACE(x);
    dBodySetPosition(b, x, 0.0, 0.0999);
    f.Probe();
    // Area shares along x of the patch [x - 0.025, x + 0.025]: belt x > 0,
    // gap -0.01 < x < 0, floor x < -0.01.
    const auto overlap = [&](double lo, double hi) {
      return std::clamp(std::min(hi, x + 0.5 * length) - std::max(lo, x - 0.5 * length), 0.0,
                        length) /
             length;
    };
    const double belt = overlap(0.0, 1.0), in_gap = overlap(-gap, 0.0);
    const double support = 1.0 - in_gap;
    double vx = 0.0, vy = 0.0;
    f.PatchVelocity(0, &vx, &vy);
    EXPECT_NEAR(f.contact(0).support_share, support, 1e-12);
    EXPECT_NEAR(vy, 0.4 * belt / support, 1e-12);
    EXPECT_EQ(vx, 0.0);
  }
  f.ClearGeoms();
  dGeomDestroy(g);
}

// A sphere (a wheel without axle: the block tread) of radius r, mass m at
// (x, y, z), registered with the floor world; returns its body.
dBodyID RestingSphere(FloorWorld& f, double x, double y, double z, double r, double m,
                      dGeomID* geom) {
  const dBodyID b = dBodyCreate(f.world());
  dMass mass;
  dMassSetSphereTotal(&mass, m, r);
  dBodySetMass(b, &mass);
  dBodySetPosition(b, x, y, z);
  *geom = dCreateSphere(nullptr, r);
  dGeomSetBody(*geom, b);
  f.AddGeom(*geom, BlockTread(m));
  return b;
}

// Guards the floor's height profile (the class comment's "Uneven
// surfaces"): a sphere set down anywhere on an ISO 8608 class C floor comes
// to rest with its centre r + h(x, y) above the nominal floor, less its
// static deflection m g / k (exact to the slope's square: r |grad h|^2 / 2,
// under 0.1 mm here), and the contact normal is the surface's, (-grad h,
// 1) normalised. A belt stays level: the same sphere on it rests at r.
TEST(FloorWorld, SphereRestsOnTheFloorsProfile) {
  models::Unevenness c;
  c.psd_n0_m3 = models::Iso8608ClassPsd('C');
  c.seed = 3;
  const models::SurfaceProfile profile(c);
  FloorWorld f;
  f.SetSurface({0.8, 1e6, 1e4});
  f.SetBelts({{5.0, 0.0, 2.0, 1.0, 0.0, 0.8}});
  f.SetFloorProfile(profile);
  const double r = 0.1, m = 2.0, sink = m * kGravityMps2 / 1e6;
  const std::pair<double, double> spots[] = {{0.0, 0.0}, {1.3, -0.7}, {-2.1, 3.4}};
  std::vector<dGeomID> geoms;
  std::vector<dBodyID> bodies;
  for (const auto& [x, y] : spots) {
    const double h = profile.Height(x, y, nullptr, nullptr);
    geoms.emplace_back();
    bodies.push_back(RestingSphere(f, x, y, r + h + 0.001, r, m, &geoms.back()));
  }
  geoms.emplace_back();
  bodies.push_back(RestingSphere(f, 5.0, 0.0, r + 0.001, r, m, &geoms.back()));
  for (int i = 0; i < 500; ++i) ASSERT_TRUE(f.Step(kStepS));
  for (std::size_t k = 0; k < 3; ++k) {
    SCOPED_TRACE(k);
    const dReal* p = dBodyGetPosition(bodies[k]);
    double du = 0.0, dv = 0.0;
    const double h = profile.Height(p[0], p[1], &du, &dv);
    EXPECT_NEAR(p[2], r + h - sink, 1e-4);
    EXPECT_EQ(f.contact(static_cast<int>(k)).surface, 0);
  }
  EXPECT_NEAR(dBodyGetPosition(bodies[3])[2], r - sink, 1e-6);
  EXPECT_EQ(f.contact(3).surface, 1);
  f.ClearGeoms();
  for (dGeomID g : geoms) dGeomDestroy(g);
}

// Guards a terrain piece's profile: on a slope tilted 10 deg carrying the
// same class C profile in its own axes, a sphere at rest stands r + h(u, v)
// above the nominal top face along its normal (u, v along and across the
// piece from its top's centre), and far above the nominal face (more than
// the profile's bound) nothing touches.
TEST(FloorWorld, SphereRestsOnATerrainPiecesProfile) {
  models::Unevenness c;
  c.psd_n0_m3 = models::Iso8608ClassPsd('C');
  c.seed = 5;
  const models::SurfaceProfile profile(c);
  const double pitch = 10.0 * std::numbers::pi / 180.0;
  FloorWorld f;
  f.SetSurface({0.9, 1e6, 1e4});
  f.AddTerrain(Slope(pitch), 0.9, profile);
  const double r = 0.1, m = 2.0, sink = m * kGravityMps2 / 1e6;
  // The top face's normal (-sin p, 0, cos p), its centre (0, 0, 1).
  const double n[3] = {-std::sin(pitch), 0.0, std::cos(pitch)};
  const double along[3] = {std::cos(pitch), 0.0, std::sin(pitch)};
  const double u0 = 0.4;
  const double h0 = profile.Height(u0, 0.0, nullptr, nullptr);
  dGeomID g = nullptr;
  const dBodyID b = RestingSphere(f, u0 * along[0] + (r + h0) * n[0], 0.0,
                                  1.0 + u0 * along[2] + (r + h0) * n[2], r, m, &g);
  for (int i = 0; i < 300; ++i) ASSERT_TRUE(f.Step(kStepS));
  const dReal* p = dBodyGetPosition(b);
  const double d[3] = {p[0], p[1], p[2] - 1.0};
  const double u = d[0] * along[0] + d[2] * along[2];
  const double v = d[1];
  const double height = d[0] * n[0] + d[2] * n[2];
  EXPECT_NEAR(height, r + profile.Height(u, v, nullptr, nullptr) - sink, 1e-4);
  EXPECT_EQ(f.contact(0).surface, 1);
  // Lifted by more than the bound above the nominal face: no contact.
  dBodySetPosition(b, u0 * along[0] + (r + profile.bound_m() + 0.002) * n[0], 0.0,
                   1.0 + u0 * along[2] + (r + profile.bound_m() + 0.002) * n[2]);
  f.Probe();
  EXPECT_EQ(f.contact(0).points, 0);
  f.ClearGeoms();
  dGeomDestroy(g);
}

}  // namespace
}  // namespace linesim::chassis
