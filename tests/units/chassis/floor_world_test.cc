#include "units/chassis/floor_world.h"

#include <gtest/gtest.h>
#include <ode/ode.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace linesim::chassis {
namespace {

constexpr double kStepS = 1e-3;

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
    f.AddGeom(geom);
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
// v(t) = v0 - mu g t, direction unchanged.
TEST(FloorWorld, SlidingFrictionIsCoulombInAnyDirection) {
  const double mu = 0.5, v0_mps = 1.0;
  for (const double dir_rad : {0.0, std::numbers::pi / 4.0, 2.0}) {
    SCOPED_TRACE(dir_rad);
    FloorWorld f;
    f.SetSurface({mu, 1e6, 1e4});
    Box box(f, 0.0, 0.0, 2.0, 0.2);
    dBodySetLinearVel(box.body, v0_mps * std::cos(dir_rad), v0_mps * std::sin(dir_rad), 0.0);
    for (int i = 0; i < 100; ++i) ASSERT_TRUE(f.Step(kStepS));
    const double v_mps = v0_mps - mu * kGravityMps2 * 0.1;
    EXPECT_NEAR(std::hypot(box.vx(), box.vy()), v_mps, 0.01 * v_mps);
    EXPECT_NEAR(std::atan2(box.vy(), box.vx()), dir_rad, 1e-6);
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

}  // namespace
}  // namespace linesim::chassis
