// Robot-person distance and contacts against the closed form of a circle
// and a rectangle.
#include "units/people/person_clearance_unit.h"

#include <gtest/gtest.h>

#include <cmath>

#include "../test_helpers.h"

namespace linesim::people {
namespace {

using test_helpers::Get;
using test_helpers::SetAll;
using test_helpers::SetArray;

// One worker: both legs (radius 0.05 m, 0 to 0.84 m) at (x, y) and (x, y +
// 0.2), torso (radius 0.2 m) from 0.84 m up at (x, y + 0.1).
std::vector<double> Worker(double x, double y) {
  return {x, y,       0, 0, 0.05, 0.0,  0.84,  //
          x, y + 0.2, 0, 0, 0.05, 0.0,  0.84,  //
          x, y + 0.1, 0, 0, 0.2,  0.84, 1.75};
}

// Guards against a wrong frame or a torso counted below its height: a
// 1.0 x 0.6 m body turned 90 deg at (1, 0) reaches x 0.7..1.3, y -0.5..0.5;
// a leg at (1.0, 0.8) is 0.8 - 0.5 - 0.05 = 0.25 m away (the other leg
// farther, the torso above the body's 0.5 m top is ignored).
TEST(PersonClearance, DistanceInTheRobotsFrame) {
  PersonClearanceUnit u("pc", 1);
  SetAll(u, "body_length", 1.0);
  SetAll(u, "body_width", 0.6);
  SetArray(u, "position_3d", {1.0, 0.0, 0.1});
  SetArray(u, "orientation", {std::cos(M_PI / 4), 0.0, 0.0, std::sin(M_PI / 4)});
  SetArray(u, "cylinders", Worker(1.0, 0.8));
  u.Setup(0, 0);
  u.Initialize();
  EXPECT_NEAR(Get(u, "distance")[0], 0.25, 1e-12);
  EXPECT_EQ(Get(u, "nearest")[0], 0.0);
  EXPECT_EQ(Get(u, "collisions")[0], 0.0);
}

// Guards against contacts counted per step instead of per event: touching
// for two steps is one collision; leaving and touching again is another.
TEST(PersonClearance, ContactEvents) {
  PersonClearanceUnit u("pc", 1);
  SetAll(u, "body_length", 1.0);
  SetAll(u, "body_width", 0.6);
  SetArray(u, "cylinders", Worker(3.0, 0.0));
  u.Setup(0, 0);
  u.Initialize();
  const cosim::TimeNs dt = 10'000'000;
  const auto step = [&](double x) {
    SetArray(u, "cylinders", Worker(x, 0.0));
    ASSERT_EQ(u.DoStep(0, dt), cosim::StepResult::kOk);
  };
  step(0.52);  // 0.02 m off the front face less 0.05: overlapping
  step(0.52);
  EXPECT_EQ(Get(u, "collisions")[0], 1.0);
  EXPECT_EQ(Get(u, "min_distance")[0], 0.0);
  step(1.0);
  EXPECT_NEAR(Get(u, "distance")[0], 0.45, 1e-12);
  step(0.54);
  EXPECT_EQ(Get(u, "collisions")[0], 2.0);
  EXPECT_EQ(Get(u, "worker_collisions")[0], 2.0);
}

// Guards issue 37's report of a contact, which nothing resolves (person
// contact is not modelled): the time in contact is summed over the steps
// that end in contact (3 of 10 ms here), per worker and in all; each
// contact event is a warning naming the worker and the time; Initialize
// (which the master may call more than once) starts them afresh.
TEST(PersonClearance, ContactIsTimedAndWarned) {
  PersonClearanceUnit u("pc", 2, {"alice", "bob"});
  SetAll(u, "body_length", 1.0);
  SetAll(u, "body_width", 0.6);
  const auto both = [](double xa, double xb) {
    std::vector<double> c = Worker(xa, 0.0);
    const std::vector<double> b = Worker(xb, 3.0);
    c.insert(c.end(), b.begin(), b.end());
    return c;
  };
  SetArray(u, "cylinders", both(3.0, 3.0));
  u.Setup(0, 0);
  u.Initialize();
  u.Initialize();
  EXPECT_TRUE(u.warnings().empty());
  const cosim::TimeNs dt = 10'000'000;
  cosim::TimeNs t = 0;
  const auto step = [&](double xa) {
    SetArray(u, "cylinders", both(xa, 3.0));
    ASSERT_EQ(u.DoStep(t, dt), cosim::StepResult::kOk);
    t += dt;
  };
  step(0.52);  // touching from 10 ms
  step(0.52);
  step(1.0);   // clear
  step(0.54);  // again from 40 ms
  EXPECT_NEAR(Get(u, "contact_time")[0], 0.03, 1e-15);
  EXPECT_NEAR(Get(u, "worker_contact_time")[0], 0.03, 1e-15);
  EXPECT_EQ(Get(u, "worker_contact_time")[1], 0.0);
  ASSERT_EQ(u.warnings().size(), 2u);
  EXPECT_EQ(u.warnings()[0].rfind("at t = 0.01 s: alice touches the robot's body: contact with "
                                  "a person is not modelled",
                                  0),
            0u)
      << u.warnings()[0];
  EXPECT_EQ(u.warnings()[1].rfind("at t = 0.04 s: alice", 0), 0u) << u.warnings()[1];
}

}  // namespace
}  // namespace linesim::people
