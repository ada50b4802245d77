#include "units/evaluation/clearance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "models/scene.h"

// Every expected distance here is analytic: the Euclidean distance between
// two boxes (or a box and a cylinder) worked out from their sizes and poses
// in the comment beside it. FCL's GJK runs to a distance tolerance of 1e-6 m,
// so the checks allow 1e-5 m.
namespace linesim::evaluation {
namespace {

constexpr double kTol = 1e-5;
constexpr double kPi = std::numbers::pi;

// The body used throughout: 1.0 x 0.6 x 0.5 m, bottom 0.1 m above base_link:
// at the origin, unrotated, it spans x -0.5..0.5, y -0.3..0.3, z 0.1..0.6.
constexpr double kL = 1.0, kW = 0.6, kH = 0.5, kBottom = 0.1;

using models::BoxSolid;
using models::CylinderSolid;

models::Scene SceneWith(const std::vector<models::Solid>& obstacles) {
  models::Scene scene = models::OpenFloor();
  for (std::size_t i = 0; i < obstacles.size(); ++i) {
    scene.obstacles.push_back({"o" + std::to_string(i), "cart", obstacles[i]});
  }
  return scene;
}

// A 20 x 2 m belt along x centred on the origin carrying a 4.6 x 1.8 x 1.2 m
// car body on 0.3 m skids at x = -7 (the factory_line scene's second body, body_2).
models::Scene LineScene() {
  models::Scene scene = models::OpenFloor();
  models::Belt belt;
  belt.name = "line";
  belt.area = {0.0, 0.0, 20.0, 2.0, 0.0};
  belt.nominal_speed_mps = 0.1;
  scene.belts.push_back(belt);
  scene.carried.push_back({"body_1", 0, BoxSolid(-7.0, 0.0, 0.0, 4.6, 1.8, 1.2, 0.3)});
  return scene;
}

struct Rig {
  explicit Rig(const models::Scene& scene, const std::string& query = "pruned")
      : unit("clearance", scene) {
    auto& v = unit.variables();
    v.SetReal(*v.Find("body_length"), kL);
    v.SetReal(*v.Find("body_width"), kW);
    v.SetReal(*v.Find("body_height"), kH);
    v.SetReal(*v.Find("body_bottom"), kBottom);
    v.SetString(*v.Find("query"), query);
  }
  // Pose: base_link at (x, y, z), yaw about z, then roll about x (q = qz qx).
  void Pose(double x, double y, double yaw = 0.0, double roll = 0.0, double z = 0.0) {
    auto& v = unit.variables();
    v.SetRealArray(*v.Find("position_3d"), std::vector<double>{x, y, z});
    const double cz = std::cos(yaw / 2), sz = std::sin(yaw / 2);
    const double cx = std::cos(roll / 2), sx = std::sin(roll / 2);
    v.SetRealArray(*v.Find("orientation"), std::vector<double>{cz * cx, cz * sx, sz * sx, sz * cx});
  }
  void Travel(double s) {
    auto& v = unit.variables();
    v.SetRealArray(*v.Find("belt_travel"), std::vector<double>{s});
  }
  // One communication point as the master makes it: inputs, outputs, step.
  void Step() {
    unit.UpdateOutputs();
    ASSERT_EQ(unit.DoStep(t, 10'000'000), cosim::StepResult::kOk) << unit.last_error();
    t += 10'000'000;
  }
  double Real(const char* name) { return unit.variables().GetReal(*unit.variables().Find(name)); }
  std::int64_t Int(const char* name) {
    return unit.variables().GetInteger(*unit.variables().Find(name));
  }
  double Clearance() { return Real("clearance"); }

  ClearanceUnit unit;
  cosim::TimeNs t = 0;
};

// Distance of the body (at the origin unless said) from one obstacle.
double DistanceTo(const models::Solid& obstacle, double x = 0.0, double y = 0.0, double yaw = 0.0,
                  double roll = 0.0, const std::string& query = "pruned") {
  Rig r(SceneWith({obstacle}), query);
  r.Pose(x, y, yaw, roll);
  r.unit.Initialize();
  EXPECT_EQ(r.Int("nearest"), 0);
  EXPECT_EQ(r.Real("in_contact"), 0.0);
  return r.Clearance();
}

// Guards the box-box distance, face to face: a box spanning x 1.5..2.5 faces
// the body's front face (x 0.5) across 1.0 m; both stand in z 0..1 and
// 0.1..0.6, y overlapping.
TEST(Clearance, AxisAlignedBoxesFaceToFace) {
  EXPECT_NEAR(DistanceTo(BoxSolid(2.0, 0.0, 0.0, 1.0, 2.0, 1.0)), 1.0, kTol);
  EXPECT_NEAR(DistanceTo(BoxSolid(2.0, 0.0, 0.0, 1.0, 2.0, 1.0), 0, 0, 0, 0, "full"), 1.0, kTol);
}

// Guards the vertical extent (bottom_m, body_bottom, body_height): a box
// hanging from 1.0 m over the body (top 0.1 + 0.5 = 0.6 m) is 0.4 m away.
TEST(Clearance, BoxAboveTheBody) {
  EXPECT_NEAR(DistanceTo(BoxSolid(0.0, 0.0, 0.0, 3.0, 3.0, 1.0, 1.0)), 0.4, kTol);
}

// Guards the edge and corner cases: a 1 x 1 box at (2, 2) has its corner
// (1.5, 1.5) nearest to the body's corner (0.5, 0.3): vertical edges facing,
// hypot(1.0, 1.2); lifted to start at 1.0 m (0.4 above the body's top), the
// corner-to-corner distance in 3D, sqrt(1.0^2 + 1.2^2 + 0.4^2).
TEST(Clearance, AxisAlignedEdgeAndCorner) {
  EXPECT_NEAR(DistanceTo(BoxSolid(2.0, 2.0, 0.0, 1.0, 1.0, 1.0)), std::hypot(1.0, 1.2), kTol);
  EXPECT_NEAR(DistanceTo(BoxSolid(2.0, 2.0, 0.0, 1.0, 1.0, 1.0, 1.0)),
              std::sqrt(1.0 * 1.0 + 1.2 * 1.2 + 0.4 * 0.4), kTol);
}

// Guards the yaw of the obstacle and of the body (orientation input):
// - a 1 x 1 box at (2, 0) turned 45 deg points its corner at x = 2 - sqrt(2)/2
//   to the body's front face at x = 0.5;
// - the body turned 45 deg reaches x = (0.5 + 0.3) cos 45 with its corner,
//   facing a wall face at x = 1.5;
// - both turned 45 deg: in the body's frame the box sits at (sqrt 2, -sqrt 2),
//   unrotated, so the gaps are sqrt 2 - 1.0 along x and sqrt 2 - 0.8 along y.
TEST(Clearance, RotatedBoxes) {
  const double s2 = std::sqrt(2.0);
  EXPECT_NEAR(DistanceTo(BoxSolid(2.0, 0.0, kPi / 4, 1.0, 1.0, 1.0)), 2.0 - s2 / 2 - 0.5, kTol);
  EXPECT_NEAR(DistanceTo(BoxSolid(2.0, 0.0, 0.0, 1.0, 10.0, 1.0), 0, 0, kPi / 4),
              1.5 - 0.8 * std::cos(kPi / 4), kTol);
  EXPECT_NEAR(DistanceTo(BoxSolid(2.0, 0.0, kPi / 4, 1.0, 1.0, 1.0), 0, 0, kPi / 4),
              std::hypot(s2 - 1.0, s2 - 0.8), kTol);
}

// Guards the full 3D orientation (roll): rolled by -0.1 rad about x, the
// body's top edge (y 0.3, z 0.6) swings to y = 0.3 cos 0.1 + 0.6 sin 0.1,
// toward a tall wall face at y = 1.0.
TEST(Clearance, RolledBody) {
  EXPECT_NEAR(DistanceTo(BoxSolid(0.0, 1.5, 0.0, 10.0, 1.0, 3.0), 0, 0, 0, -0.1),
              1.0 - (0.3 * std::cos(0.1) + 0.6 * std::sin(0.1)), kTol);
}

// Guards the cylinder: a pillar of radius 0.25 at (2, 0) faces the front
// face across 2 - 0.25 - 0.5; at (2, 2) the body's nearest point to its
// axis is the corner (0.5, 0.3).
TEST(Clearance, Cylinder) {
  EXPECT_NEAR(DistanceTo(CylinderSolid(2.0, 0.0, 0.25, 4.0)), 1.25, kTol);
  EXPECT_NEAR(DistanceTo(CylinderSolid(2.0, 2.0, 0.25, 4.0)), std::hypot(1.5, 1.7) - 0.25, kTol);
}

// Guards the nearest index and the minimum over several objects.
TEST(Clearance, NearestOfSeveral) {
  Rig r(SceneWith({BoxSolid(3.0, 0.0, 0.0, 1.0, 1.0, 1.0), CylinderSolid(0.0, -2.0, 0.25, 4.0),
                   BoxSolid(-4.0, 0.0, 0.0, 1.0, 1.0, 1.0)}));
  r.Pose(0.0, 0.0);
  r.unit.Initialize();
  EXPECT_EQ(r.Int("nearest"), 1);  // 2 - 0.25 - 0.3 = 1.45 < 2.0 < 3.0
  EXPECT_NEAR(r.Clearance(), 1.45, kTol);
  // At y = 1 (body y 0.7..1.3): the cylinder 2.7 - 0.25 = 2.45 away, the
  // boxes (y -0.5..0.5) corner to corner hypot(2.0, 0.2) and hypot(3.0, 0.2).
  r.Pose(0.0, 1.0);
  r.Step();
  EXPECT_EQ(r.Int("nearest"), 0);
  EXPECT_NEAR(r.Clearance(), std::hypot(2.0, 0.2), kTol);
}

// Guards the carried object: the car body's front is at -4.7 + s for belt
// travel s, the body's rear at -0.5, so the clearance is 4.2 - s, and the
// robot is hit at s > 4.2.
TEST(Clearance, CarBodyApproachesWithBeltTravel) {
  Rig r(LineScene());
  r.Pose(0.0, 0.0);
  r.Travel(0.0);
  r.unit.Initialize();
  EXPECT_EQ(r.Int("nearest"), 0);
  for (double s : {0.0, 1.0, 2.5, 4.0, 4.19}) {
    r.Travel(s);
    r.Step();
    EXPECT_NEAR(r.Clearance(), 4.2 - s, kTol) << "travel " << s;
    EXPECT_EQ(r.Real("in_contact"), 0.0);
  }
  r.Travel(4.3);
  r.Step();
  EXPECT_EQ(r.Clearance(), 0.0);
  EXPECT_EQ(r.Real("in_contact"), 1.0);
  EXPECT_EQ(r.Int("collisions"), 1);
}

// Guards the reuse of a distance when nothing moved (pruned query): a robot
// standing at (0, 1.5) (body y 1.2..1.8) 0.7 m from a box spanning y
// 2.5..3.5, while the car body (y -0.9..0.9, front at -4.7 + s) comes
// along: hypot(4.2 - s, 0.3) away (front to the body's rear corner), the
// nearest once that is below 0.7. While it is far the standing robot needs
// no narrow-phase call; the values stay exact.
TEST(Clearance, StandingRobotReusesDistances) {
  models::Scene scene = LineScene();
  scene.obstacles.push_back({"box", "cart", BoxSolid(0.0, 3.0, 0.0, 1.0, 1.0, 1.0)});
  Rig r(scene);
  r.Pose(0.0, 1.5);
  r.Travel(0.0);
  r.unit.Initialize();
  r.Step();
  for (double s : {1.0, 2.0, 3.0}) {
    r.Travel(s);
    r.Step();
    EXPECT_NEAR(r.Clearance(), 0.7, kTol);
    EXPECT_EQ(r.Int("nearest"), 0);
    EXPECT_EQ(r.unit.last_narrow_phase_calls(), 0) << s;
  }
  r.Travel(3.9);
  r.Step();
  EXPECT_NEAR(r.Clearance(), std::hypot(0.3, 0.3), kTol);
  EXPECT_EQ(r.Int("nearest"), 1);
  r.Travel(4.0);  // the car body moved, the robot did not
  r.Step();
  EXPECT_NEAR(r.Clearance(), std::hypot(0.2, 0.3), kTol);
  r.Pose(0.0, 1.6);  // moved away from the line by 0.1
  r.Step();
  EXPECT_NEAR(r.Clearance(), std::hypot(0.2, 0.4), kTol);
  EXPECT_GT(r.unit.last_narrow_phase_calls(), 0);
}

// Guards the lift-off (models::CarriedTravelRange): the body leaves the
// 20 m belt when its front reaches x = 10, at s = 10 - 2.3 + 7 = 14.7. A
// robot with its rear at x = 10.5 sees it 10.5 - (-4.7 + s) away until
// then, and nothing (max_clearance, nearest -1) after.
TEST(Clearance, CarBodyLiftedOffAtTheBeltEnd) {
  Rig r(LineScene());
  r.Pose(11.0, 0.0);
  r.Travel(14.6);
  r.unit.Initialize();
  EXPECT_NEAR(r.Clearance(), 0.6, kTol);
  r.Travel(14.7);
  r.Step();
  EXPECT_NEAR(r.Clearance(), 0.5, kTol);
  EXPECT_EQ(r.Int("nearest"), 0);
  r.Travel(14.71);
  r.Step();
  EXPECT_EQ(r.Clearance(), 100.0);  // the default max_clearance
  EXPECT_EQ(r.Int("nearest"), -1);
  EXPECT_NEAR(r.Real("min_clearance"), 0.5, kTol);
  // Gone, it cannot be hit: the robot where the body would be.
  r.Pose(11.0 + 0.1, 0.0);
  r.Travel(16.0);
  r.Step();
  EXPECT_EQ(r.Real("in_contact"), 0.0);
  EXPECT_EQ(r.Int("collisions"), 0);
}

// Guards the collision rule: a contact event counts once, at its start.
// Box x 1.0..2.0; the body's front at x + 0.5: separated at x = 0, inside
// at 0.6 and 0.8, out at 0.3, inside again at 0.7: two collisions.
TEST(Clearance, CollisionsCountContactEvents) {
  for (const char* query : {"pruned", "full"}) {
    Rig r(SceneWith({BoxSolid(1.5, 0.0, 0.0, 1.0, 1.0, 1.0)}), query);
    r.Pose(0.0, 0.0);
    r.unit.Initialize();
    const std::vector<std::pair<double, std::int64_t>> path = {
        {0.0, 0}, {0.6, 1}, {0.8, 1}, {0.3, 1}, {0.7, 2}, {0.7, 2}};
    for (const auto& [x, count] : path) {
      r.Pose(x, 0.0);
      r.Step();
      EXPECT_EQ(r.Int("collisions"), count) << query << " x " << x;
      EXPECT_EQ(r.Real("in_contact"), x + 0.5 >= 1.0 ? 1.0 : 0.0) << query << " x " << x;
      if (x + 0.5 >= 1.0) {
        EXPECT_EQ(r.Clearance(), 0.0);
        EXPECT_EQ(r.Int("nearest"), 0);
      }
    }
  }
}

// Guards the per-object rule: touching two objects at once is two
// collisions; starting in contact is one (nothing touched before the start).
TEST(Clearance, TwoObjectsAtOnceAndContactAtTheStart) {
  // Boxes x 0.4..1.4 and -1.4..-0.4: the body (x -0.5..0.5) overlaps both.
  Rig r(SceneWith({BoxSolid(0.9, 0.0, 0.0, 1.0, 1.0, 1.0), BoxSolid(-0.9, 0.0, 0.0, 1.0, 1.0, 1.0)}));
  r.Pose(0.0, 0.0);
  r.unit.Initialize();
  EXPECT_EQ(r.Int("collisions"), 2);
  r.Step();
  EXPECT_EQ(r.Int("collisions"), 2);
  r.Pose(0.2, 0.0);  // the front one only: x -0.3..0.7
  r.Step();
  EXPECT_EQ(r.Int("collisions"), 2);
  r.Pose(0.0, 0.0);  // the rear one again
  r.Step();
  EXPECT_EQ(r.Int("collisions"), 3);
}

// Guards the metrics' outputs: the running minimum over the points passed,
// and that UpdateOutputs alone (no step) does not commit a point.
TEST(Clearance, MinimumOverTheRun) {
  Rig r(SceneWith({CylinderSolid(3.0, 0.0, 0.5, 2.0)}));  // face at x = 2.5
  r.Pose(0.0, 0.0);
  r.unit.Initialize();
  EXPECT_NEAR(r.Real("min_clearance"), 2.0, kTol);
  for (double x : {0.5, 1.2, 0.9}) {
    r.Pose(x, 0.0);
    r.Step();
  }
  EXPECT_NEAR(r.Clearance(), 1.1, kTol);
  EXPECT_NEAR(r.Real("min_clearance"), 0.8, kTol);  // at x = 1.2
  r.Pose(1.9, 0.0);  // 0.1 away, looked at but not stepped
  r.unit.UpdateOutputs();
  EXPECT_NEAR(r.Real("min_clearance"), 0.1, kTol);
  r.Pose(0.0, 0.0);
  r.Step();
  EXPECT_NEAR(r.Real("min_clearance"), 0.8, kTol);
}

// A run through a factory-line-like scene: walls, pillars, a cart, the car
// body moving; the robot crossing the line and touching the body.
models::Scene RunScene() {
  models::Scene scene = LineScene();
  scene.obstacles.push_back({"wall", "wall", BoxSolid(0.0, 5.0, 0.0, 30.0, 0.2, 4.0)});
  scene.obstacles.push_back({"pillar", "pillar", CylinderSolid(-3.0, 3.0, 0.25, 4.0)});
  scene.obstacles.push_back({"cart", "cart", BoxSolid(3.0, -3.0, 0.3, 1.2, 0.8, 1.0)});
  return scene;
}

std::vector<double> Drive(Rig& r, int from, int to) {
  std::vector<double> out;
  for (int k = from; k < to; ++k) {
    const double a = 0.01 * k;
    r.Pose(-2.0 + 2.5 * std::sin(a), 3.5 * std::sin(0.7 * a), 0.9 * a);
    r.Travel(0.05 * a * 10.0);
    r.Step();
    out.push_back(r.Clearance());
    out.push_back(static_cast<double>(r.Int("nearest")));
    out.push_back(r.Real("in_contact"));
    out.push_back(r.Real("min_clearance"));
    out.push_back(static_cast<double>(r.Int("collisions")));
  }
  return out;
}

// Guards determinism and the pruning: two units give the same bytes; the
// pruned query agrees with the full one; a unit restored from a saved state
// continues exactly as the original.
TEST(Clearance, DeterministicPrunedEqualsFullAndRestores) {
  Rig a(RunScene()), b(RunScene()), full(RunScene(), "full");
  for (Rig* r : {&a, &b, &full}) {
    r->Pose(-2.0, 0.0);
    r->Travel(0.0);
    r->unit.Initialize();
  }
  const auto ra = Drive(a, 0, 600);
  EXPECT_EQ(ra, Drive(b, 0, 600));
  const auto rf = Drive(full, 0, 600);
  ASSERT_EQ(ra.size(), rf.size());
  // (GJK's tolerance: 1e-6 m.)
  for (std::size_t i = 0; i < ra.size(); ++i) EXPECT_NEAR(ra[i], rf[i], 1e-6) << i;
  // The run touched something (the trajectory crosses the car body).
  EXPECT_GT(ra.back(), 0.0);

  const cosim::UnitState saved = a.unit.SaveState();
  const auto cont = Drive(a, 600, 900);
  Rig c(RunScene());
  c.Pose(0.0, 0.0);
  c.Travel(0.0);
  c.unit.Initialize();
  c.unit.RestoreState(saved);
  c.t = a.t - cosim::TimeNs{300} * 10'000'000;
  EXPECT_EQ(Drive(c, 600, 900), cont);
}

// Guards the pruned query's bounds against large moves between steps: poses
// jumping anywhere in the scene (seeded std::mt19937_64), tilted and turned,
// the belt jumping, give the same distances, nearest objects, contacts and
// counts as the full query.
TEST(Clearance, PrunedEqualsFullForJumpingPoses) {
  Rig pruned(RunScene()), full(RunScene(), "full");
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> x(-6.0, 6.0), y(-1.5, 5.5), a(-kPi, kPi),
      tilt(-0.05, 0.05), s(0.0, 8.0);
  for (int k = 0; k < 400; ++k) {
    const double px = x(rng), py = y(rng), yaw = a(rng), roll = tilt(rng), travel = s(rng);
    for (Rig* r : {&pruned, &full}) {
      r->Pose(px, py, yaw, roll);
      r->Travel(travel);
      if (k == 0) r->unit.Initialize();
      r->Step();
    }
    ASSERT_NEAR(pruned.Clearance(), full.Clearance(), 1e-6) << k;
    ASSERT_EQ(pruned.Int("nearest"), full.Int("nearest")) << k;
    ASSERT_EQ(pruned.Real("in_contact"), full.Real("in_contact")) << k;
    ASSERT_EQ(pruned.Int("collisions"), full.Int("collisions")) << k;
  }
  EXPECT_GT(full.Int("collisions"), 0);
}

// Guards the required body parameters: a unit without the body's size
// refuses to start, naming each missing one; a non-finite body_bottom is
// refused too (a negative one is allowed: the box is placed relative to
// base_link, whatever a robot description makes of it).
TEST(Clearance, MissingBodySizeIsRefused) {
  ClearanceUnit u("clearance", SceneWith({}));
  auto problems = u.CheckParameters();
  std::vector<std::string> names;
  for (const auto& p : problems) names.push_back(p.variable);
  EXPECT_EQ(names,
            (std::vector<std::string>{"body_length", "body_width", "body_height", "body_bottom"}));
  EXPECT_THROW(u.Initialize(), cosim::UnitError);

  Rig r(SceneWith({}));
  r.unit.variables().SetReal(*r.unit.variables().Find("body_bottom"), INFINITY);
  problems = r.unit.CheckParameters();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_EQ(problems[0].variable, "body_bottom");
  r.unit.variables().SetReal(*r.unit.variables().Find("body_bottom"), -0.07);
  EXPECT_TRUE(r.unit.CheckParameters().empty());
}

// Guards the inputs: belt_travel only with belts; a zero quaternion fails
// the step with a message.
TEST(Clearance, InputsAndBadOrientation) {
  Rig open(SceneWith({}));
  EXPECT_FALSE(open.unit.variables().Find("belt_travel").has_value());
  Rig line(LineScene());
  EXPECT_TRUE(line.unit.variables().Find("belt_travel").has_value());
  open.unit.Initialize();
  EXPECT_EQ(open.Clearance(), 100.0);  // nothing in the scene
  EXPECT_EQ(open.Int("nearest"), -1);
  auto& v = open.unit.variables();
  v.SetRealArray(*v.Find("orientation"), std::vector<double>{0, 0, 0, 0});
  EXPECT_EQ(open.unit.DoStep(0, 10'000'000), cosim::StepResult::kError);
  EXPECT_NE(open.unit.last_error().find("orientation"), std::string::npos);
}

}  // namespace
}  // namespace linesim::evaluation
